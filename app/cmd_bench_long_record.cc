// The long-record rows of `exotwin bench` (app/bench_probes.h): `predict` and `diagnose` of a
// generated 1 kHz record (600 s; quick: 20 s), each run as a child process of this executable, against
// reading the same file once with strtod per field (the floor of any CSV reader) in the same run.
// Peak memory is the child's own VmHWM (EXOTWIN_PEAK_FILE, app/main.cc; its ru_maxrss would also
// count this process's pages it shared until exec), next to that of `exotwin --help` (start-up alone).
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "app/bench_probes.h"
#include "core/data_dir.h"
#include "core/file_text.h"
#include "formats/number_text.h"
#include "formats/csv_table.h"
#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin {
namespace {

using json = nlohmann::ordered_json;

// Seconds to read `path` whole and parse every comma-separated field of its data lines with strtod.
double StrtodReadSeconds(const std::string& path, size_t* fields) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string text = ReadTextFile(path, "", "a text CSV file");
  size_t n = 0;
  double sum = 0;
  const char* p = text.c_str();
  while (*p) {
    const char* nl = std::strchr(p, '\n');
    if (!nl) nl = p + std::strlen(p);
    if (*p != '#' && !(*p >= 'a' && *p <= 'z')) {  // not a comment nor the header
      for (const char* q = p; q < nl;) {
        char* e = nullptr;
        sum += std::strtod(q, &e);
        ++n;
        if (e == q || *e != ',') break;
        q = e + 1;
      }
    }
    p = *nl ? nl + 1 : nl;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  *fields = n + (sum == 0.123456789 ? 1 : 0);  // keeps the sum alive
  return s;
}

struct ChildRun {
  double wall_s = 0, cpu_s = 0;
  double max_rss_mb = 0;
};

// Runs this executable with `args` (stdout and stderr to /dev/null); throws if it does not exit 0.
ChildRun RunSelf(std::vector<std::string> args) {
  args.insert(args.begin(), "exotwin");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string peak_file =
      (std::filesystem::temp_directory_path() / ("exotwin_bench_peak_" + std::to_string(getpid()))).string();
  std::remove(peak_file.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("bench: fork failed");
  if (pid == 0) {
    if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr)) _exit(127);
    setenv("EXOTWIN_PEAK_FILE", peak_file.c_str(), 1);
    execv("/proc/self/exe", argv.data());
    _exit(127);
  }
  int status = 0;
  rusage ru{};
  if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("bench: `exotwin " + args[1] + "` failed on the long record");
  ChildRun r;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.cpu_s = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  r.max_rss_mb = ru.ru_maxrss / 1024.0;
  if (std::FILE* f = std::fopen(peak_file.c_str(), "r")) {
    long kb = 0;
    if (std::fscanf(f, "%ld", &kb) == 1 && kb > 0) r.max_rss_mb = kb / 1024.0;
    std::fclose(f);
    std::remove(peak_file.c_str());
  }
  return r;
}

struct LongRecord {
  std::string csv, params;
  std::string what;  // the record in the row's words
  double data_s = 0;
  size_t samples = 0, bytes = 0, fields = 0;
  double strtod_s = 0;      // best strtod read of the file
  double start_up_mb = 0;   // peak memory of `exotwin --help`
};

// The file's size, its best strtod read (the floor) and the start-up memory into *r.
void MeasureFloor(const BenchConfig& c, LongRecord* r) {
  r->bytes = std::filesystem::file_size(r->csv);
  r->strtod_s = std::numeric_limits<double>::infinity();
  for (int i = 0; i < std::max(1, c.repeat); ++i) r->strtod_s = std::min(r->strtod_s, StrtodReadSeconds(r->csv, &r->fields));
  r->start_up_mb = RunSelf({"--help"}).max_rss_mb;
}

// The record (generated once per scratch folder: S1 with a hidden Coulomb friction, 10 columns),
// the strtod floor and the start-up memory.
const LongRecord& TheLongRecord(const BenchConfig& c) {
  static LongRecord r;
  if (!r.csv.empty() && std::filesystem::exists(r.csv)) return r;
  const GenerateOptions g = BenchFrictionRecord(c.quick ? 20 : 600);
  r.params = DataPath("examples/S1.yaml");
  const GeneratedData data = GenerateMeasured(ReadModelFile(r.params), g);
  r.csv = c.scratch + "/long_record.csv";
  WriteGeneratedCsv(data, r.csv, g.seed);
  r.data_s = g.duration;
  r.samples = data.data.size();
  MeasureFloor(c, &r);
  return r;
}

// The record `run` writes for the shipped gait scenario (scenarios/gait_2kmh.yaml, S1 in EXOwheel,
// closed loop) at 600 s (quick: 20 s): besides t, q_*, tau_*, its cmd_*, ref_*, state and five emg_*
// columns (15 in all); diagnosed with the model file of its subject.
const LongRecord& TheRunRecord(const BenchConfig& c) {
  static LongRecord r;
  if (!r.csv.empty() && std::filesystem::exists(r.csv)) return r;
  Scenario s = ReadScenario(DataPath("scenarios/gait_2kmh.yaml"));
  s.protocol.duration = c.quick ? 20 : 600;
  s.log_measured_csv = true;
  RunOptions o;
  o.out_dir = c.scratch + "/run_record";
  RunScenario(s, o);
  r.params = DataPath("examples/S1.yaml");
  r.csv = o.out_dir + "/measured.csv";
  r.what = "a run record";
  r.data_s = s.protocol.duration;
  r.samples = ReadCsv(r.csv).rows();
  MeasureFloor(c, &r);
  return r;
}

// The median of paired runs' ratios (at least one).
double MedianOf(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

json LongRecordRow(const BenchConfig& c, const LongRecord& r, const std::string& command, int pairs) {
  const std::string out = c.scratch + "/long_" + command + (command == "predict" ? ".csv" : "");
  // In pairs, the strtod read then the command: the ratio is the median of the pairs' ratios (a
  // machine whose speed drifts between the floor's timing and the command's moves both of a pair).
  // The times and the CPU time are the best run's, the peak memory the largest.
  std::vector<double> ratios;
  ChildRun run;
  run.wall_s = std::numeric_limits<double>::infinity();
  for (int i = 0; i < std::max(1, pairs); ++i) {
    size_t fields = 0;
    const double floor_s = StrtodReadSeconds(r.csv, &fields);
    const ChildRun k = RunSelf({command, "--params", r.params, "--measured", r.csv, "--out", out});
    ratios.push_back(k.wall_s / floor_s);
    const double rss = std::max(run.max_rss_mb, k.max_rss_mb);
    if (k.wall_s < run.wall_s) run = k;
    run.max_rss_mb = rss;
  }
  std::sort(ratios.begin(), ratios.end());
  const double ratio = MedianOf(ratios);
  // `diagnose` runs on every core (diagnosis/diagnose.h DiagnoseThreads), the strtod read on one: the
  // row names the cores, and its CPU seconds over the same floor.
  const bool threaded = command == "diagnose";
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  std::string work = "`" + command + "` on " + (r.what.empty() ? "" : r.what + ", ") +
                     std::to_string(static_cast<int>(r.data_s)) + " s of 1 kHz data (" +
                     std::to_string(static_cast<int>(r.bytes / 1e6)) + " MB)";
  if (threaded) work += " on " + std::to_string(cores) + " cores";
  std::string detail = std::to_string(static_cast<int>(std::lround(run.max_rss_mb))) + " MB peak";
  if (threaded) detail += "; CPU " + NumberText(run.cpu_s / r.strtod_s, 3) + "x";
  detail += "; pairs " + NumberText(ratios.front(), 3) + " .. " + NumberText(ratios.back(), 3) + "x";
  return json{{"ratio_to_strtod_read", ratio},
              {"pairs", ratios.size()},
              {"pair_ratio_min", ratios.front()},
              {"pair_ratio_max", ratios.back()},
              {"status", "ok"},
              {"data_s", r.data_s},
              {"samples", r.samples},
              {"file_mb", r.bytes / 1e6},
              {"strtod_read_s", r.strtod_s},
              {command + "_s", run.wall_s},
              {command + "_cpu_s", run.cpu_s},
              {"peak_rss_mb", run.max_rss_mb},
              {"start_up_peak_rss_mb", r.start_up_mb},
              {"data_peak_rss_mb", run.max_rss_mb - r.start_up_mb},
              {"cores", threaded ? cores : 1u},
              {"rows", BenchRowsJson({{work, ratio, "x", "reading the file once with strtod per field (paired runs, median)",
                                       command == "predict" ? "<= 2.5x, <= 150 MB" : "<= 3x, <= 150 MB", detail}})}};
}

// Pairs: at least 3 (their median), --quick as --repeat says (a check that the rows work, no figure).
int LongRecordPairs(const BenchConfig& c) { return c.quick ? std::max(1, c.repeat) : std::max(3, c.repeat); }

}  // namespace

json BenchPredictLong(const BenchConfig& c) { return LongRecordRow(c, TheLongRecord(c), "predict", LongRecordPairs(c)); }

json BenchDiagnoseLong(const BenchConfig& c) {
  json j = LongRecordRow(c, TheLongRecord(c), "diagnose", LongRecordPairs(c));
  // The same on the record `run` writes (its extra columns: the reader keeps what diagnose reads).
  json run = LongRecordRow(c, TheRunRecord(c), "diagnose", LongRecordPairs(c));
  for (const auto& row : run["rows"]) j["rows"].push_back(row);
  run.erase("rows");
  j["run_record"] = run;
  return j;
}


// Issue 63's cost row: `diagnose` on a 60 s record (quick: 20 s) of S1 at 1 kHz holding a form off the
// table, (0.3 + 0.06 |tau_R|) sgn(qd) at the knee, with stage 5c (the residual tests, the ceilings and
// the search for terms beyond the table, which names the form) against `diagnose --no-completeness`
// (the diagnosis without them) on the same record: paired runs, the median of the pairs' ratios.
json BenchTermSearch(const BenchConfig& c) {
  GenerateOptions g;
  g.seed = 1, g.effects = 0, g.duration = c.quick ? 20 : 60, g.rate = 1000;
  Effect form;
  form.name = "term", form.joint = "knee", form.value = 0.06, form.expr = "(5 + abs(tau_R)) * sgn(qd)", form.stage = "link";
  g.terms = {form};
  const std::string params = DataPath("examples/S1.yaml");
  const std::string csv = c.scratch + "/term_record.csv";
  WriteGeneratedCsv(GenerateMeasured(ReadModelFile(params), g), csv, g.seed);
  std::vector<double> ratios, cpu_ratios;
  for (int i = 0; i < LongRecordPairs(c); ++i) {
    const ChildRun off = RunSelf({"diagnose", "--params", params, "--measured", csv, "--out", c.scratch + "/term_off",
                                  "--no-completeness"});
    const ChildRun on = RunSelf({"diagnose", "--params", params, "--measured", csv, "--out", c.scratch + "/term_on"});
    ratios.push_back(on.wall_s / off.wall_s), cpu_ratios.push_back(on.cpu_s / off.cpu_s);
  }
  const double ratio = MedianOf(ratios), cpu = MedianOf(cpu_ratios);
  const std::string work = "`diagnose` with its completeness tests, ceilings and search for terms (names the form), " +
                           std::to_string(static_cast<int>(g.duration)) + " s record holding a form off the table";
  const std::string detail = "CPU " + NumberText(cpu, 3) + "x; pairs " + NumberText(*std::min_element(ratios.begin(), ratios.end()), 3) +
                             " .. " + NumberText(*std::max_element(ratios.begin(), ratios.end()), 3) + "x";
  return json{{"ratio", ratio},
              {"cpu_ratio", cpu},
              {"pairs", ratios.size()},
              {"status", "ok"},
              {"data_s", g.duration},
              {"rows", BenchRowsJson({{work, ratio, "x", "the same `diagnose --no-completeness` (paired runs, median)",
                                       "<= 2x", detail}})}};
}

}  // namespace exotwin
