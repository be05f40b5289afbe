#include "batch/controller_process.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>
#include <vector>

#include "formats/csv_table.h"
#include "core/output_path.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "protocol/can_link.h"
#include "protocol/shm_link.h"
#include "runner/exowheel_setup.h"
#include "runner/hal_setup.h"
#include "runner/remote_controller.h"

namespace exotwin {
namespace fs = std::filesystem;

std::string WriteControllerFile(const Scenario& s, const std::string& dir, uint64_t seed) {
  if (s.emg_calibration) return "";
  CreateOutputFolder(dir);
  const std::string path = dir + "/controller.yaml";
  // Whole or absent (a controller may be started as soon as the file appears).
  WriteFileAtomic(path, s.device == Device::kHal3
                            ? controller::ControllerFileYaml(HalControllerFileOf(s, seed, 0),
                                                             "the HAL-3 controller of " + s.source + ", run 1 of " +
                                                                 std::to_string(HalRuns(s)) + " (written by exotwin serve)")
                            : controller::ControllerFileYaml(ControllerFileOf(s, ResolveSubject(s)),
                                                             "the controller file of " + s.source +
                                                                 " (written by exotwin serve)"));
  return path;
}

std::string WriteControllerScenario(const Scenario& s, const std::string& path) {
  WriteFileAtomic(path, "# the device and controller part of " + s.source +
                            " (exotwin-controller asks the twin for the rest)\ndevice: " + DeviceName(s.device) + "\n" +
                            ControllerSpecYaml(s.controller));
  return path;
}

std::string DefaultControllerBinary() {
  std::error_code ec;
  const fs::path self = ExecutablePath();
  if (self.empty()) return "";
  for (const fs::path& p : {self.parent_path() / "exotwin-controller",
                            self.parent_path().parent_path() / "deploy" / "exotwin-controller"})
    if (fs::exists(p, ec)) return p.string();
  return "";
}

namespace {

// A private folder for the controller's scenario and the link's sockets (short enough for sockaddr_un),
// removed with them; its unique name also names the private shared-memory segment.
class LinkDir {
 public:
  LinkDir() {
    std::string tmpl = (fs::temp_directory_path() / "exotwin_link_XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) throw InputError(tmpl + ": cannot create the link's folder");
    path_ = tmpl;
  }
  ~LinkDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

pid_t StartController(const std::string& bin, const std::string& config, const std::string& bus,
                      const std::string& log, double spin_s) {
  std::vector<std::string> args = {bin, "--config", config, "--bus", bus, "--spin", std::to_string(1e6 * spin_s)};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (std::FILE* f = std::freopen(log.c_str(), "w", stderr)) ::dup2(::fileno(f), STDOUT_FILENO);
    ::execv(bin.c_str(), argv.data());
    std::fprintf(stderr, "cannot start %s\n", bin.c_str());
    ::_exit(127);
  }
  if (pid < 0) throw InputError(bin + ": cannot start the controller process");
  return pid;
}

// Waits up to `seconds` for the controller to exit, then kills it.
void Reap(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int st = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &st, WNOHANG) == pid) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &st, 0);
}

}  // namespace

RunResult RunWithControllerProcess(const Scenario& s, RunOptions opt, const std::string& controller_bin,
                                   double timeout_s, ServeClock clock, BusKind transport) {
  if (controller_bin.empty() || ::access(controller_bin.c_str(), X_OK) != 0)
    throw InputError("exotwin-controller: '" + controller_bin + "' is not an executable");
  const LinkDir dir;
  const std::string config = WriteControllerScenario(s, dir.path() + "/scenario.yaml");
  if (transport != BusKind::kShm && transport != BusKind::kUnix)
    throw InputError("the controller process's link is shm: or unix:");
  const BusAddress address = ParseBusAddress(transport == BusKind::kShm ? "shm:" + fs::path(dir.path()).filename().string()
                                                                        : "unix:" + dir.path() + "/bus");
  std::unique_ptr<CanLink> link = CanLink::Open(address, LinkEnd::kTwin);
  // Over a socket both ends spin before they block only when they may run on different CPUs: the
  // controller inherits this process's CPUs, and on a single one a spinning end holds the CPU its peer
  // needs. Over shared memory the waits yield that CPU instead (CanLink::WaitInput): both spin.
  const double spin = transport == BusKind::kUnix && OnOneCpu() ? 0.0 : kDefaultLinkSpin;
  link->SetSpin(spin);
  const pid_t pid = StartController(controller_bin, config, address.text, opt.out_dir + "/controller.log", spin);
  RemoteController remote(link.get(), clock, 1.0 / s.controller.rate_hz, timeout_s);
  opt.remote = &remote;
  RunResult r;
  try {
    r = RunScenario(s, opt);
  } catch (...) {
    ::kill(pid, SIGTERM);
    Reap(pid, 5.0);
    throw;
  }
  remote.EndRun();
  Reap(pid, 5.0);
  if (!remote.deterministic()) {  // result.json already written: record the failure in it too
    CheckResult c;
    c.name = c.metric = "controller_link";
    c.op = ">=";
    c.value = 0;
    c.limit = 1;
    r.checks.push_back(c);
    WriteResultJson(r, opt.out_dir + "/result.json");
  }
  return r;
}

}  // namespace exotwin
