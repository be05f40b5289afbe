// exotwin-controller --config FILE.yaml (--bus ADDR | --can IFACE) [--spin US] [--rt-priority N]: the deployable controller
// (DESIGN.md "Command line"). Exit 0 at the end of the run (NMT stop) or after SIGINT / SIGTERM (zero
// torque commanded first); 2 on bad input (the file, key or address named on stderr).
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>

#include "controller/controller_config.h"
#include "core/error.h"
#include "core/file_text.h"
#include "core/realtime.h"
#include "core/stop_signal.h"
#include "core/yaml_fields.h"
#include "deploy/controller_node.h"
#include "protocol/bus_address.h"
#include "protocol/can_link.h"

namespace {

constexpr const char* kUsage = "usage: exotwin-controller --config FILE.yaml (--bus ADDR | --can IFACE) [--spin US]\n"
                               "                          [--rt-priority N]\n"
                               "  ADDR: unix:PATH | udp:HOST:PORT | can:IFACE | shm:NAME\n"
                               "  --spin US: a wait for the twin's next frames spins up to US us before it blocks\n"
                               "             (adaptive; default 50; 0: block at once)\n"
                               "  --rt-priority N: lock the memory and take SCHED_FIFO priority 1..99 (a refusal:\n"
                               "             a warning, the controller runs on at normal priority)";

int Usage(const std::string& why) {
  std::cerr << "exotwin-controller: " << why << "\n" << kUsage << std::endl;
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace exotwin;
  std::string config, bus, what = "--bus";
  double spin_us = 1e6 * kDefaultLinkSpin;
  int rt_priority = 0;
  try {
    CheckCommandLine(argc, argv);
  } catch (const InputError& e) {
    return Usage(e.what());
  }
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::cout << kUsage << std::endl;
      return 0;
    }
    if ((a == "--config" || a == "--bus" || a == "--can" || a == "--spin" || a == "--rt-priority") && i + 1 >= argc)
      return Usage(a + ": expected a value");
    if (a == "--config") config = argv[++i];
    else if (a == "--spin") {
      char* end = nullptr;
      spin_us = std::strtod(argv[++i], &end);
      if (end == argv[i] || *end != '\0' || !(spin_us >= 0 && spin_us <= 1e6))
        return Usage(std::string("--spin: expected 0 to 1000000 us, got '") + argv[i] + "'");
    }
    else if (a == "--rt-priority") {
      char* end = nullptr;
      const long n = std::strtol(argv[++i], &end, 10);
      if (end == argv[i] || *end != '\0' || n < 1 || n > 99)
        return Usage(std::string("--rt-priority: expected 1 to 99, got '") + argv[i] + "'");
      rt_priority = static_cast<int>(n);
    }
    else if (a == "--bus" || a == "--can") {
      if (!bus.empty()) return Usage("give one of --bus, --can");
      what = a;
      bus = a == "--can" ? std::string("can:") + argv[++i] : argv[++i];
    } else return Usage("unknown argument '" + a + "'");
  }
  if (config.empty()) return Usage("--config FILE.yaml is required");
  if (bus.empty()) return Usage("--bus ADDR or --can IFACE is required");
  try {
    // A scenario (it names a device): its controller part here, the rest from the twin (ControllerNode).
    const std::string text = ReadYamlText(config, "controller or scenario");
    const YAML::Node root = ParseYaml(text, config);
    const bool scenario = root && root.IsMap() && root["device"];
    ControllerSpec scenario_controller;
    controller::ControllerFile cfg;
    bool hal3 = false;
    if (scenario) {
      hal3 = YamlString(YamlContext{config}, root["device"], "device", {"exowheel", "exowheel_exo_only", "hal3"}) == "hal3";
      if (root["controller"]) ParseControllerSpec(YamlContext{config}, root["controller"], &scenario_controller);
    } else {
      cfg = controller::ParseControllerFile(text, config);
    }
    const BusAddress address = ParseBusAddress(bus, what);
    if (address.kind == BusKind::kUdp && !address.loopback())
      std::cerr << "exotwin-controller: note: UDP on " << address.host
                << ", not loopback: torque commands cross the network" << std::endl;
    try {  // the loop's and the supervisor's checks, before the bus is opened
      if (!scenario && cfg.hal) controller::HalLoop(*cfg.hal, nullptr);
      else if (!scenario) controller::ExoConfigOf(cfg);
    } catch (const std::invalid_argument& e) {
      throw InputError(config + ": " + e.what());
    }
    std::unique_ptr<CanLink> link = CanLink::Open(address, LinkEnd::kController);
    if (address.kind != BusKind::kSocketCan) link->SetSpin(1e-6 * spin_us);
    if (rt_priority > 0) {  // as serve's --rt-priority: a refusal is said, the run goes on
      const RealtimeGrant g = RequestRealtime(rt_priority);
      if (!g.refused.empty())
        std::cerr << "exotwin-controller: warning: real-time request refused by the kernel: " << g.refused
                  << "; the controller runs on" << (g.fifo ? "" : " at normal priority") << std::endl;
      std::cerr << "exotwin-controller: memory " << (g.memory_locked ? "locked" : "not locked") << ", scheduling "
                << (g.fifo ? "SCHED_FIFO " + std::to_string(g.priority) : std::string("SCHED_OTHER (normal)")) << std::endl;
    }
    InstallStopSignalHandlers();
    if (scenario) {
      ControllerNode node(scenario_controller, hal3, config, link.get(), std::cerr);
      return node.Run();
    }
    ControllerNode node(cfg, link.get(), std::cerr);
    return node.Run();
  } catch (const InputError& e) {
    std::cerr << "exotwin-controller: " << e.what() << std::endl;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "exotwin-controller: error: " << e.what() << std::endl;
    return 2;
  }
}
