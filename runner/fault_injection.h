// Fault injection on the EXOwheel rig (scenario faults:, FaultSpec): switches on the joint modules
// (hwsim::JointModuleFaults), the bus (VirtualCanBusConfig) and the controller's CAN node (bus-off).
#pragma once
#include <string>
#include <vector>

#include "hwsim/joint_module.h"
#include "hwsim/virtual_can_bus.h"
#include "runner/scenario.h"

namespace exotwin {

// A scenario fault and whether it is switched on.
struct FaultSwitch {
  FaultSpec spec;
  bool active = false;
};

// True when `f` acts on joint j (0 hip, 1 knee): its joint is "all" or that joint.
bool FaultActsOn(const FaultSpec& f, int j);

// Switches every fault to its state at time t (s): on in [at, at + duration) (duration <= 0: to the
// end). Each change appends "t=<t> on|off <type> <joint>" to *events and sets the switch of
// modules[0..1] (hip, knee), of the bus (frame_drop: `value` or 0.5, back to hw.can_drop_rate;
// frame_late: every delivery late by `value` s, default 10 ms) or of `controller_node` (bus_off).
void ApplyFaults(std::vector<FaultSwitch>& faults, double t, hwsim::JointModule* modules[2],
                 hwsim::VirtualCanBus& bus, hwsim::VirtualCanBus::Endpoint* controller_node,
                 const HardwareSpec& hw, std::vector<std::string>* events);

}  // namespace exotwin
