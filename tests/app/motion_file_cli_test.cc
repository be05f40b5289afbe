// OpenSim motion files through the command line (issue 18 item 3): a scenario driven by Winter's
// stride written by the test as a .mot (`protocol: {trajectory: file, path: walk.mot}`), tracked as
// the Winter-table gait scenario is; `run --sto` (and `render --sto`) writes measured.sto /
// truth.sto that the reader reads back to the CSVs' values; `predict` and `render-replay` take a
// .mot as --measured; bad motion files exit 2 naming the file and the line.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "formats/csv_table.h"
#include "formats/opensim_storage.h"
#include "tests/app/cli_test_util.h"
#include "tests/motion_file.h"
#include "tests/winter_stride.h"

namespace exotwin {
namespace {

using testing::MotText;
using testing::MotVariant;
using testing::RunExotwin;
using testing::WriteText;

// gait_2kmh.yaml's set-up (S1, passive, 2 s stride, 2 s ramp, same controller and hardware), shorter.
std::string GaitScenario(const std::string& name, const std::string& trajectory, double duration) {
  return "name: " + name + "\nseed: 1\ndevice: exowheel\nsubject: {preset: S1, passive: riener1999}\n"
         "protocol: {" + trajectory + ", duration: " + std::to_string(duration) + ", trials: 1, ramp: 2.0}\n"
         "controller: {rate_hz: 1000, kp: [600, 400], kd: [30, 15], feedforward: true, torque_limit: 100}\n"
         "hardware: {can_bitrate: 1000000, can_latency: 0.00005, can_jitter: 0.00001, torque_sensor_noise: 0.024}\n"
         "checks:\n"
         "  - {name: hip tracking RMS (deg), metric: tracking_rms_hip_deg, max: 1.0}\n"
         "  - {name: knee tracking RMS (deg), metric: tracking_rms_knee_deg, max: 1.0}\n"
         "  - {name: controller stayed running, metric: safe_state_entered, max: 0}\n";
}

nlohmann::json ReadJson(const std::string& path) { return nlohmann::json::parse(testing::ReadText(path)); }

class MotionFileCli : public ::testing::Test {
 protected:
  void WriteMot(const std::string& path, const MotVariant& v = MotVariant()) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    const testing::SampledStride w = testing::WinterStride(100.0);
    WriteText(path, MotText(w.t, w.hip, w.knee, v));
  }
  const testing::ScopedTempDir tmp_{"motion_cli"};
  const std::string dir_ = tmp_.path();
};

TEST_F(MotionFileCli, MotDrivenScenarioTracksAsTheWinterGaitAndWritesSto) {
  WriteMot(dir_ + "/motions/walk.mot");
  WriteText(dir_ + "/mot.yaml", GaitScenario("walk_mot", "trajectory: file, path: motions/walk.mot, side: r", 60));
  WriteText(dir_ + "/gait.yaml", GaitScenario("walk_winter", "trajectory: gait, stride_period: 2.0", 60));
  const std::string cwd = std::filesystem::current_path().string();
  const auto m = RunExotwin("run " + dir_ + "/mot.yaml --out " + dir_ + "/out_mot --sto");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  const auto g = RunExotwin("run " + dir_ + "/gait.yaml --out " + dir_ + "/out_gait");
  ASSERT_EQ(g.exit_code, 0) << g.output;
  const nlohmann::json jm = ReadJson(dir_ + "/out_mot/result.json"), jg = ReadJson(dir_ + "/out_gait/result.json");
  const double mh = jm["metrics"]["tracking_rms_hip_deg"], mk = jm["metrics"]["tracking_rms_knee_deg"];
  const double gh = jg["metrics"]["tracking_rms_hip_deg"], gk = jg["metrics"]["tracking_rms_knee_deg"];
  std::printf("tracking RMS (deg), 60 s, S1 at 2 km/h: .mot stride hip %.4f knee %.4f; Winter-table gait hip %.4f "
              "knee %.4f\n", mh, mk, gh, gk);
  EXPECT_LT(mh, 1.0);
  EXPECT_LT(mk, 1.0);
  EXPECT_NEAR(mh, gh, 0.25 * gh + 0.02);  // the same reference up to the 100 Hz sampling
  EXPECT_NEAR(mk, gk, 0.25 * gk + 0.02);

  // The recorded references agree with Winter's: the runs' measured angles differ little.
  const CsvTable am = ReadCsv(dir_ + "/out_mot/measured.csv"), ag = ReadCsv(dir_ + "/out_gait/measured.csv");
  ASSERT_EQ(am.rows(), ag.rows());
  double worst = 0;
  for (const char* q : {"q_hip", "q_knee"})
    for (size_t i = 0; i < am.rows(); ++i)
      worst = std::max(worst, std::abs(am.columns[am.Find(q)][i] - ag.columns[ag.Find(q)][i]));
  std::printf("largest |q_mot - q_winter| over the run: %.4f deg\n", worst * 180 / M_PI);
  EXPECT_LT(worst * 180 / M_PI, 0.3);

  // --sto: the same content, read back by the reader bit for bit (time <- t).
  EXPECT_NE(m.output.find("wrote " + dir_ + "/out_mot/measured.sto"), std::string::npos) << m.output;
  for (const char* base : {"measured", "truth"}) {
    const CsvTable csv = ReadCsv(dir_ + "/out_mot/" + base + ".csv");
    const StorageTable sto = ReadStorage(dir_ + "/out_mot/" + base + ".sto");
    EXPECT_EQ(sto.in_degrees, 0) << base;
    ASSERT_EQ(sto.names.size(), csv.names.size()) << base;
    for (size_t c = 0; c < csv.names.size(); ++c) {
      EXPECT_EQ(sto.names[c], csv.names[c] == "t" ? "time" : csv.names[c]);
      EXPECT_EQ(sto.columns[c], csv.columns[c]) << base << " " << csv.names[c];
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/out_gait/measured.sto"));  // only on request
  EXPECT_EQ(std::filesystem::current_path().string(), cwd);
}

TEST_F(MotionFileCli, BadMotionFileExitsTwoNamingFileAndLine) {
  MotVariant v;
  v.state_unit = false;  // nRows, nColumns, ..., endheader on line 9: the unit cannot be told
  WriteMot(dir_ + "/walk.mot", v);
  WriteText(dir_ + "/s.yaml", GaitScenario("bad", "trajectory: file, path: walk.mot", 1));
  auto r = RunExotwin("run " + dir_ + "/s.yaml --out " + dir_ + "/o");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir_ + "/walk.mot: line 9"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("inDegrees"), std::string::npos) << r.output;
  // non-monotonic time
  WriteText(dir_ + "/t.mot", "walk\nnRows=3\nnColumns=3\ninDegrees=yes\nendheader\ntime hip_flexion_r knee_angle_r\n"
                              "0 10 -20\n0.02 11 -21\n0.01 12 -22\n");
  WriteText(dir_ + "/t.yaml", GaitScenario("bad_t", "trajectory: file, path: t.mot", 1));
  r = RunExotwin("run " + dir_ + "/t.yaml --out " + dir_ + "/o2");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir_ + "/t.mot: line 9: time 0.01 s does not increase"), std::string::npos) << r.output;
  // no time column; fewer columns than the header says
  WriteText(dir_ + "/n.mot", "inDegrees=yes\nendheader\nframe hip_flexion_r knee_angle_r\n0 1 2\n1 1 2\n");
  WriteText(dir_ + "/m.yaml", testing::kSubjectModelYaml);
  r = RunExotwin("predict --params " + dir_ + "/m.yaml --measured " + dir_ + "/n.mot --out " + dir_ + "/p.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir_ + "/n.mot: line 3: no 'time' column"), std::string::npos) << r.output;
  WriteText(dir_ + "/c.mot", "nColumns=4\ninDegrees=yes\nendheader\ntime hip_flexion_r knee_angle_r\n0 1 2\n1 1 2\n");
  r = RunExotwin("predict --params " + dir_ + "/m.yaml --measured " + dir_ + "/c.mot --out " + dir_ + "/p.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir_ + "/c.mot: line 4: 3 column names, the header says nColumns=4"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/p.csv"));
}

TEST_F(MotionFileCli, PredictAndRenderReplayTakeAMotionFile) {
  MotVariant v;
  v.side = "l";
  v.header = MotVariant::Header::kToolLines;
  v.sep = ' ';
  WriteMot(dir_ + "/walk_l.mot", v);
  WriteText(dir_ + "/model.yaml", testing::kSubjectModelYaml);
  auto r = RunExotwin("predict --params " + dir_ + "/model.yaml --measured " + dir_ + "/walk_l.mot --side l --out " +
                      dir_ + "/pred.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("kinematics only"), std::string::npos) << r.output;
  const CsvTable p = ReadCsv(dir_ + "/pred.csv");
  EXPECT_EQ(p.names, (std::vector<std::string>{"t", "tau_hip", "tau_knee"}));
  EXPECT_EQ(p.rows(), 200u);
  // The twin holds the leg against gravity: the mean hip reading is well away from zero.
  double mean = 0;
  for (double x : p.columns[1]) mean += x / p.rows();
  EXPECT_GT(std::abs(mean), 1.0);
  r = RunExotwin("predict --params " + dir_ + "/model.yaml --measured " + dir_ + "/walk_l.mot --out " + dir_ + "/x.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;  // side r by default: no hip_flexion_r
  EXPECT_NE(r.output.find("no column 'hip_flexion_r'"), std::string::npos) << r.output;
  r = RunExotwin("predict --params " + dir_ + "/model.yaml --measured " + dir_ + "/walk_l.mot --side l --cutoff auto "
                 "--out " + dir_ + "/x.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("kinematics only"), std::string::npos) << r.output;

  r = RunExotwin("render-replay --params " + dir_ + "/model.yaml --measured " + dir_ + "/walk_l.mot --side l -o " +
                 dir_ + "/replay.mp4 --width 160 --height 120 --fps 10");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_GT(std::filesystem::file_size(dir_ + "/replay.mp4"), 1000u);
}

}  // namespace
}  // namespace exotwin

namespace exotwin {
namespace {

TEST(RenderSto, RenderWritesTheLogsAsStorageFilesOnRequest) {
  const testing::ScopedTempDir tmp("render_sto");
  const std::string dir = tmp.path();
  WriteText(dir + "/s.yaml", "name: hold\ndevice: exowheel\nsubject: {preset: S1}\n"
                             "protocol: {trajectory: hold, duration: 0.2, ramp: 0}\n");
  const auto r = RunExotwin("render " + dir + "/s.yaml -o " + dir + "/v.mp4 --out " + dir + "/o --sto");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* base : {"measured", "truth"}) {
    const CsvTable csv = ReadCsv(dir + "/o/" + base + ".csv");
    const StorageTable sto = ReadStorage(dir + "/o/" + base + ".sto");
    EXPECT_EQ(sto.rows(), csv.rows()) << base;
    EXPECT_EQ(sto.Time(), csv.columns[csv.Find("t")]) << base;
  }
}

}  // namespace
}  // namespace exotwin
