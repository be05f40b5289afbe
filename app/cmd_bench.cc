// `exotwin bench [--out FILE.json] [--repeat R] [--quick] [--only NAME,...]`: speed of the twin, as
// JSON (stdout, and FILE.json): start-up (--help vs /bin/true), closed loop vs bare mj_step, render
// + encode fps, identification and diagnosis throughput, sweep speed-up on 2 worker processes, the
// controller across the process boundary (lockstep speed, real-time jitter); each
// with the ratio against its baseline measured in the same run (app/bench_probes.h). Exit 0, 2 on
// bad options. The rows of all probes also go to stderr as one Markdown
// table, ratio first, under the machine's cores and load.
#include <CLI/CLI.hpp>

#include <algorithm>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "formats/csv_table.h"
#include "app/bench_probes.h"
#include "app/commands.h"
#include "core/error.h"

namespace exotwin {
namespace {

CommandRunner RegisterBench(CLI::App& app) {
  struct Opts {
    std::string out, only;
    int repeat = 3;
    bool quick = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("bench", "Benchmark the twin (start-up, closed loop, render, identification, diagnosis, sweep)");
  sub->add_option("--out", o->out, "write the JSON here too");
  sub->add_option("--repeat", o->repeat, "repetitions per timing, best kept (default 3)");
  sub->add_flag("--quick", o->quick, "small problem sizes (seconds instead of a minute)");
  sub->add_option("--only", o->only, "comma-separated subset: startup,run,closed_loop,render,identification,diagnosis,sweep,"
                  "predict_long,diagnose_long,term_search,link,replay,python,motion_fit");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    if (o->repeat < 1) throw InputError("--repeat: expected >= 1, got " + std::to_string(o->repeat));
    const std::vector<std::string> all = {"startup", "run", "closed_loop", "render", "identification", "diagnosis", "sweep",
                                          "predict_long", "diagnose_long", "term_search", "link", "replay", "python", "motion_fit"};
    std::vector<std::string> selected;
    if (o->only.empty()) selected = all;
    else {
      size_t start = 0;
      while (start <= o->only.size()) {
        const size_t end = std::min(o->only.find(',', start), o->only.size());
        const std::string name = o->only.substr(start, end - start);
        if (std::find(all.begin(), all.end(), name) == all.end())
          throw InputError("--only: unknown probe '" + name +
                           "', expected a comma-separated subset of startup,run,closed_loop,render,identification,diagnosis,sweep,"
                           "predict_long,diagnose_long,term_search,link,replay,python,motion_fit");
        selected.push_back(name);
        start = end + 1;
      }
    }
    BenchConfig c;
    c.repeat = o->repeat;
    c.quick = o->quick;
    std::string tmpl = (std::filesystem::temp_directory_path() / "exotwin_bench_XXXXXX").string();
    if (!mkdtemp(tmpl.data())) throw std::runtime_error("bench: cannot create a temporary folder");
    c.scratch = tmpl;

    nlohmann::ordered_json j;
    const BenchMachine start = MeasureMachine();
    j["machine"] = MachineJson(start);
    c.cpus = MeasureCpus(c);
    j["machine"]["cpus"] = CpusJson(c.cpus);
    j["quick"] = o->quick;
    j["repeat"] = o->repeat;
    std::vector<BenchRow> rows;
    for (const std::string& name : selected) {
      std::fprintf(stderr, "bench: %s...\n", name.c_str());
      // Single-threaded work runs on the fastest CPU, its baseline too (bench_probes.h BenchCpu); the
      // render (llvmpipe and encoder threads), `run` (its log writer thread), the sweep and `diagnose`
      // (its cutoff choice, columns and replays on every core; the row says how many) use them all.
      const bool threaded = name == "render" || name == "run" || name == "sweep" || name == "link" || name == "python" ||
                            name == "motion_fit" || name == "diagnose_long" || name == "term_search";
      const ScopedCpuPin pin(threaded ? -1 : FastestCpu(c.cpus));
      if (name == "startup") j[name] = BenchStartup(c);
      if (name == "run") j[name] = BenchRunCommand(c);
      if (name == "closed_loop") j[name] = BenchClosedLoop(c);
      if (name == "render") j[name] = BenchRender(c);
      if (name == "identification") j[name] = BenchIdentification(c);
      if (name == "diagnosis") j[name] = BenchDiagnosis(c);
      if (name == "sweep") j[name] = BenchSweep(c);
      if (name == "predict_long") j[name] = BenchPredictLong(c);
      if (name == "diagnose_long") j[name] = BenchDiagnoseLong(c);
      if (name == "term_search") j[name] = BenchTermSearch(c);
      if (name == "link") j[name] = BenchLink(c);
      if (name == "replay") j[name] = BenchReplay(c);
      if (name == "python") j[name] = BenchPython(c);
      if (name == "motion_fit") j[name] = BenchMotionFit(c);
      if (pin.pinned()) j[name]["pinned_cpu"] = FastestCpu(c.cpus);
      for (const BenchRow& r : BenchRowsFromJson(j[name])) rows.push_back(r);
    }
    const BenchMachine end = MeasureMachine();
    j["machine_at_end"] = MachineJson(end);
    std::filesystem::remove_all(c.scratch);
    PrintBenchTable(stderr, rows, start, end, c.cpus);
    const std::string text = j.dump(2) + "\n";
    std::fputs(text.c_str(), stdout);
    if (!o->out.empty()) WriteFileAtomic(o->out, text);
    return 0;
  };
}

const CommandRegistration kBench(RegisterBench);

}  // namespace
}  // namespace exotwin
