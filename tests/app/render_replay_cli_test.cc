// `exotwin render-replay` through the command line: a measured CSV becomes a decodable MP4 with one
// frame per 1/30 s of data, with or without a --predicted file; bad input exits 2 naming the problem.
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

TEST_F(RenderReplayCli, OutputFolderMissing) {
  const auto r = RunExotwin(Args(dir_ + "/no/such/x.mp4"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("does not exist"), std::string::npos) << r.output;
}

TEST_F(RenderReplayCli, MissingOutputOption) {
  const auto r = RunExotwin("render-replay --params " + dir_ + "/model.yaml --measured " + dir_ + "/data.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

}  // namespace
}  // namespace exotwin
