// `exotwin replay` through the command line: the files of DESIGN.md on the shipped real-rig example
// (the rig's rigid model against the model with the friction and rotor inertia diagnose names), and
// bad input that exits 2 naming the place, with nothing written in --out.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>
#include <sys/stat.h>

#include "formats/csv_table.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::ReadText;
using testing::WriteText;

const std::string kRig = std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/";
const std::string kRecord = kRig + "trajectory_05.csv";
const std::string kMap = kRig + "dfki_double_pendulum_A0.map.yaml";

std::string RigModel(const std::string& effects) {
  return "L1: 0.3\n"
         "exo: {J1: 0.131785691, J2: 0.023923745, X1: 0.349117969, X2: 0.111064801, Y1: 0, Y2: 0, m1: 0.559380615, "
         "m2: 0.604345947}\n"
         "passive: none\n"
         "effects: " + effects + "\n";
}

// The effects diagnose names on the two shipped records (coulomb hip / knee, the knee's rotor
// inertia), rounded.
const char* kLearned =
    "[{name: coulomb_friction, joint: hip, value: 0.13}, {name: coulomb_friction, joint: knee, value: 0.145},"
    " {name: inertia_error, joint: knee, value: 0.0031}]";

bool Exists(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

class ReplayCli : public ::testing::Test {
 protected:
  testing::RunResult Replay(const std::string& model, const std::string& extra, const std::string& out = "out") {
    WriteText(dir_ + "/m.yaml", model);
    return RunExotwin("replay --params " + dir_ + "/m.yaml --measured " + kRecord + " --map " + kMap + " --out " +
                      dir_ + "/" + out + " " + extra);
  }
  void ExpectBadInput(const testing::RunResult& r, const std::string& must_contain) {
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(must_contain), std::string::npos) << "expected '" << must_contain << "': " << r.output;
    EXPECT_FALSE(Exists(dir_ + "/out")) << "something written in --out";
  }
  const testing::ScopedTempDir tmp_{"replay"};
  const std::string dir_ = tmp_.path();
};

TEST_F(ReplayCli, TheLearnedFrictionMovesLikeTheRig) {
  const auto rigid = Replay(RigModel("[]"), "", "rigid");
  ASSERT_EQ(rigid.exit_code, 0) << rigid.output;
  const auto learned = Replay(RigModel(kLearned), "", "learned");
  ASSERT_EQ(learned.exit_code, 0) << learned.output;
  auto Read = [&](const std::string& sub) {
    return nlohmann::json::parse(std::ifstream(dir_ + "/" + sub + "/replay.json"));
  };
  const auto a = Read("rigid"), b = Read("learned");
  EXPECT_EQ(a["horizon_s"], 0.5);
  EXPECT_EQ(a["windows"], 19);  // 9.99 s of record
  ASSERT_EQ(a["records"].size(), 1u);
  for (const char* j : {"hip", "knee"}) {
    const double before = a["joints"][j]["rmse_rad"], after = b["joints"][j]["rmse_rad"];
    std::printf("%s: rigid %.2f deg, learned %.2f deg\n", j, before * 57.2958, after * 57.2958);
    EXPECT_LT(after, 0.4 * before) << j;  // measured: 6.5 -> 1.1 deg (hip), 23.3 -> 2.5 deg (knee)
  }
  const CsvTable t = ReadCsv(dir_ + "/learned/replay.csv");
  ASSERT_EQ(t.names.size(), 7u);
  EXPECT_EQ(t.names[2], "q_hip_sim");
  EXPECT_EQ(t.columns[5].back(), 18);  // the last window's index
  // --input command drives the twin with the commanded torque (the rig's motor tracks it).
  const auto cmd = Replay(RigModel(kLearned), "--input command --horizon 0.25", "cmd");
  EXPECT_EQ(cmd.exit_code, 0) << cmd.output;
  EXPECT_EQ(Read("cmd")["horizon_s"], 0.25);
}

// The twin's own record (the shipped gait scenario, 20 s, closed loop on S1): its joint modules log the
// torque they apply over the coming step, so the rigid S1 twin follows it closer with each sample held
// (--between-samples hold) than interpolated (measured: 0.44 / 0.60 mrad hip / knee held, 0.59 / 0.98
// interpolated; on 60 s of it 0.36 / 0.53 and 0.57 / 0.97); replay.json says which.
TEST_F(ReplayCli, TheTwinsOwnRecordReplaysCloserWithTheInputHeld) {
  std::string scenario = ReadText(std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/gait_2kmh.yaml");
  const size_t at = scenario.find("duration: 60");
  ASSERT_NE(at, std::string::npos);
  scenario.replace(at, 12, "duration: 20");
  WriteText(dir_ + "/s.yaml", scenario);
  const auto run = RunExotwin("run " + dir_ + "/s.yaml --out " + dir_ + "/run");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  auto ReplayRecord = [&](const std::string& between) {
    const auto r = RunExotwin("replay --params " + std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml --measured " +
                              dir_ + "/run/measured.csv --between-samples " + between + " --out " + dir_ + "/" + between);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return nlohmann::json::parse(std::ifstream(dir_ + "/" + between + "/replay.json"));
  };
  const auto linear = ReplayRecord("linear"), hold = ReplayRecord("hold");
  EXPECT_EQ(linear["input_between_samples"], "linear");
  EXPECT_EQ(hold["input_between_samples"], "hold");
  for (const char* j : {"hip", "knee"}) {
    const double a = linear["joints"][j]["rmse_rad"], b = hold["joints"][j]["rmse_rad"];
    std::printf("%s: %.3g rad interpolated, %.3g rad held\n", j, a, b);
    EXPECT_LT(b, 0.9 * a) << j;
  }
}

// --windows quiet (the motion fit's windows, diagnosis/replay.h): the twin's own gait record (20 s,
// closed loop on S1) with a 0.03 rad hip dead band in its plant, replayed by its truth twin (S1 with
// the band). Every 0.5 s, windows restart and run through the band's knocks, where the restart velocity
// misses the link's crossing; the quiet windows restart and run outside them and the truth twin
// follows its own record closely there (measured: 0.78 -> 0.009 deg at the hip). The real rig's
// record 05 (a double pendulum swung, no knocks) keeps the every-horizon restarts; 113 of its 4728
// scored samples (2.4 %) lie where its fast content exceeds the quiet level and are not scored.
TEST_F(ReplayCli, QuietWindowsLetADeadBandsTruthTwinFollowItsRecord) {
  std::string scenario = ReadText(std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/gait_2kmh.yaml");
  const size_t at = scenario.find("duration: 60");
  ASSERT_NE(at, std::string::npos);
  scenario.replace(at, 12, "duration: 20");
  scenario += "plant: {effects: [{name: backlash, joint: hip, value: 0.03}]}\n";
  WriteText(dir_ + "/s.yaml", scenario);
  const auto run = RunExotwin("run " + dir_ + "/s.yaml --out " + dir_ + "/run");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::string model = ReadText(std::string(EXOTWIN_SOURCE_DIR) + "/examples/S1.yaml");
  const size_t fx = model.find("effects: []");
  ASSERT_NE(fx, std::string::npos);
  model.replace(fx, 11, "effects: [{name: backlash, joint: hip, value: 0.03}]");
  WriteText(dir_ + "/truth.yaml", model);
  auto ReplayRecord = [&](const std::string& windows) {
    const auto r = RunExotwin("replay --params " + dir_ + "/truth.yaml --measured " + dir_ +
                              "/run/measured.csv --between-samples hold --windows " + windows + " --out " + dir_ + "/" + windows);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return nlohmann::json::parse(std::ifstream(dir_ + "/" + windows + "/replay.json"));
  };
  const auto every = ReplayRecord("every"), quiet = ReplayRecord("quiet");
  EXPECT_EQ(every["windows_schedule"], "every");
  EXPECT_EQ(quiet["windows_schedule"], "quiet");
  const double e = every["joints"]["hip"]["rmse_rad"], q = quiet["joints"]["hip"]["rmse_rad"];
  std::printf("hip: every 0.5 s %.3f deg (%d windows), quiet %.3f deg (%d windows)\n", e * 57.2958,
              every["windows"].get<int>(), q * 57.2958, quiet["windows"].get<int>());
  EXPECT_LT(q, 0.1 * e);
  EXPECT_GE(quiet["windows"].get<int>(), 10);
  const auto a = Replay(RigModel(kLearned), "--windows every", "rig_every");
  const auto b = Replay(RigModel(kLearned), "--windows quiet", "rig_quiet");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const auto ra = nlohmann::json::parse(std::ifstream(dir_ + "/rig_every/replay.json"));
  const auto rb = nlohmann::json::parse(std::ifstream(dir_ + "/rig_quiet/replay.json"));
  EXPECT_EQ(ra["windows"], rb["windows"]);
  const int na = ra["records"][0]["samples"], nb = rb["records"][0]["samples"];
  EXPECT_LE(nb, na);
  EXPECT_GE(nb, 0.95 * na);
}

TEST_F(ReplayCli, WindowsNeitherEveryNorQuiet) {
  ExpectBadInput(Replay(RigModel("[]"), "--windows some"), "--windows: expected 'every' or 'quiet', got 'some'");
}

TEST_F(ReplayCli, BetweenSamplesNeitherLinearNorHold) {
  ExpectBadInput(Replay(RigModel("[]"), "--between-samples cubic"), "--between-samples: expected 'linear' or 'hold', got 'cubic'");
}

TEST_F(ReplayCli, HorizonNotPositive) { ExpectBadInput(Replay(RigModel("[]"), "--horizon 0"), "--horizon"); }

TEST_F(ReplayCli, HorizonLongerThanTheRecord) {
  ExpectBadInput(Replay(RigModel("[]"), "--horizon 11"), "trajectory_05.csv: --horizon 11");
}

TEST_F(ReplayCli, CommandInputWithoutCommandColumns) {
  const std::string csv = dir_ + "/plain.csv";
  std::string text = "t,q_hip,q_knee,tau_hip,tau_knee\n";
  for (int i = 0; i < 1000; ++i) text += std::to_string(i * 0.002) + ",0.1,-0.2,0.05,0.01\n";
  WriteText(csv, text);
  WriteText(dir_ + "/m.yaml", RigModel("[]"));
  ExpectBadInput(RunExotwin("replay --params " + dir_ + "/m.yaml --measured " + csv + " --input command --out " + dir_ + "/out"),
                 "plain.csv: --input command needs the column 'cmd_hip'");
}

TEST_F(ReplayCli, AnEffectThePlantCannotCarry) {
  ExpectBadInput(Replay(RigModel("[{name: viscous_friction, joint: hip, value: 0.01}, {name: muscle_activity, joint: knee, value: 1, weights: {vl: 0.1}}]"), ""),
                 "m.yaml: effects[1] (muscle_activity, knee): the forward plant cannot carry");
}

// A one-joint model file (DESIGN.md "One-joint devices") replays a one-joint record: the embedding's
// hip held, the files carry the knee alone (no hip columns or keys). The makers' nominal point mass
// against the README's reference fit (I 0.177, mgl 3.53, R 0.002, C 0.15) on the shipped record.
TEST_F(ReplayCli, AOneJointModelReplaysAOneJointRecord) {
  const std::string pendulum = std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/simple_pendulum/";
  auto Run = [&](const std::string& model, const std::string& out) {
    return RunExotwin("replay --params " + model + " --measured " + pendulum + "pd_system_identification.csv" +
                      " --map " + pendulum + "dfki_simple_pendulum.map.yaml --out " + dir_ + "/" + out);
  };
  const auto nominal = Run(pendulum + "model.yaml", "nominal");
  ASSERT_EQ(nominal.exit_code, 0) << nominal.output;
  EXPECT_EQ(nominal.output.find("hip"), std::string::npos) << nominal.output;
  WriteText(dir_ + "/fit.yaml", "joint: knee\ndevice: {I: 0.177, mgl: 3.53, R: 0.002, C: 0.15}\neffects: []\n");
  const auto fit = Run(dir_ + "/fit.yaml", "fit");
  ASSERT_EQ(fit.exit_code, 0) << fit.output;
  const auto a = nlohmann::json::parse(std::ifstream(dir_ + "/nominal/replay.json"));
  const auto b = nlohmann::json::parse(std::ifstream(dir_ + "/fit/replay.json"));
  EXPECT_EQ(a["one_joint"], true);
  EXPECT_EQ(a["windows"], 7);  // 3.9 s of record
  EXPECT_FALSE(a["joints"].contains("hip"));
  EXPECT_FALSE(a["records"][0]["joints"].contains("hip"));
  const double before = a["joints"]["knee"]["rmse_rad"], after = b["joints"]["knee"]["rmse_rad"];
  std::printf("knee: nominal %.2f deg, reference fit %.2f deg\n", before * 57.2958, after * 57.2958);
  EXPECT_GT(before, 0.02);  // measured 2.93 deg
  EXPECT_LT(after, before);  // measured 2.80 deg
  const CsvTable t = ReadCsv(dir_ + "/fit/replay.csv");
  EXPECT_EQ(t.names, (std::vector<std::string>{"t", "q_knee", "q_knee_sim", "window", "record"}));
  EXPECT_EQ(t.columns[3].back(), 6);
}

// A record with both joints given a one-joint model file, and a one-joint record given a two-joint
// one: exit 2 naming the record and the model file.
TEST_F(ReplayCli, ARecordOfTheOtherKindIsRefused) {
  const std::string pendulum = std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/simple_pendulum/";
  const std::string one = pendulum + "model.yaml";
  ExpectBadInput(RunExotwin("replay --params " + one + " --measured " + kRecord + " --map " + kMap + " --out " + dir_ +
                            "/out"),
                 "trajectory_05.csv: a record with hip columns (q_hip, tau_hip, ...) given the one-joint model file " + one);
  WriteText(dir_ + "/m.yaml", RigModel("[]"));
  ExpectBadInput(RunExotwin("replay --params " + dir_ + "/m.yaml --measured " + pendulum + "pd_system_identification.csv" +
                            " --map " + pendulum + "dfki_simple_pendulum.map.yaml --out " + dir_ + "/out"),
                 "pd_system_identification.csv: a one-joint record (q_knee, tau_knee, no hip column) given the two-joint "
                 "model file " + dir_ + "/m.yaml");
}

}  // namespace
}  // namespace exotwin
