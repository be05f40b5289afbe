// Diagnose's two entry points: the records read (copied into the analysis) and the records given up
// (their columns moved into it, for long records) give one and the same diagnosis.
#include <gtest/gtest.h>

#include <cstring>

#include "diagnosis/diagnose.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"

namespace exotwin {
namespace {

const std::string kS1 = std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml";

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// Two records of one device with EMG and effects that stage 5 refines (sensor delay, backlash) and
// leave-one-out scoring: every stage runs.
TEST(Diagnose, ConsumingTheRecordsGivesTheSameDiagnosisBitForBit) {
  const LegParams base = ReadModelFile(kS1);
  std::vector<MeasuredData> records;
  for (uint64_t seed : {5u, 6u}) {
    GenerateOptions g;
    g.seed = seed;
    g.effects = 2;
    g.allowed = {"sensor_delay", "backlash"};
    g.duration = 20;
    g.rate = 500;
    records.push_back(GenerateMeasured(base, g).data);
  }
  std::vector<const MeasuredData*> pointers;
  for (const MeasuredData& m : records) pointers.push_back(&m);
  const Diagnosis copied = Diagnose(base, pointers);
  std::vector<MeasuredData> given = records;
  const Diagnosis moved = Diagnose(base, std::move(given));
  for (const MeasuredData& m : given) EXPECT_EQ(m.size(), 0u);  // the columns went into the analysis

  ASSERT_FALSE(copied.effects.empty());
  EXPECT_EQ(DiagnosisJson(moved), DiagnosisJson(copied));
  ASSERT_EQ(moved.effects.size(), copied.effects.size());
  for (size_t k = 0; k < copied.effects.size(); ++k) {
    EXPECT_EQ(moved.effects[k].effect.name, copied.effects[k].effect.name);
    EXPECT_EQ(std::memcmp(&moved.effects[k].effect.value, &copied.effects[k].effect.value, sizeof(double)), 0);
  }
  for (int j = 0; j < 2; ++j) {
    EXPECT_TRUE(SameBits(moved.measured[j], copied.measured[j]));
    EXPECT_TRUE(SameBits(moved.before[j], copied.before[j]));
    EXPECT_TRUE(SameBits(moved.after[j], copied.after[j]));
    EXPECT_TRUE(SameBits(moved.kin.qdd[j], copied.kin.qdd[j]));
  }
  EXPECT_TRUE(moved.leave_one_out);
}

// DiagnoseOptions::threads: one thread or two (the cutoff choice's rates, regressor and low-passes,
// the columns' samples, the rigid and extended twins' replays side by side) give the same diagnosis
// bit for bit. 30 s at 1 kHz: long enough that every split engages (ForEachSample splits from 20000
// samples).
TEST(Diagnose, OneThreadOrTwoGiveTheSameDiagnosisBitForBit) {
  const LegParams base = ReadModelFile(kS1);
  GenerateOptions g;
  g.seed = 11;
  g.effects = 2;
  g.allowed = {"coulomb_friction", "backlash"};
  g.duration = 30;
  g.rate = 1000;
  const MeasuredData record = GenerateMeasured(base, g).data;
  ASSERT_GE(record.size(), 30000u);
  DiagnoseOptions one, two;
  one.threads = 1, two.threads = 2;
  const Diagnosis a = Diagnose(base, {&record}, one);
  const Diagnosis b = Diagnose(base, {&record}, two);
  ASSERT_FALSE(a.effects.empty());
  ASSERT_TRUE(a.simulation.done);
  EXPECT_EQ(DiagnosisJson(a), DiagnosisJson(b));
  for (int j = 0; j < 2; ++j) {
    EXPECT_TRUE(SameBits(a.after[j], b.after[j]));
    EXPECT_TRUE(SameBits(a.simulation.rigid[j], b.simulation.rigid[j]));
    EXPECT_TRUE(SameBits(a.simulation.extended[j], b.simulation.extended[j]));
  }
  EXPECT_EQ(a.simulation.rigid[0].size(), a.simulation.t.size());
}

}  // namespace
}  // namespace exotwin
