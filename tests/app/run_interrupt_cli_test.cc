// `exotwin run` stopped by SIGTERM or SIGINT (issue 21): the run ends after the current step, closes
// its logs (every row of measured.csv whole, the last at or before the time reached), writes
// result.json with "interrupted" {signal, name, t_s, trial} and every check failed, and exits 128 + N
// (143 SIGTERM, 130 SIGINT). DESIGN.md "Interrupted runs".
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

constexpr double kDuration = 600;  // s: far longer than the test waits

// Data lines of a CSV (after the '#' comments): the header's column count and, per row, its fields.
struct CsvLines {
  size_t header_columns = 0;
  std::vector<std::vector<std::string>> rows;
  bool ends_with_newline = false;
};

CsvLines ReadCsvLines(const std::string& path) {
  const std::string text = testing::ReadText(path);
  CsvLines out;
  out.ends_with_newline = !text.empty() && text.back() == '\n';
  std::istringstream in(text);
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    if (header) {
      out.header_columns = fields.size();
      header = false;
    } else {
      out.rows.push_back(fields);
    }
  }
  return out;
}

size_t DataRows(const std::string& path) {
  const std::string text = testing::ReadText(path);
  size_t n = 0;
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n' && i + 1 < text.size() && text[i + 1] != '#') ++n;
  return n > 0 ? n - 1 : 0;  // the header
}

// Runs a long hold scenario, sends `sig` once measured.csv holds a few rows, and checks the run's end.
void InterruptRun(int sig, const char* name) {
  const testing::ScopedTempDir tmp("run_interrupt");
  const std::string yaml = tmp.File("long.yaml"), out = tmp.File("out");
  std::ofstream(yaml) << "name: long_hold\nseed: 1\ndevice: exowheel\nsubject: {preset: S1}\n"
                         "protocol: {trajectory: hold, duration: "
                      << kDuration << ", ramp: 0.1}\n"
                      << "checks:\n  - {name: tracking, metric: tracking_rms_hip_deg, max: 100}\n";
  const pid_t pid = testing::StartExotwin({"run", yaml, "--out", out});
  ASSERT_GE(pid, 0);
  const std::string log = out + "/measured.csv";
  for (int i = 0; i < 6000 && DataRows(log) < 500; ++i)  // up to 60 s (slow under sanitizers)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  kill(pid, sig);
  int status = 0;
  for (int i = 0; i < 6000 && waitpid(pid, &status, WNOHANG) == 0; ++i)  // the stop takes one step
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (waitpid(pid, &status, WNOHANG) == 0) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    FAIL() << "the run did not stop within 60 s of " << name;
  }
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 128 + sig);

  std::ifstream in(out + "/result.json");
  ASSERT_TRUE(in.good()) << "no result.json";
  const nlohmann::json j = nlohmann::json::parse(in);
  const nlohmann::json& stop = j.at("interrupted");
  EXPECT_EQ(stop.at("signal").get<int>(), sig);
  EXPECT_EQ(stop.at("name").get<std::string>(), name);
  EXPECT_EQ(stop.at("trial").get<int>(), 1);
  const double t_s = stop.at("t_s").get<double>();
  EXPECT_GT(t_s, 0.0);
  EXPECT_LT(t_s, kDuration);
  ASSERT_EQ(j.at("checks").size(), 1u);
  EXPECT_FALSE(j.at("checks").at(0).at("passed").get<bool>());
  EXPECT_GT(j.at("metrics").at("samples").get<double>(), 0.0);

  const CsvLines csv = ReadCsvLines(log);
  EXPECT_TRUE(csv.ends_with_newline);
  ASSERT_GT(csv.header_columns, 1u);
  ASSERT_GE(csv.rows.size(), 500u);
  for (size_t r = 0; r < csv.rows.size(); ++r)
    ASSERT_EQ(csv.rows[r].size(), csv.header_columns) << "row " << r;
  EXPECT_EQ(static_cast<double>(csv.rows.size()), j.at("metrics").at("samples").get<double>());
  const double t_last = std::stod(csv.rows.back()[0]);
  EXPECT_LE(t_last, t_s + 1e-3);
  EXPECT_GT(t_last, t_s - 0.1);  // the logs hold the run up to where it stopped (100 Hz logging at most)
}

TEST(RunInterrupt, SigtermWritesInterruptedResultAndExits143) { InterruptRun(SIGTERM, "SIGTERM"); }

TEST(RunInterrupt, SigintWritesInterruptedResultAndExits130) { InterruptRun(SIGINT, "SIGINT"); }

}  // namespace
}  // namespace exotwin
