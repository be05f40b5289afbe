#include <CLI/CLI.hpp>

#include <cstdio>

#include <nlohmann/json.hpp>

#include "formats/opensim_storage.h"
#include "app/commands.h"
#include "core/stop_signal.h"
#include "core/error.h"
#include "core/file_text.h"
#include "formats/csv_table.h"
#include "core/realtime.h"
#include "protocol/bus_address.h"
#include "protocol/can_link.h"
#include "batch/controller_process.h"
#include "runner/out_folder_lock.h"
#include "runner/remote_controller.h"
#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin {
namespace {

// Prints the checks as a table; returns 0 when all passed, 1 otherwise, 128 + N when signal N
// (SIGINT, SIGTERM) interrupted the run (result.json then says where: DESIGN.md "Interrupted runs").
int Report(const RunResult& r, const std::string& out_dir) {
  const auto samples = r.metrics.find("samples");
  std::printf("scenario %s (seed %llu): %zu samples, results in %s/result.json\n", r.scenario.c_str(),
              static_cast<unsigned long long>(r.seed),
              samples == r.metrics.end() ? size_t{0} : static_cast<size_t>(samples->second), out_dir.c_str());
  for (const CheckResult& c : r.checks)
    std::printf("  %-4s %-32s %12.5g %s %-10.5g (%s)\n", c.passed ? "ok" : "FAIL", c.name.c_str(), c.value,
                c.op.c_str(), c.limit, c.metric.c_str());
  if (r.interrupted) {
    std::fprintf(stderr, "exotwin: interrupted by %s at t = %.3f s (trial %d): checks not passed\n",
                 StopSignalName(r.interrupted->signal), r.interrupted->t, r.interrupted->trial);
    return 128 + r.interrupted->signal;
  }
  return r.all_passed() ? 0 : 1;
}

// --sto: every measured[_trialN].csv and truth[_trialN].csv the run wrote (r.files, relative to
// out_dir) also as an OpenSim storage file beside it (same name, .sto; formats/opensim_storage.h
// CsvToStorage: inDegrees=no, SI values unchanged). Returns the files written.
std::vector<std::string> WriteStorageCopies(const RunResult& r, const std::string& out_dir) {
  std::vector<std::string> written;
  for (const std::string& f : r.files) {
    const std::string base = f.substr(f.find_last_of('/') + 1);
    const bool log = base.rfind("measured", 0) == 0 || base.rfind("truth", 0) == 0;
    if (!log || base.size() < 4 || base.compare(base.size() - 4, 4, ".csv") != 0) continue;
    const std::string csv = out_dir + "/" + f, sto = csv.substr(0, csv.size() - 4) + ".sto";
    CsvToStorage(csv, sto);
    written.push_back(sto);
  }
  return written;
}

constexpr const char* kMcapHelp =
    "also write the run's logs as a ROS 2 bag (MCAP, zstd chunks; topics in DESIGN.md \"ROS 2 bags (MCAP) in and out\")";

// Adds `key: value` to the top level of the result.json at `path` (written whole, atomically).
void AddToResultJson(const std::string& path, const std::string& key, const nlohmann::ordered_json& value) {
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(ReadTextFile(path, "result", "JSON"));
  j[key] = value;
  WriteFileAtomic(path, j.dump(2) + "\n");
}

CommandRunner RegisterRun(CLI::App& app) {
  struct Opts {
    std::string scenario, out = "out", can_log, video, mcap;
    uint64_t seed = 0;
    bool sto = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("run", "Run a scenario: plant + virtual hardware + the real controller");
  sub->add_option("scenario", o->scenario, "scenario YAML")->required();
  sub->add_option("--out", o->out, "output folder (result.json, measured.csv, truth.csv)");
  auto* seed = sub->add_option("--seed", o->seed, "seed (overrides the scenario's)");
  sub->add_option("--can-log", o->can_log, "candump log of every CAN frame");
  sub->add_option("--video", o->video, "render an MP4 video of the run");
  sub->add_option("--mcap", o->mcap, kMcapHelp);
  sub->add_flag("--sto", o->sto,
                "also write measured.csv and truth.csv as OpenSim storage files (measured.sto, truth.sto; "
                "version-1 header, inDegrees=no, tab-separated)");
  return [sub, o, seed]() -> int {
    if (!*sub) return -1;
    InstallStopSignalHandlers();
    const Scenario s = ReadScenario(o->scenario);
    const OutFolderLock lock(o->out);
    RunOptions opt;
    opt.out_dir = o->out;
    if (*seed) opt.seed = o->seed;
    opt.can_log = o->can_log;
    opt.mcap = o->mcap;
    opt.progress = true;
    opt.video_path = o->video;
    const RunResult r = RunScenario(s, opt);
    if (o->sto)
      for (const std::string& f : WriteStorageCopies(r, o->out)) std::fprintf(stderr, "run: wrote %s\n", f.c_str());
    return Report(r, o->out);
  };
}

// `exotwin render SCENARIO.yaml -o FILE.mp4`: runs the scenario (logs under --out) and renders its
// first trial off-screen: side view, human and exoskeleton in distinct colours, overlays.
CommandRunner RegisterRender(CLI::App& app) {
  struct Opts {
    std::string scenario, video, out = "out/render", mcap;
    bool sto = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("render", "Run a scenario and render it to an MP4 (H.264, 30 fps, 1280x720)");
  sub->add_option("scenario", o->scenario, "scenario YAML")->required();
  sub->add_option("-o,--output", o->video, "output MP4")->required();
  sub->add_option("--out", o->out, "folder for the run's logs and result.json");
  sub->add_flag("--sto", o->sto, "also write the logs as OpenSim storage files (as run --sto)");
  sub->add_option("--mcap", o->mcap, kMcapHelp);
  return [sub, o]() -> int {
    if (!*sub) return -1;
    InstallStopSignalHandlers();
    const Scenario s = ReadScenario(o->scenario);
    const OutFolderLock lock(o->out);
    RunOptions opt;
    opt.out_dir = o->out;
    opt.video_path = o->video;
    opt.mcap = o->mcap;
    opt.progress = true;
    const RunResult r = RunScenario(s, opt);
    if (o->sto)
      for (const std::string& f : WriteStorageCopies(r, o->out)) std::fprintf(stderr, "render: wrote %s\n", f.c_str());
    const int rc = Report(r, o->out);
    std::printf("wrote %s\n", o->video.c_str());
    return rc > 1 ? rc : 0;  // a failed check does not fail the rendering; an interruption does
  };
}

// `exotwin serve SCENARIO.yaml --bus ADDR`: the scenario's plant and hardware on a CAN link, the
// controller in another process (DESIGN.md "The CAN transport between processes"). Writes
// DIR/controller.yaml (the controller file of the scenario) before it waits for the controller.
CommandRunner RegisterServe(CLI::App& app) {
  struct Opts {
    std::string scenario, out = "out", bus, can, clock = "lockstep", can_log, mcap;
    uint64_t seed = 0;
    double timeout = 10.0;
    double link_delay_ms = 0, link_jitter_ms = 0, link_loss = 0, rt_spin_us = 100, link_spin_us = 1e6 * kDefaultLinkSpin;
    int rt_priority = 0;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("serve", "Run a scenario's twin for a controller in another process");
  sub->add_option("scenario", o->scenario, "scenario YAML (any device and protocol)")->required();
  auto* bus = sub->add_option("--bus", o->bus, "unix:PATH | udp:HOST:PORT | can:IFACE | shm:NAME");
  auto* can = sub->add_option("--can", o->can, "SocketCAN interface (same as --bus can:IFACE)");
  bus->excludes(can);
  sub->add_option("--clock", o->clock, "lockstep (default) or realtime")->check(CLI::IsMember({"lockstep", "realtime"}));
  sub->add_option("--out", o->out, "output folder (result.json, measured.csv, truth.csv, controller.yaml)");
  auto* seed = sub->add_option("--seed", o->seed, "seed (overrides the scenario's)");
  sub->add_option("--timeout", o->timeout, "s of wall clock without an answer after which the controller is gone")
      ->check(CLI::Range(0.01, 3600.0));
  sub->add_option("--can-log", o->can_log, "candump log of every CAN frame of the twin's bus");
  sub->add_option("--mcap", o->mcap, kMcapHelp);
  sub->add_option("--link-delay", o->link_delay_ms, "ms of simulated time added to each device frame crossing the link");
  sub->add_option("--link-jitter", o->link_jitter_ms, "ms: each device frame further delayed by up to this (uniform, seeded)");
  sub->add_option("--link-loss", o->link_loss, "probability 0..1 that a device frame crossing the link is lost (seeded)");
  auto* rt_priority = sub->add_option("--rt-priority", o->rt_priority,
                                      "realtime: lock the memory and take SCHED_FIFO priority 1..99 (a refusal: warning)");
  sub->add_option("--rt-spin", o->rt_spin_us, "realtime: us spent spinning before each tick's deadline (default 100)");
  sub->add_option("--link-spin", o->link_spin_us,
                  "us a wait for the controller's answer spins before it blocks (adaptive; default 50, 0: block)");
  return [sub, o, seed, rt_priority]() -> int {
    if (!*sub) return -1;
    if (o->bus.empty() && o->can.empty()) throw InputError("serve: --bus ADDR or --can IFACE is required");
    if (!(o->rt_spin_us >= 0 && o->rt_spin_us <= 1e6))
      throw InputError("--rt-spin: expected 0 to 1000000 us, got " + std::to_string(o->rt_spin_us));
    if (!(o->link_spin_us >= 0 && o->link_spin_us <= 1e6))
      throw InputError("--link-spin: expected 0 to 1000000 us, got " + std::to_string(o->link_spin_us));
    InstallStopSignalHandlers();
    const Scenario s = ReadScenario(o->scenario);
    const LinkFaults faults = LinkFaultsOf(o->link_delay_ms, o->link_jitter_ms, o->link_loss, *seed ? o->seed : s.seed);
    const BusAddress address = o->can.empty() ? ParseBusAddress(o->bus) : ParseBusAddress("can:" + o->can, "--can");
    if (address.kind == BusKind::kUdp && !address.loopback())
      std::fprintf(stderr, "exotwin serve: note: UDP on %s, not loopback: torque commands cross the network\n",
                   address.host.c_str());
    const OutFolderLock lock(o->out);
    {  // the scenario's files and outputs checked before the link opens and the controller is awaited
      RunOptions check;
      check.out_dir = o->out;
      check.can_log = o->can_log;
      check.mcap = o->mcap;
      CheckScenarioRun(s, check);
    }
    const std::string controller_file = WriteControllerFile(s, o->out, *seed ? o->seed : s.seed);
    std::unique_ptr<CanLink> link = CanLink::Open(address, LinkEnd::kTwin);
    if (address.kind != BusKind::kSocketCan) link->SetSpin(1e-6 * o->link_spin_us);
    const ServeClock clock = o->clock == "realtime" ? ServeClock::kRealtime : ServeClock::kLockstep;
    if (*rt_priority) {
      const RealtimeGrant g = RequestRealtime(o->rt_priority);
      if (!g.refused.empty())
        std::fprintf(stderr, "exotwin serve: warning: real-time request refused by the kernel: %s; the run goes on%s\n",
                     g.refused.c_str(), g.fifo ? "" : " at normal priority");
      std::fprintf(stderr, "exotwin serve: memory %s, scheduling %s\n", g.memory_locked ? "locked" : "not locked",
                   g.fifo ? ("SCHED_FIFO " + std::to_string(g.priority)).c_str() : "SCHED_OTHER (normal)");
    }
    RemoteController remote(link.get(), clock, 1.0 / s.controller.rate_hz, o->timeout, faults, 1e-6 * o->rt_spin_us);
    std::fprintf(stderr, "exotwin serve: %s on %s, %s clock; waiting for the controller (%s)\n", s.name.c_str(),
                 link->Describe().c_str(), o->clock.c_str(),
                 controller_file.empty() ? "start it on the scenario file: its trials run different controller files"
                                         : ("controller file " + controller_file + ", or the scenario file").c_str());
    RunOptions opt;
    opt.out_dir = o->out;
    if (*seed) opt.seed = o->seed;
    opt.can_log = o->can_log;
    opt.mcap = o->mcap;
    opt.remote = &remote;
    RunResult r;
    try {
      r = RunScenario(s, opt);
    } catch (...) {
      remote.EndRun();  // the controller's session ends with the twin's
      throw;
    }
    remote.EndRun();
    if (clock == ServeClock::kRealtime) AddToResultJson(o->out + "/result.json", "link_jitter_histogram", remote.JitterHistogram());
    const CanLinkStatistics& st = link->statistics();
    std::fprintf(stderr, "exotwin serve: link %s: frames received %llu, sent %llu, dropped foreign %llu, malformed %llu%s\n",
                 link->Describe().c_str(), static_cast<unsigned long long>(st.received),
                 static_cast<unsigned long long>(st.sent), static_cast<unsigned long long>(st.foreign),
                 static_cast<unsigned long long>(st.malformed), remote.deterministic() ? "" : "; run NOT deterministic (controller lost)");
    const int rc = Report(r, o->out);
    if (rc == 0 && !remote.deterministic()) {
      std::fprintf(stderr, "exotwin serve: the controller was lost (result.json events): the run fails\n");
      return 1;
    }
    return rc;
  };
}

const CommandRegistration kRun(RegisterRun);
const CommandRegistration kServe(RegisterServe);
const CommandRegistration kRender(RegisterRender);

}  // namespace
}  // namespace exotwin
