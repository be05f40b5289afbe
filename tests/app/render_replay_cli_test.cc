// `exotwin render-replay` through the command line: a measured CSV becomes a decodable MP4 with one
// frame per 1/30 s of data, with or without a --predicted file; --sim adds ghost legs from `replay`
// outputs; bad input exits 2 naming the problem.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include <opencv2/videoio.hpp>

#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::WriteText;

constexpr const char* kModel = testing::kSubjectModelYaml;

// 2 s at 1 kHz, with two EMG channels.
std::string MeasuredCsv() {
  std::ostringstream os;
  os << "t,q_hip,q_knee,tau_hip,tau_knee,emg_VM,emg_RF\n";
  for (int i = 0; i < 2000; ++i) {
    const double t = i * 0.001;
    os << t << "," << 0.5 + 0.3 * std::sin(2 * t) << "," << -0.8 + 0.4 * std::sin(3 * t) << ","
       << -20 + 3 * std::sin(2 * t) << "," << 2 * std::cos(3 * t) << "," << 0.01 * std::sin(300 * t) << ","
       << 0.02 * std::sin(170 * t) * std::sin(t) << "\n";
  }
  return os.str();
}

// A `replay` output for the first 1.5 s of MeasuredCsv() (three 0.5 s windows), the twin holding
// (q_hip_sim, q_knee_sim); `t0` shifts its time base.
std::string ReplayCsv(double q_hip_sim, double q_knee_sim, double t0 = 0.0) {
  std::ostringstream os;
  os << "# exotwin replay\nt,q_hip,q_hip_sim,q_knee,q_knee_sim,window,record\n";
  for (int i = 0; i < 1500; ++i)
    os << t0 + i * 0.001 << ",0.5," << q_hip_sim << ",-0.8," << q_knee_sim << "," << i / 500 << ",0\n";
  return os.str();
}

// Pixels of a frame's lower 60 % (below the legend) that are strongly red (the first ghost: rgba
// 0.95 0.1 0.1 0.45), which neither the skin, the exoskeleton, the floor nor the charts are.
int RedPixels(const cv::Mat& bgr) {
  int n = 0;
  for (int y = int(0.4 * bgr.rows); y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b c = bgr.at<cv::Vec3b>(y, x);
      n += c[2] > 70 && c[2] > c[1] + 50 && c[2] > c[0] + 50;
    }
  return n;
}

cv::Mat FirstFrame(const std::string& path) {
  cv::VideoCapture cap(path, cv::CAP_FFMPEG);
  cv::Mat f;
  if (cap.isOpened()) cap.read(f);
  return f;
}

long DecodedFrames(const std::string& path) {
  cv::VideoCapture cap(path, cv::CAP_FFMPEG);
  if (!cap.isOpened()) return -1;
  long n = 0;
  cv::Mat f;
  while (cap.read(f)) ++n;
  return n;
}

class RenderReplayCli : public ::testing::Test {
 protected:
  void SetUp() override {
    WriteText(dir_ + "/model.yaml", kModel);
    WriteText(dir_ + "/data.csv", MeasuredCsv());
  }
  std::string Args(const std::string& out) const {
    return "render-replay --params " + dir_ + "/model.yaml --measured " + dir_ + "/data.csv -o " + out;
  }
  const testing::ScopedTempDir tmp_{"render_replay"};
  const std::string dir_ = tmp_.path();
};

TEST_F(RenderReplayCli, WritesVideoWithTwinPrediction) {
  const auto r = RunExotwin(Args(dir_ + "/replay.mp4"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(DecodedFrames(dir_ + "/replay.mp4"), 60);
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/replay.tmp.mp4"));
}

TEST_F(RenderReplayCli, UsesPredictedFile) {
  ASSERT_EQ(RunExotwin("predict --params " + dir_ + "/model.yaml --measured " + dir_ + "/data.csv --out " +
                       dir_ + "/pred.csv").exit_code, 0);
  const auto r = RunExotwin(Args(dir_ + "/replay.mp4") + " --predicted " + dir_ + "/pred.csv --fps 25");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(DecodedFrames(dir_ + "/replay.mp4"), 50);
}

TEST_F(RenderReplayCli, PredictedFileWithoutTorqueColumn) {
  WriteText(dir_ + "/pred.csv", "t,tau_hip\n0,1\n1,2\n");
  const auto r = RunExotwin(Args(dir_ + "/x.mp4") + " --predicted " + dir_ + "/pred.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("missing column 'tau_knee'"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/x.mp4"));
}

TEST_F(RenderReplayCli, GhostLegsFromReplayFiles) {
  std::filesystem::create_directories(dir_ + "/rigid");
  std::filesystem::create_directories(dir_ + "/extended");
  WriteText(dir_ + "/rigid/replay.csv", ReplayCsv(1.5, -1.5));  // thigh out forward, shank hanging
  WriteText(dir_ + "/extended/replay.csv", ReplayCsv(-0.4, -1.5));
  const std::string small = " --width 160 --height 96 --fps 5";
  const auto plain = RunExotwin(Args(dir_ + "/plain.mp4") + small);
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  const auto r = RunExotwin(Args(dir_ + "/ghosts.mp4") + small + " --sim " + dir_ + "/rigid/replay.csv --sim " +
                            dir_ + "/extended/replay.csv --sim-label stiff");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("ghost leg 1 (red): stiff"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ghost leg 2 (green): extended"), std::string::npos) << r.output;
  EXPECT_EQ(DecodedFrames(dir_ + "/ghosts.mp4"), 10);
  // The red ghost's shank is drawn (forward of the measured leg); without --sim nothing is red.
  const cv::Mat ghosts = FirstFrame(dir_ + "/ghosts.mp4"), plain_frame = FirstFrame(dir_ + "/plain.mp4");
  ASSERT_FALSE(ghosts.empty());
  ASSERT_FALSE(plain_frame.empty());
  EXPECT_GT(RedPixels(ghosts), 40);
  EXPECT_EQ(RedPixels(plain_frame), 0);
}

// A one-joint record (the shipped pendulum) with its one-joint `replay` output (t, q_knee, q_knee_sim,
// window, record): the ghost's hip is the held 0. A two-joint record refuses that file.
TEST_F(RenderReplayCli, GhostLegOfAOneJointReplay) {
  const std::string pendulum = std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/simple_pendulum/";
  const std::string args = " --params " + pendulum + "model.yaml --measured " + pendulum +
                           "pd_system_identification.csv --map " + pendulum + "dfki_simple_pendulum.map.yaml";
  const auto rep = RunExotwin("replay" + args + " --horizon 1 --out " + dir_ + "/one");
  ASSERT_EQ(rep.exit_code, 0) << rep.output;
  const auto r = RunExotwin("render-replay" + args + " --sim " + dir_ + "/one/replay.csv --width 160 --height 96 "
                            "--fps 2 -o " + dir_ + "/one.mp4");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_GT(DecodedFrames(dir_ + "/one.mp4"), 5);
  const auto two = RunExotwin(Args(dir_ + "/x.mp4") + " --sim " + dir_ + "/one/replay.csv");
  EXPECT_EQ(two.exit_code, 2) << two.output;
  EXPECT_NE(two.output.find(dir_ + "/one/replay.csv: missing column 'q_hip_sim'"), std::string::npos) << two.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/x.mp4"));
}

TEST_F(RenderReplayCli, SimFileWithoutSimulatedAnglesIsRefused) {
  WriteText(dir_ + "/bad.csv", "t,q_hip,q_hip_sim,q_knee\n0,0,0,0\n0.001,0,0,0\n");
  const auto r = RunExotwin(Args(dir_ + "/x.mp4") + " --sim " + dir_ + "/bad.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir_ + "/bad.csv: missing column 'q_knee_sim'"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/x.mp4"));
}

TEST_F(RenderReplayCli, SimFileOfAnotherTimeRangeIsRefused) {
  WriteText(dir_ + "/late.csv", ReplayCsv(0.5, -0.8, 5.0));  // 5..6.5 s; the record covers 0..2 s
  const auto r = RunExotwin(Args(dir_ + "/x.mp4") + " --sim " + dir_ + "/late.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir_ + "/late.csv: covers"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not a replay of this record"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/x.mp4"));
}

// -o with missing parent folders: they are created (DESIGN.md "Command line", issue 41 item 6).
TEST_F(RenderReplayCli, OutputFolderMissingIsCreated) {
  const auto r = RunExotwin(Args(dir_ + "/no/such/x.mp4"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir_ + "/no/such/x.mp4")) << r.output;
}

TEST_F(RenderReplayCli, MissingOutputOption) {
  const auto r = RunExotwin("render-replay --params " + dir_ + "/model.yaml --measured " + dir_ + "/data.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

}  // namespace
}  // namespace exotwin
