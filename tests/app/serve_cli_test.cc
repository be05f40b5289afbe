// `exotwin serve` with `exotwin-controller` in another process (issue 17; DESIGN.md "The CAN transport
// between processes"): lockstep gives the in-process run byte for byte; a killed controller leaves the
// twin running with the joint modules' watchdogs cutting the torque; real time runs to the end and
// reports its timing; start-up in either order and a restarted twin; bad input exits 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <linux/can.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "formats/csv_table.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::ReadText;
using testing::WriteText;

// The shipped gait scenario shortened to `duration` s.
std::string GaitScenario(const std::string& dir, double duration, const std::string& name = "gait.yaml") {
  std::string text = ReadText(std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/gait_2kmh.yaml");
  const size_t at = text.find("duration: 60");
  text.replace(at, 12, "duration: " + std::to_string(duration));
  WriteText(dir + "/" + name, text);
  return dir + "/" + name;
}

// Waits for `pid` up to `seconds`; its exit code (128 + N when killed by signal N), -1 on time-out (the
// process is then killed).
int WaitFor(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int st = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &st, WNOHANG) == pid) return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &st, 0);
  return -1;
}

bool WaitForFile(const std::string& path, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (std::filesystem::exists(path)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

nlohmann::json Result(const std::string& dir) { return nlohmann::json::parse(ReadText(dir + "/result.json")); }

// Newlines in a file being written (a progress measure: comments and header count too).
size_t Lines(const std::string& path) {
  const std::string t = ReadText(path);
  return static_cast<size_t>(std::count(t.begin(), t.end(), '\n'));
}

// The output (stdout + stderr) of a shell command.
std::string Shell(const std::string& cmd) {
  std::string out;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  pclose(p);
  return out;
}

struct Pair {
  int serve = -1, controller = -1;
  std::string serve_log, controller_log;
};

// serve SCENARIO --bus BUS --out OUT (+ extra), then the controller on OUT/controller.yaml.
// config: the controller's --config (default: the controller file serve writes); bus: default
// unix:DIR/bus.
Pair ServeWithController(const std::string& dir, const std::string& scenario, const std::string& out,
                         std::vector<std::string> extra = {}, double seconds = 120, std::string config = "",
                         std::string bus = "") {
  if (bus.empty()) bus = "unix:" + dir + "/bus";
  std::vector<std::string> args = {"serve", scenario, "--bus", bus, "--out", out};
  args.insert(args.end(), extra.begin(), extra.end());
  Pair p;
  const pid_t serve = testing::StartProgram(testing::ExotwinBin(), args, dir + "/serve.log");
  EXPECT_TRUE(WaitForFile(out + "/controller.yaml", 30));
  const pid_t ctl = testing::StartProgram(
      testing::ControllerBin(), {"--config", config.empty() ? out + "/controller.yaml" : config, "--bus", bus},
      dir + "/ctl.log");
  p.serve = WaitFor(serve, seconds);
  p.controller = WaitFor(ctl, 30);
  p.serve_log = ReadText(dir + "/serve.log");
  p.controller_log = ReadText(dir + "/ctl.log");
  return p;
}

// Over each transport between two processes on one host: unix:DIR/bus and shm:NAME.
class ServeCliTransport : public ::testing::TestWithParam<std::string> {
 protected:
  static std::string Bus(const std::string& dir) {
    return GetParam() == "unix" ? "unix:" + dir + "/bus" : "shm:exotwin_serve_test_" + std::to_string(::getpid());
  }
};

TEST_P(ServeCliTransport, LockstepWritesTheSameMeasuredCsvAsRun) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 4.0);
  const auto run = testing::RunExotwin("run " + scenario + " --out " + dir.path() + "/run");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string bus = Bus(dir.path());
  const Pair p = ServeWithController(dir.path(), scenario, dir.path() + "/serve", {}, 120, "", bus);
  ASSERT_EQ(p.serve, 0) << p.serve_log;
  EXPECT_EQ(p.controller, 0) << p.controller_log;
  const std::string a = ReadText(dir.path() + "/run/measured.csv"), b = ReadText(dir.path() + "/serve/measured.csv");
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "measured.csv differs between run and serve";
  EXPECT_TRUE(ReadText(dir.path() + "/run/truth.csv") == ReadText(dir.path() + "/serve/truth.csv"));
  const nlohmann::json r = Result(dir.path() + "/serve");
  EXPECT_EQ(r["metrics"]["link_deterministic"], 1.0);
  EXPECT_EQ(r["metrics"]["link_frames_foreign"], 0.0);
  EXPECT_EQ(r["metrics"]["tracking_rms_hip_deg"], Result(dir.path() + "/run")["metrics"]["tracking_rms_hip_deg"]);
  EXPECT_NE(p.controller_log.find("run over (NMT stop): 4000 ticks"), std::string::npos) << p.controller_log;
  EXPECT_NE(p.serve_log.find("link " + GetParam() + ":"), std::string::npos) << p.serve_log;
  if (GetParam() == "shm") {
    EXPECT_FALSE(std::filesystem::exists("/dev/shm/" + bus.substr(4)));  // removed when both ends left
  }
}

// DESIGN.md: `exotwin-controller --config SCENARIO.yaml`: the scenario's controller part, the
// feed-forward model and reference downloaded from the twin (link::kIdConfigRequest): the same bytes.
TEST(ServeCli, ControllerStartedOnTheScenarioFileWritesTheSameMeasuredCsvAsRun) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 3.0);
  const auto run = testing::RunExotwin("run " + scenario + " --out " + dir.path() + "/run");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const Pair p = ServeWithController(dir.path(), scenario, dir.path() + "/serve", {}, 120, scenario);
  ASSERT_EQ(p.serve, 0) << p.serve_log;
  EXPECT_EQ(p.controller, 0) << p.controller_log;
  EXPECT_NE(p.controller_log.find("controller file for " + scenario + " received"), std::string::npos) << p.controller_log;
  const std::string a = ReadText(dir.path() + "/run/measured.csv"), b = ReadText(dir.path() + "/serve/measured.csv");
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "measured.csv differs between run and serve with the scenario as the controller's config";
}

// A scenario whose controller part differs from the served one: the controller refuses it (exit 2).
TEST(ServeCli, ControllerOnAnotherScenarioRefusesTheTwinsFile) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 1.0);
  std::string other = ReadText(scenario);
  const size_t at = other.find("kp: [600, 400]");
  ASSERT_NE(at, std::string::npos);
  other.replace(at, 14, "kp: [123, 45]");
  testing::WriteText(dir.path() + "/other.yaml", other);
  const Pair p = ServeWithController(dir.path(), scenario, dir.path() + "/serve", {"--timeout", "2"}, 120,
                                     dir.path() + "/other.yaml");
  EXPECT_EQ(p.controller, 2) << p.controller_log;
  EXPECT_NE(p.controller_log.find("the twin serves another controller"), std::string::npos) << p.controller_log;
  EXPECT_EQ(p.serve, 1) << p.serve_log;  // no controller answered: the run fails, logs kept
}

TEST_P(ServeCliTransport, ControllerKilledMidGaitWatchdogCutsTheTorque) {
  testing::ScopedTempDir dir("serve");
  // 30 s: long enough (0.1 s of wall clock at least, over shm at the in-process speed) for the kill to
  // come before the end.
  const std::string scenario = GaitScenario(dir.path(), 30.0), out = dir.path() + "/serve", bus = Bus(dir.path());
  const pid_t serve = testing::StartProgram(testing::ExotwinBin(), {"serve", scenario, "--bus", bus, "--out", out},
                                            dir.path() + "/serve.log");
  ASSERT_TRUE(WaitForFile(out + "/controller.yaml", 30));
  const pid_t ctl = testing::StartProgram(testing::ControllerBin(), {"--config", out + "/controller.yaml", "--bus", bus});
  // Mid-gait: once the twin has logged past 2.5 s (simulated) the controller is killed.
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end && Lines(out + "/measured.csv") < 2500)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ::kill(ctl, SIGKILL);
  EXPECT_EQ(WaitFor(ctl, 10), 128 + SIGKILL);
  const int rc = WaitFor(serve, 60);
  EXPECT_EQ(rc, 1) << ReadText(dir.path() + "/serve.log");  // a run that lost its controller fails
  const nlohmann::json r = Result(out);
  EXPECT_EQ(r["metrics"]["link_deterministic"], 0.0);
  const double t_lost = r["metrics"]["link_controller_lost_s"];
  EXPECT_GT(t_lost, 2.0);
  EXPECT_LT(t_lost, 29.9);
  bool event = false;
  for (const auto& e : r["events"]) event |= e.get<std::string>().find("controller_lost") != std::string::npos;
  EXPECT_TRUE(event) << r["events"];
  // Every log whole; from 50 ms after the loss on (watchdog 20 ms), no actuator torque (truth.csv tau_R_hip, tau_R_knee).
  // ReadCsv (the project's reader) refuses a row with a missing field: every row is whole.
  const CsvTable truth = ReadCsv(out + "/truth.csv"), measured = ReadCsv(out + "/measured.csv");
  ASSERT_EQ(truth.rows(), 30000u);
  ASSERT_EQ(measured.rows(), 30000u);
  const int t = truth.Find("t"), hip = truth.Find("tau_R_hip"), knee = truth.Find("tau_R_knee");
  ASSERT_TRUE(t >= 0 && hip >= 0 && knee >= 0);
  double before = 0, after = 0;
  for (size_t i = 0; i < truth.rows(); ++i) {
    const double tau = std::abs(truth.columns[hip][i]) + std::abs(truth.columns[knee][i]);
    if (truth.columns[t][i] < t_lost) before = std::max(before, tau);
    if (truth.columns[t][i] > t_lost + 0.05) after = std::max(after, tau);
  }
  EXPECT_GT(before, 1.0);  // the controller was holding the leg
  EXPECT_LT(after, 1e-9);  // the driver's current loop (first order, hardware.motor_lag) decays to nothing
}

TEST(ServeCli, RealtimeRunsToTheEndAndReportsJitter) {  // 2 s of gait: 2000 ticks, each counted once
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 2.0);
  const Pair p = ServeWithController(dir.path(), scenario, dir.path() + "/serve", {"--clock", "realtime"});
  EXPECT_TRUE(p.serve == 0 || p.serve == 1) << p.serve_log;  // timing decides tracking on a loaded machine
  EXPECT_EQ(p.controller, 0) << p.controller_log;
  const nlohmann::json r = Result(dir.path() + "/serve");
  EXPECT_EQ(r["metrics"]["samples"], 2000.0);
  for (const char* k : {"link_jitter_p50_us", "link_jitter_p99_us", "link_jitter_max_us", "link_late_cycles",
                        "link_missed_cycles"})
    EXPECT_TRUE(r["metrics"].contains(k)) << k;
  // The histogram counts every tick once; the largest jitter lies in its last non-empty bin.
  const nlohmann::json& h = r["link_jitter_histogram"];
  const std::vector<double> edges = h["edges_us"];
  const std::vector<double> counts = h["counts"];
  ASSERT_EQ(edges.size(), counts.size());
  double total = 0;
  size_t last = 0;
  for (size_t i = 0; i < counts.size(); ++i) total += counts[i], last = counts[i] > 0 ? i : last;
  EXPECT_EQ(total, 2000.0);
  const double max_us = r["metrics"]["link_jitter_max_us"];
  EXPECT_GE(max_us, edges[last]);
  if (last + 1 < edges.size()) {
    EXPECT_LT(max_us, edges[last + 1]);
  }
}

TEST_P(ServeCliTransport, ControllerStartedBeforeTheTwinAndTwinRestartedUnderIt) {
  testing::ScopedTempDir dir("serve");
  const std::string bus = Bus(dir.path());
  const std::string scenario = GaitScenario(dir.path(), 1.0), longer = GaitScenario(dir.path(), 600, "long.yaml");
  // A controller file from a first lockstep pair.
  const Pair first = ServeWithController(dir.path(), scenario, dir.path() + "/first", {}, 120, "", bus);
  ASSERT_EQ(first.serve, 0) << first.serve_log;
  // The controller first, then a twin that dies (SIGKILL) mid-run, then a new twin: the controller
  // starts a fresh loop for it and the second run is the in-process run.
  const pid_t ctl = testing::StartProgram(testing::ControllerBin(),
                                          {"--config", dir.path() + "/first/controller.yaml", "--bus", bus},
                                          dir.path() + "/ctl.log");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const pid_t dead = testing::StartProgram(testing::ExotwinBin(), {"serve", longer, "--bus", bus, "--out", dir.path() + "/dead"});
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < end && Lines(dir.path() + "/dead/measured.csv") < 300)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(dead, SIGKILL);
  EXPECT_EQ(WaitFor(dead, 10), 128 + SIGKILL);
  const auto again = testing::RunExotwin("serve " + scenario + " --bus " + bus + " --out " + dir.path() + "/again");
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(WaitFor(ctl, 30), 0);
  const std::string log = ReadText(dir.path() + "/ctl.log");
  EXPECT_NE(log.find("trial 1: control loop started"), log.rfind("trial 1: control loop started")) << log;
  EXPECT_TRUE(ReadText(dir.path() + "/first/measured.csv") == ReadText(dir.path() + "/again/measured.csv"));
  EXPECT_EQ(Result(dir.path() + "/again")["metrics"]["link_deterministic"], 1.0);
}

INSTANTIATE_TEST_SUITE_P(, ServeCliTransport, ::testing::Values("unix", "shm"),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

TEST(ServeCli, NoControllerWithinTheTimeoutRunsOnSafely) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 0.5);
  const auto r = testing::RunExotwin("serve " + scenario + " --bus unix:" + dir.path() + "/bus --timeout 0.3 --out " +
                                     dir.path() + "/o");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("NOT deterministic"), std::string::npos) << r.output;
  const nlohmann::json j = Result(dir.path() + "/o");
  EXPECT_EQ(j["metrics"]["link_controller_lost_s"], 0.0);
  EXPECT_EQ(j["metrics"]["torque_max_hip"], 0.0);
}

// Security (issue 17): a second, unconfigured peer floods the twin's socket with full-torque commands
// during a lockstep run; nothing it sends reaches the plant (the logs are the in-process run's).
TEST(ServeCli, FramesOfAnUnconfiguredPeerNeverReachThePlant) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 2.0);
  ASSERT_EQ(testing::RunExotwin("run " + scenario + " --out " + dir.path() + "/run").exit_code, 0);
  std::atomic<bool> stop{false};
  std::atomic<int> sent{0};
  std::thread intruder([&] {
    const int fd = ::socket(AF_UNIX, SOCK_DGRAM, 0);
    sockaddr_un self{}, to{};
    self.sun_family = to.sun_family = AF_UNIX;
    std::snprintf(self.sun_path, sizeof self.sun_path, "%s/intruder", dir.path().c_str());
    std::snprintf(to.sun_path, sizeof to.sun_path, "%s/bus", dir.path().c_str());
    ::bind(fd, reinterpret_cast<sockaddr*>(&self), sizeof self);
    can_frame cf{};
    cf.can_dlc = 4;
    cf.data[1] = 0x7F;  // +327 N m, enabled
    cf.data[3] = 0x01;
    while (!stop) {
      for (uint32_t id : {0x100u, 0x101u}) {
        cf.can_id = id;
        if (::sendto(fd, &cf, sizeof cf, MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&to), sizeof to) == sizeof cf) ++sent;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    ::close(fd);
    ::unlink(self.sun_path);
  });
  const Pair p = ServeWithController(dir.path(), scenario, dir.path() + "/serve");
  stop = true;
  intruder.join();
  EXPECT_EQ(p.serve, 0) << p.serve_log;
  EXPECT_GT(sent.load(), 0);
  const nlohmann::json r = Result(dir.path() + "/serve");
  EXPECT_GT(r["metrics"]["link_frames_foreign"].get<double>(), 0.0);
  EXPECT_TRUE(ReadText(dir.path() + "/run/measured.csv") == ReadText(dir.path() + "/serve/measured.csv"));
  EXPECT_TRUE(ReadText(dir.path() + "/run/truth.csv") == ReadText(dir.path() + "/serve/truth.csv"));
}

// The regression gate on the deployable controller: baselines made in-process hold, bit for bit, when
// the suite runs with exotwin-controller in another process.
TEST(ServeCli, RegressWithTheControllerProcessMatchesInProcessBaselines) {
  testing::ScopedTempDir dir("serve");
  std::filesystem::create_directories(dir.path() + "/suite");
  GaitScenario(dir.path() + "/suite", 1.5);
  const std::string base = "regress --jobs 1 --suite " + dir.path() + "/suite --out " + dir.path() + "/";
  const auto made = testing::RunExotwin(base + "update --update");
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const auto r = testing::RunExotwin(base + "cp --controller-process");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("1 scenarios, 0 failed, 0 metrics moved"), std::string::npos) << r.output;
  EXPECT_NE(ReadText(dir.path() + "/cp/gait_2kmh/controller.log").find("run over (NMT stop): 1500 ticks"),
            std::string::npos);
  const auto bad = testing::RunExotwin(base + "x --controller-process --controller-bin " + dir.path() + "/nothing");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find(dir.path() + "/nothing"), std::string::npos) << bad.output;
}

// A shipped scenario with its text edited: each {from, to} replaced once (the test fails if absent).
std::string EditedScenario(const std::string& dir, const std::string& shipped,
                           const std::vector<std::pair<std::string, std::string>>& edits) {
  std::string text = ReadText(std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/" + shipped);
  for (const auto& [from, to] : edits) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  }
  WriteText(dir + "/" + shipped, text);
  return dir + "/" + shipped;
}

// The HAL-3 knee loop as the deployable controller (a controller file with `hal:`, the EMG calibration
// and tau_c of the run): lockstep gives the in-process run's logs byte for byte.
TEST(ServeCli, HalAssistThroughServeWritesTheSameMeasuredCsvAsRun) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = EditedScenario(dir.path(), "hal3_exp2_assist.yaml", {{"duration: 12", "duration: 5"}});
  const auto run = testing::RunExotwin("run " + scenario + " --out " + dir.path() + "/run");
  const Pair p = ServeWithController(dir.path(), scenario, dir.path() + "/serve");
  EXPECT_EQ(p.serve, run.exit_code) << p.serve_log << run.output;
  EXPECT_EQ(p.controller, 0) << p.controller_log;
  EXPECT_NE(p.controller_log.find("HAL-3 knee loop, mode assist"), std::string::npos) << p.controller_log;
  const std::string a = ReadText(dir.path() + "/run/measured.csv"), b = ReadText(dir.path() + "/serve/measured.csv");
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "measured.csv differs between run and serve (HAL-3)";
  EXPECT_TRUE(ReadText(dir.path() + "/run/truth.csv") == ReadText(dir.path() + "/serve/truth.csv"));
  const nlohmann::json r = Result(dir.path() + "/serve"), q = Result(dir.path() + "/run");
  EXPECT_EQ(r["metrics"]["link_deterministic"], 1.0);
  for (const char* m : {"rls_D_mean", "rls_K_mean", "rls_I_hat", "emg_gaps", "strain_up_Nm", "J_tau_m"})
    EXPECT_EQ(r["metrics"][m], q["metrics"][m]) << m;
  EXPECT_NE(p.controller_log.find("run over (NMT stop): 5000 ticks"), std::string::npos) << p.controller_log;
}

// The regression gate runs every kind of scenario through the deployable controller: a HAL-3 sweep (one
// configuration per swept viscosity, downloaded at each run's NMT start) and an EMG calibration
// protocol (isometric sub-trials, each with its own controller file) hold their in-process baselines.
TEST(ServeCli, RegressWithTheControllerProcessRunsHalSweepsAndCalibrations) {
  testing::ScopedTempDir dir("serve");
  const std::string suite = dir.path() + "/suite";
  std::filesystem::create_directories(suite);
  EditedScenario(suite, "hal3_viscous_sweep.yaml",
                 {{"sweep_viscosity: [-0.5, 0.0, 0.5, 1.0, 1.25, 1.56, 1.75, 2.0, 2.25, 2.5, 3.0, 4.0]",
                   "sweep_viscosity: [0.5, 2.0]"},
                  {"duration: 10", "duration: 4.5"}});
  EditedScenario(suite, "exowheel_emg_isometric.yaml",
                 {{"contractions: 6", "contractions: 2"}, {"mvc_trials: 3", "mvc_trials: 1"}});
  const std::string base = "regress --jobs 1 --suite " + suite + " --out " + dir.path() + "/";
  const auto made = testing::RunExotwin(base + "update --update");
  ASSERT_EQ(made.exit_code == 0 || made.exit_code == 1, true) << made.output;  // checks of shortened runs may fail
  const auto r = testing::RunExotwin(base + "cp --controller-process");
  EXPECT_NE(r.output.find("2 scenarios"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 metrics moved"), std::string::npos) << r.output;
  const std::string hal_log = ReadText(dir.path() + "/cp/hal3_viscous_sweep/controller.log");
  const std::string got = "received (";  // one download per swept value, each answered before its run
  const size_t first = hal_log.find(got);
  ASSERT_NE(first, std::string::npos) << hal_log;
  EXPECT_NE(hal_log.find(got, first + 1), std::string::npos) << hal_log;
  EXPECT_NE(hal_log.find("HAL-3 loop, mode impedance"), std::string::npos) << hal_log;
  EXPECT_NE(hal_log.find("run over (NMT stop): 9000 ticks"), std::string::npos) << hal_log;
  const std::string cal_log = ReadText(dir.path() + "/cp/exowheel_emg_isometric/controller.log");
  EXPECT_NE(cal_log.find("trial 1: control loop started"), std::string::npos) << cal_log;
  EXPECT_EQ(Result(dir.path() + "/cp/exowheel_emg_isometric")["metrics"]["link_deterministic"], 1.0);
}

// The lockstep pair over a virtual SocketCAN interface, where one can be made (vcan module, root).
TEST(ServeCli, LockstepOverVcanWhereAvailable) {
  const std::string iface = "vcanexo" + std::to_string(::getpid() % 1000);
  const std::string made = Shell("ip link add dev " + iface + " type vcan && ip link set " + iface + " up && echo made");
  if (made.find("made") == std::string::npos)
    GTEST_SKIP() << "no vcan interface can be created here (needs the vcan kernel module and root): " << made;
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 1.0), out = dir.path() + "/serve";
  ASSERT_EQ(testing::RunExotwin("run " + scenario + " --out " + dir.path() + "/run").exit_code, 0);
  const pid_t serve = testing::StartProgram(testing::ExotwinBin(), {"serve", scenario, "--can", iface, "--out", out},
                                            dir.path() + "/serve.log");
  ASSERT_TRUE(WaitForFile(out + "/controller.yaml", 30));
  const pid_t ctl = testing::StartProgram(testing::ControllerBin(), {"--config", out + "/controller.yaml", "--can", iface});
  EXPECT_EQ(WaitFor(serve, 120), 0) << ReadText(dir.path() + "/serve.log");
  EXPECT_EQ(WaitFor(ctl, 30), 0);
  Shell("ip link del " + iface);
  EXPECT_TRUE(ReadText(dir.path() + "/run/measured.csv") == ReadText(out + "/measured.csv"));
}

TEST(ServeCli, BadInputExitsTwoNamingTheProblem) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 0.5);
  const std::string base = "serve " + scenario + " --out " + dir.path() + "/o ";
  auto r = testing::RunExotwin(base + "--bus unix:" + dir.path() + "/no/such/dir/bus");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(dir.path() + "/no/such/dir/bus"), std::string::npos) << r.output;
  r = testing::RunExotwin(base + "--bus tcp:1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("'tcp:1'"), std::string::npos) << r.output;
  r = testing::RunExotwin(base);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  // Link faults and real-time options out of range: exit 2 naming the option and the range.
  const std::string bus = base + "--bus unix:" + dir.path() + "/bus ";
  for (const auto& [option, expected] : std::vector<std::pair<std::string, std::string>>{
           {"--link-delay -1", "--link-delay: expected a delay of 0 to 1000 ms"},
           {"--link-jitter 2000", "--link-jitter: expected a jitter of 0 to 1000 ms"},
           {"--link-loss 1.5", "--link-loss: expected a probability of loss of 0 to 1"},
           {"--link-loss -0.1", "--link-loss: expected a probability of loss of 0 to 1"},
           {"--rt-priority 0", "--rt-priority: expected a SCHED_FIFO priority 1..99"},
           {"--rt-priority 100", "--rt-priority: expected a SCHED_FIFO priority 1..99"},
           {"--rt-spin -5", "--rt-spin: expected 0 to 1000000 us"},
           {"--link-spin -1", "--link-spin: expected 0 to 1000000 us"}}) {
    r = testing::RunExotwin(bus + option);
    EXPECT_EQ(r.exit_code, 2) << option << ": " << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << option << ": " << r.output;
  }
}

// --rt-priority that the kernel refuses (CAP_SYS_NICE dropped by setpriv, RLIMIT_RTPRIO below it): a
// warning naming what was refused and why, and the run goes on at normal priority.
TEST(ServeCli, RefusedRealtimePriorityWarnsAndRunsOn) {
  if (Shell("setpriv --version").find("setpriv") == std::string::npos) GTEST_SKIP() << "no setpriv (util-linux)";
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 0.3);
  const std::string out = Shell("setpriv --bounding-set -sys_nice --inh-caps -sys_nice " + testing::ExotwinBin() +
                                " serve " + scenario + " --bus unix:" + dir.path() + "/bus --out " + dir.path() +
                                "/o --rt-priority 50 --timeout 0.1");
  EXPECT_NE(out.find("warning: real-time request refused by the kernel: SCHED_FIFO 50: Operation not permitted"),
            std::string::npos) << out;
  EXPECT_NE(out.find("the run goes on at normal priority"), std::string::npos) << out;
  EXPECT_NE(out.find("300 samples"), std::string::npos) << out;  // the run went on (without a controller)
}

// serve --link-delay/--link-jitter/--link-loss: a poor bus on purpose, seeded on the run's seed: the
// same run twice gives the same bytes (lockstep stays deterministic), and the frames lost are counted.
TEST(ServeCli, LinkFaultsAreSeededAndDeterministic) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 2.5);
  const std::vector<std::string> faults = {"--link-delay", "1.5", "--link-jitter", "2", "--link-loss", "0.05"};
  const Pair a = ServeWithController(dir.path(), scenario, dir.path() + "/a", faults);
  EXPECT_EQ(a.controller, 0) << a.controller_log;
  const Pair b = ServeWithController(dir.path(), scenario, dir.path() + "/b", faults);
  EXPECT_EQ(b.controller, 0) << b.controller_log;
  const nlohmann::json ra = Result(dir.path() + "/a"), rb = Result(dir.path() + "/b");
  EXPECT_EQ(ra["metrics"]["link_deterministic"], 1.0);
  const double dropped = ra["metrics"]["link_frames_dropped"];
  // About 5 % of the device frames crossing the link (some 7 per ms both ways) are lost.
  EXPECT_GT(dropped, 0.02 * 7 * 2500);
  EXPECT_LT(dropped, 0.08 * 7 * 2500);
  EXPECT_EQ(rb["metrics"]["link_frames_dropped"], dropped);
  const std::string ma = ReadText(dir.path() + "/a/measured.csv");
  EXPECT_TRUE(ma == ReadText(dir.path() + "/b/measured.csv")) << "the same faults, not the same run";
  EXPECT_TRUE(ReadText(dir.path() + "/a/truth.csv") == ReadText(dir.path() + "/b/truth.csv"));
  // The poor bus shows: the tracking is worse than over a clean link (2.5 ms late, 5 % lost).
  const Pair clean = ServeWithController(dir.path(), scenario, dir.path() + "/clean");
  EXPECT_EQ(clean.serve, 0) << clean.serve_log;
  EXPECT_GT(ra["metrics"]["tracking_rms_knee_deg"].get<double>(),
            Result(dir.path() + "/clean")["metrics"]["tracking_rms_knee_deg"].get<double>());
}

// examples/python_controller/pd_controller.py: a controller written outside the project (Python 3,
// standard library only) from DESIGN.md's frame table and the DBC, over UDP in lockstep. Its gait
// reference (rebuilt from Winter's table as controller/trajectory.h defines it) equals the in-process
// one to 1e-9 rad, and its tracking (PD alone, no feed-forward model, no estimator filter) stays within
// 2 deg RMS of the in-process controller's at each joint.
TEST(ServeCli, PythonControllerOverUdpTracksTheGaitLikeTheInProcessOne) {
  testing::ScopedTempDir dir("serve");
  const std::string scenario = GaitScenario(dir.path(), 4.0);
  const auto run = testing::RunExotwin("run " + scenario + " --out " + dir.path() + "/run");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string bus = "udp:127.0.0.1:" + std::to_string(42000 + 2 * (::getpid() % 9000));
  const pid_t serve = testing::StartProgram(testing::ExotwinBin(), {"serve", scenario, "--bus", bus, "--out", dir.path() + "/py"},
                                            dir.path() + "/serve.log");
  const std::string src = EXOTWIN_SOURCE_DIR;
  const pid_t py = testing::StartProgram("/usr/bin/python3",
                                         {src + "/examples/python_controller/pd_controller.py", "--bus", bus, "--winter",
                                          src + "/data/WinterTableA1.txt", "--timeout", "20"},
                                         dir.path() + "/py.log");
  const int serve_rc = WaitFor(serve, 120), py_rc = WaitFor(py, 30);
  EXPECT_EQ(py_rc, 0) << ReadText(dir.path() + "/py.log");
  ASSERT_NE(serve_rc, -1) << ReadText(dir.path() + "/serve.log");
  EXPECT_NE(ReadText(dir.path() + "/py.log").find("run over (NMT stop): 4000 ticks"), std::string::npos);
  const nlohmann::json py_result = Result(dir.path() + "/py"), in = Result(dir.path() + "/run");
  EXPECT_EQ(py_result["metrics"]["link_deterministic"], 1.0);
  EXPECT_EQ(py_result["metrics"]["link_frames_unexpected"], 0.0);
  EXPECT_EQ(py_result["metrics"]["safe_state_entered"], 0.0);
  const CsvTable a = ReadCsv(dir.path() + "/run/measured.csv"), b = ReadCsv(dir.path() + "/py/measured.csv");
  ASSERT_EQ(b.rows(), 4000u);
  for (const char* ref : {"ref_hip", "ref_knee"}) {
    double worst = 0;
    for (size_t i = 0; i < a.rows(); ++i)
      worst = std::max(worst, std::abs(a.columns[a.Find(ref)][i] - b.columns[b.Find(ref)][i]));
    EXPECT_LT(worst, 1e-9) << ref;
  }
  for (const char* m : {"tracking_rms_hip_deg", "tracking_rms_knee_deg"}) {
    const double python = py_result["metrics"][m], in_process = in["metrics"][m];
    std::printf("%s: python %.3f deg, in-process %.3f deg\n", m, python, in_process);
    EXPECT_LT(python, in_process + 2.0) << m;
    EXPECT_GT(python, 0.0) << m;
  }
}

}  // namespace
}  // namespace exotwin
