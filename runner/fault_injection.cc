// Fault injection on the EXOwheel rig: see fault_injection.h.
#include "runner/fault_injection.h"

#include <cstdio>

namespace exotwin {

bool FaultActsOn(const FaultSpec& f, int j) { return f.joint == "all" || f.joint == (j == 0 ? "hip" : "knee"); }

void ApplyFaults(std::vector<FaultSwitch>& faults, double t, hwsim::JointModule* modules[2],
                 hwsim::VirtualCanBus& bus, hwsim::VirtualCanBus::Endpoint* controller_node,
                 const HardwareSpec& hw, std::vector<std::string>* events) {
  for (FaultSwitch& f : faults) {
    const bool on = t >= f.spec.at && (f.spec.duration <= 0 || t < f.spec.at + f.spec.duration);
    if (on == f.active) continue;
    f.active = on;
    char buf[160];
    std::snprintf(buf, sizeof(buf), "t=%.3f %s %s %s", t, on ? "on" : "off", f.spec.type.c_str(),
                  f.spec.joint.c_str());
    events->push_back(buf);
    for (int j = 0; j < 2; ++j) {
      if (!FaultActsOn(f.spec, j)) continue;
      hwsim::JointModuleFaults& mf = modules[j]->faults();
      if (f.spec.type == "sensor_stuck") mf.sensor_stuck = on;
      if (f.spec.type == "sensor_stale") mf.stale = on;
      if (f.spec.type == "encoder_glitch") mf.encoder_glitch = on;
      if (f.spec.type == "nan_measurement") mf.sensor_nan = on;
      if (f.spec.type == "command_loss") mf.drop_commands = on;
    }
    hwsim::VirtualCanBusConfig& bc = bus.config();
    if (f.spec.type == "frame_drop")
      bc.drop_probability = on ? (f.spec.value > 0 ? f.spec.value : 0.5) : hw.can_drop_rate;
    if (f.spec.type == "frame_late") {
      bc.spike_probability = on ? 1.0 : 0.0;  // every delivery late by `value` s (default 10 ms)
      bc.spike_delay = f.spec.value > 0 ? f.spec.value : 0.01;
    }
    if (f.spec.type == "bus_off") {  // the controller's CAN controller goes bus-off
      if (on) controller_node->ForceBusOff();
      else controller_node->RecoverBusOff();
    }
  }
}

}  // namespace exotwin
