#include <CLI/CLI.hpp>

#include <cstdio>

#include "analysis/opensim_storage.h"
#include "app/commands.h"
#include "core/stop_signal.h"
#include "runner/out_folder_lock.h"
#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin {
namespace {

// Prints the checks as a table; returns 0 when all passed, 1 otherwise, 128 + N when signal N
// (SIGINT, SIGTERM) interrupted the run (result.json then says where: DESIGN.md "Interrupted runs").
int Report(const RunResult& r, const std::string& out_dir) {
  const auto samples = r.metrics.find("samples");
  std::printf("scenario %s (seed %llu): %zu samples, results in %s/result.json\n", r.scenario.c_str(),
              static_cast<unsigned long long>(r.seed),
              samples == r.metrics.end() ? size_t{0} : static_cast<size_t>(samples->second), out_dir.c_str());
  for (const CheckResult& c : r.checks)
    std::printf("  %-4s %-32s %12.5g %s %-10.5g (%s)\n", c.passed ? "ok" : "FAIL", c.name.c_str(), c.value,
                c.op.c_str(), c.limit, c.metric.c_str());
  if (r.interrupted) {
    std::fprintf(stderr, "exotwin: interrupted by %s at t = %.3f s (trial %d): checks not passed\n",
                 StopSignalName(r.interrupted->signal), r.interrupted->t, r.interrupted->trial);
    return 128 + r.interrupted->signal;
  }
  return r.all_passed() ? 0 : 1;
}

// --sto: every measured[_trialN].csv and truth[_trialN].csv the run wrote (r.files, relative to
// out_dir) also as an OpenSim storage file beside it (same name, .sto; analysis/opensim_storage.h
// CsvToStorage: inDegrees=no, SI values unchanged). Returns the files written.
std::vector<std::string> WriteStorageCopies(const RunResult& r, const std::string& out_dir) {
  std::vector<std::string> written;
  for (const std::string& f : r.files) {
    const std::string base = f.substr(f.find_last_of('/') + 1);
    const bool log = base.rfind("measured", 0) == 0 || base.rfind("truth", 0) == 0;
    if (!log || base.size() < 4 || base.compare(base.size() - 4, 4, ".csv") != 0) continue;
    const std::string csv = out_dir + "/" + f, sto = csv.substr(0, csv.size() - 4) + ".sto";
    CsvToStorage(csv, sto);
    written.push_back(sto);
  }
  return written;
}

CommandRunner RegisterRun(CLI::App& app) {
  struct Opts {
    std::string scenario, out = "out", can_log, video;
    uint64_t seed = 0;
    bool sto = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("run", "Run a scenario: plant + virtual hardware + the real controller");
  sub->add_option("scenario", o->scenario, "scenario YAML")->required();
  sub->add_option("--out", o->out, "output folder (result.json, measured.csv, truth.csv)");
  auto* seed = sub->add_option("--seed", o->seed, "seed (overrides the scenario's)");
  sub->add_option("--can-log", o->can_log, "candump log of every CAN frame");
  sub->add_option("--video", o->video, "render an MP4 video of the run");
  sub->add_flag("--sto", o->sto,
                "also write measured.csv and truth.csv as OpenSim storage files (measured.sto, truth.sto; "
                "version-1 header, inDegrees=no, tab-separated)");
  return [sub, o, seed]() -> int {
    if (!*sub) return -1;
    InstallStopSignalHandlers();
    const Scenario s = ReadScenario(o->scenario);
    const OutFolderLock lock(o->out);
    RunOptions opt;
    opt.out_dir = o->out;
    if (*seed) opt.seed = o->seed;
    opt.can_log = o->can_log;
    opt.progress = true;
    opt.video_path = o->video;
    const RunResult r = RunScenario(s, opt);
    if (o->sto)
      for (const std::string& f : WriteStorageCopies(r, o->out)) std::fprintf(stderr, "run: wrote %s\n", f.c_str());
    return Report(r, o->out);
  };
}

// `exotwin render SCENARIO.yaml -o FILE.mp4`: runs the scenario (logs under --out) and renders its
// first trial off-screen: side view, human and exoskeleton in distinct colours, overlays.
CommandRunner RegisterRender(CLI::App& app) {
  struct Opts {
    std::string scenario, video, out = "out/render";
    bool sto = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("render", "Run a scenario and render it to an MP4 (H.264, 30 fps, 1280x720)");
  sub->add_option("scenario", o->scenario, "scenario YAML")->required();
  sub->add_option("-o,--output", o->video, "output MP4")->required();
  sub->add_option("--out", o->out, "folder for the run's logs and result.json");
  sub->add_flag("--sto", o->sto, "also write the logs as OpenSim storage files (as run --sto)");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    InstallStopSignalHandlers();
    const Scenario s = ReadScenario(o->scenario);
    const OutFolderLock lock(o->out);
    RunOptions opt;
    opt.out_dir = o->out;
    opt.video_path = o->video;
    opt.progress = true;
    const RunResult r = RunScenario(s, opt);
    if (o->sto)
      for (const std::string& f : WriteStorageCopies(r, o->out)) std::fprintf(stderr, "render: wrote %s\n", f.c_str());
    const int rc = Report(r, o->out);
    std::printf("wrote %s\n", o->video.c_str());
    return rc > 1 ? rc : 0;  // a failed check does not fail the rendering; an interruption does
  };
}

const CommandRegistration kRun(RegisterRun);
const CommandRegistration kRender(RegisterRender);

}  // namespace
}  // namespace exotwin
