// ExowheelSession (runner/exowheel_runner.h): the EXOwheel run advanced from outside in any parts
// gives RunExowheelScenario's logs bit for bit (captured as the CSV files hold them, RunOptions::capture)
// and its metrics; a command given for the ticks reaches the drivers through the supervisor.
#include "runner/exowheel_runner.h"

#include <gtest/gtest.h>

#include <limits>

#include "runner/scenario.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

Scenario ShortGait(double duration, int trials) {
  Scenario s = ReadScenario(std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/gait_2kmh.yaml");
  s.protocol.duration = duration;
  s.protocol.trials = trials;
  return s;
}

void ExpectSameLogs(const LogCapture& a, const LogCapture& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].file, b[i].file);
    EXPECT_EQ(a[i].columns, b[i].columns);
    ASSERT_EQ(a[i].values.size(), b[i].values.size()) << a[i].file;
    for (size_t k = 0; k < a[i].values.size(); ++k)
      if (!(a[i].values[k] == b[i].values[k]) && !(a[i].values[k] != a[i].values[k] && b[i].values[k] != b[i].values[k]))
        FAIL() << a[i].file << " value " << k << ": " << a[i].values[k] << " vs " << b[i].values[k];
  }
}

TEST(ExowheelSession, AdvancedInPartsIsTheRunBitForBit) {
  const Scenario s = ShortGait(0.6, 2);
  const testing::ScopedTempDir tmp("exowheel_session");
  LogCapture whole_logs, part_logs;
  RunOptions o;
  o.out_dir = tmp.File("whole");
  o.seed = 4;
  o.capture = &whole_logs;
  const RunResult whole = RunExowheelScenario(s, o);
  o.out_dir = tmp.File("parts");
  o.capture = &part_logs;
  ExowheelSession session(s, o);
  EXPECT_EQ(session.steps_per_tick(), 1);
  long steps = 0;
  double row[15];
  for (long part = 1; !session.done(); part = part % 7 + 1) {
    steps += session.Advance(part, nullptr);
    ASSERT_EQ(session.MeasuredRow(row), 15u);  // S1 with EMG: the 5 emg_* columns too
    EXPECT_EQ(row[0], session.time());
  }
  EXPECT_EQ(steps, 1200);
  EXPECT_EQ(session.trial(), 1);
  EXPECT_EQ(session.Advance(10, nullptr), 0);
  const RunResult parts = session.Finish();
  ASSERT_EQ(whole_logs.size(), 4u);
  EXPECT_EQ(whole_logs[2].file, "measured_trial2.csv");
  EXPECT_EQ(whole_logs[0].rows(), 600u);
  ExpectSameLogs(whole_logs, part_logs);
  for (const auto& [name, value] : whole.metrics) {
    if (name != "wall_time_s") {
      EXPECT_EQ(parts.metrics.at(name), value) << name;
    }
  }
  EXPECT_EQ(parts.files, whole.files);
  EXPECT_EQ(parts.events, whole.events);
}

TEST(ExowheelSession, CommandReplacesTheControlLawAtTheTicks) {
  const Scenario s = ShortGait(0.2, 1);
  const testing::ScopedTempDir tmp("exowheel_command");
  RunOptions o;
  o.out_dir = tmp.path();
  ExowheelSession session(s, o);
  session.Advance(5, nullptr);  // the modules' first frames
  const double command[2] = {2.5, -1.25};
  session.Advance(1, command);
  double row[15];
  session.MeasuredRow(row);
  EXPECT_EQ(row[5], command[0]);  // cmd_hip
  EXPECT_EQ(row[6], command[1]);  // cmd_knee
  EXPECT_EQ(row[9], 0.0);         // state: running
  double truth[9];
  ASSERT_EQ(session.TruthRow(truth), 9u);
  EXPECT_EQ(truth[0], row[0]);
  session.Advance(std::numeric_limits<long>::max(), nullptr);
  EXPECT_TRUE(session.done());
  EXPECT_EQ(session.Finish().metrics.at("samples"), 200.0);
}

}  // namespace
}  // namespace exotwin
