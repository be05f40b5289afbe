// `exotwin bench`: JSON with each probe's timing and its ratio against the in-run baseline.
// Quick sizes, start-up, closed loop and sweep only (render, identification and diagnosis have their
// own benches). No timing is asserted: the machines are shared.
#include <sched.h>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <fstream>

#include "app/bench_probes.h"
#include "tests/app/cli_test_util.h"

namespace exotwin::testing {
namespace {

// `exotwin bench --quick --repeat 1 --only <only>`'s JSON; a failed run (exit code not 0) fails the
// test and returns an empty object.
nlohmann::ordered_json QuickBench(const std::string& only) {
  const testing::ScopedTempDir tmp("bench_" + only.substr(0, only.find(',')));
  const std::string dir = tmp.path();
  const RunResult r = RunExotwin("bench --quick --repeat 1 --only " + only + " --out " + dir + "/b.json");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  if (r.exit_code != 0) return nlohmann::ordered_json::object();
  std::ifstream f(dir + "/b.json");
  return nlohmann::ordered_json::parse(f);  // key order as written
}

TEST(BenchCli, QuickJsonHasRatios) {
  const testing::ScopedTempDir tmp("bench");
  const std::string dir = tmp.path();
  const RunResult r = RunExotwin("bench --quick --repeat 1 --only startup,closed_loop,sweep,replay --out " + dir + "/b.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream f(dir + "/b.json");
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(f);  // key order as written
  EXPECT_EQ(j["closed_loop"]["status"], "ok");
  EXPECT_GT(j["closed_loop"]["ratio_closed_loop_to_bare"].get<double>(), 1.0);
  EXPECT_EQ(j["closed_loop"]["steps"], 2000);
  EXPECT_GT(j["closed_loop"]["ratio_voluntary_human_to_bare"].get<double>(), 1.0);
  EXPECT_TRUE(j["closed_loop"]["emg_cost_us_per_step"].is_number());
  EXPECT_GT(j["sweep"]["speedup_2_jobs"].get<double>(), 0.0);
  EXPECT_EQ(j["startup"]["status"], "ok");
  EXPECT_EQ(j["startup"].begin().key(), "ratio_help_to_true");  // ratio first
  EXPECT_GT(j["startup"]["help_s"].get<double>(), 0.0);
  EXPECT_GT(j["startup"]["true_s"].get<double>(), 0.0);
  EXPECT_FALSE(j.contains("render"));
  EXPECT_EQ(j["replay"].begin().key(), "ratio_replay_to_bare");
  EXPECT_EQ(j["replay"]["steps"], 20000);
  EXPECT_EQ(j["replay"]["windows"], 39);  // 20 s minus the last sample: 39 whole windows of 0.5 s
  EXPECT_GT(j["replay"]["ratio_replay_to_bare"].get<double>(), 0.0);
  // The table (stderr): one row per figure, ratio first, under the machine's cores and load.
  EXPECT_EQ(j["closed_loop"]["rows"].size(), 2u);
  EXPECT_EQ(j["sweep"]["rows"][0]["goal"], ">= 1.85x");
  EXPECT_TRUE(j["machine"]["load_avg_15min"].is_number());
  EXPECT_GT(j["machine"]["cores"].get<int>(), 0);
  EXPECT_NE(r.output.find("| ratio | goal | work | against | figures |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("closed loop without logs, EMG"), std::string::npos);
  EXPECT_NE(r.output.find("machine: "), std::string::npos);
  // Every CPU the process may use, measured pinned to it; the single-threaded probes ran on the
  // fastest, the sweep's two jobs on all of them, bounded by what the CPUs allow.
  const auto& cpus = j["machine"]["cpus"];
  ASSERT_GE(cpus.size(), 1u);
  int fastest = -1;
  double t_fastest = 1e300;
  for (const auto& c : cpus) {
    EXPECT_GT(c["bare_mj_step_s"].get<double>(), 0.0);
    if (c["bare_mj_step_s"].get<double>() < t_fastest) t_fastest = c["bare_mj_step_s"], fastest = c["cpu"];
  }
  EXPECT_EQ(j["closed_loop"]["pinned_cpu"], fastest);
  EXPECT_EQ(j["startup"]["pinned_cpu"], fastest);
  EXPECT_FALSE(j["sweep"].contains("pinned_cpu"));
  EXPECT_EQ(j["sweep"]["jobs1_pinned_to_fastest_cpu"], fastest);
  const double bound = j["sweep"]["speedup_bound_of_these_cpus"].get<double>();
  EXPECT_GE(bound, 1.0);
  EXPECT_LE(bound, static_cast<double>(cpus.size()) + 1e-12);
  EXPECT_NE(r.output.find("single-threaded probes run on cpu" + std::to_string(fastest)), std::string::npos) << r.output;
}

// The CPUs' speed-up bound: the sum over CPUs of t_fastest / t_cpu.
TEST(BenchTable, SpeedupBoundOfUnequalCpus) {
  EXPECT_DOUBLE_EQ(SpeedupBoundOfCpus({{0, 0.12}, {1, 0.18}}), 1.0 + 0.12 / 0.18);
  EXPECT_DOUBLE_EQ(SpeedupBoundOfCpus({{0, 0.2}, {1, 0.2}}), 2.0);
  EXPECT_DOUBLE_EQ(SpeedupBoundOfCpus({}), 1.0);
  EXPECT_EQ(FastestCpu({{0, 0.3}, {3, 0.1}, {5, 0.2}}), 3);
  EXPECT_EQ(FastestCpu({}), -1);
}

// ScopedCpuPin sets this thread's affinity to one CPU and restores the previous mask.
TEST(BenchTable, ScopedCpuPinRestoresTheAffinity) {
  cpu_set_t before;
  ASSERT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
  int first = -1;
  for (int c = 0; c < CPU_SETSIZE && first < 0; ++c)
    if (CPU_ISSET(c, &before)) first = c;
  {
    const ScopedCpuPin pin(first);
    ASSERT_TRUE(pin.pinned());
    cpu_set_t now;
    ASSERT_EQ(sched_getaffinity(0, sizeof now, &now), 0);
    EXPECT_EQ(CPU_COUNT(&now), 1);
    EXPECT_TRUE(CPU_ISSET(first, &now));
  }
  cpu_set_t after;
  ASSERT_EQ(sched_getaffinity(0, sizeof after, &after), 0);
  EXPECT_TRUE(CPU_EQUAL(&before, &after));
  EXPECT_FALSE(ScopedCpuPin(-1).pinned());
}

// The long-record rows: ratio against the strtod read of the same file first, the child's peak memory
// and the start-up's (no timed assertion: the machines are shared).
TEST(BenchCli, QuickLongRecordRows) {
  const nlohmann::ordered_json j = QuickBench("predict_long,diagnose_long");
  ASSERT_FALSE(j.empty());
  for (const char* row : {"predict_long", "diagnose_long"}) {
    SCOPED_TRACE(row);
    ASSERT_EQ(j[row]["status"], "ok");
    EXPECT_EQ(j[row].begin().key(), "ratio_to_strtod_read");
    EXPECT_GT(j[row]["ratio_to_strtod_read"].get<double>(), 0.0);
    // Paired with the strtod read (--quick: as many pairs as --repeat): the ratio is the pairs' median.
    EXPECT_EQ(j[row]["pairs"], 1);
    EXPECT_LE(j[row]["pair_ratio_min"].get<double>(), j[row]["ratio_to_strtod_read"].get<double>());
    EXPECT_GE(j[row]["pair_ratio_max"].get<double>(), j[row]["ratio_to_strtod_read"].get<double>());
    EXPECT_EQ(j[row]["samples"], 20001);  // 20 s at 1 kHz, both ends
    EXPECT_GT(j[row]["peak_rss_mb"].get<double>(), 0.0);
    EXPECT_GT(j[row]["start_up_peak_rss_mb"].get<double>(), 0.0);
    // The child's own peak (not the bench's pages it shared until exec): above its start-up's.
    EXPECT_GT(j[row]["data_peak_rss_mb"].get<double>(), 0.0);
  }
}

// The term search's cost row (issue 63): `diagnose` against `diagnose --no-completeness` on the same
// record, in pairs; the row's ratio is the pairs' median (no timed assertion).
TEST(BenchCli, QuickTermSearchRow) {
  const nlohmann::ordered_json j = QuickBench("term_search");
  ASSERT_EQ(j["term_search"]["status"], "ok");
  EXPECT_EQ(j["term_search"]["pairs"], 1);
  EXPECT_GT(j["term_search"]["ratio"].get<double>(), 0.0);
  EXPECT_EQ(j["term_search"]["data_s"], 20);
  EXPECT_EQ(j["term_search"]["rows"].size(), 1u);
}

// EXOTWIN_PEAK_FILE: the process's peak resident memory (VmHWM, kB) written at exit.
TEST(BenchCli, PeakFileHoldsThePeakMemory) {
  const testing::ScopedTempDir tmp("peak");
  const std::string file = tmp.path() + "/peak";
  ASSERT_EQ(setenv("EXOTWIN_PEAK_FILE", file.c_str(), 1), 0);
  const RunResult r = RunExotwin("--help");
  unsetenv("EXOTWIN_PEAK_FILE");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream f(file);
  long kb = -1;
  ASSERT_TRUE(f >> kb) << "no number in " << file;
  EXPECT_GT(kb, 1000);       // the program and its libraries: megabytes
  EXPECT_LT(kb, 1000000);    // --help reads no data: far below a gigabyte
}

TEST(BenchCli, UnknownProbeExits2) {
  const RunResult r = RunExotwin("bench --only warp_drive");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("warp_drive"), std::string::npos);
}

}  // namespace
}  // namespace exotwin::testing
