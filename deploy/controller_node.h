// The deployable controller's main loop (exotwin-controller): the EXOwheel control loop
// (controller/exo_controller.h) or the HAL-3 knee loop (controller/hal_loop.h, a controller file with
// `hal:`) driven by the twin-controller link (protocol/link_frames.h) or a SocketCAN interface. It
// ticks on each SYNC at the SYNC's time on the frames received before it, sends its commands, its
// telemetry and a cycle-done frame; an NMT start begins a fresh control loop for the trial it names
// (answered by a ready frame), an NMT stop ends the session. It never reaches the plant.
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <ostream>

#include "controller/controller_config.h"
#include "controller/exo_controller.h"
#include "controller/hal_loop.h"
#include "protocol/can_link.h"

namespace exotwin {

class ControllerNode {
 public:
  // cfg and link outlive the node; log gets one line per event (start, trial, safety state, end).
  ControllerNode(const controller::ControllerFile& cfg, CanLink* link, std::ostream& log);
  // Started on a scenario file: the controller part `scenario_controller` (its gains and limits) is
  // the scenario's, the rest is the twin's (the feed-forward model and reference computed from the
  // subject in sim/; for a HAL-3 scenario, `hal3`, the operator's EMG calibration and the run's
  // virtual viscosity): the node asks for the controller file at every NMT start
  // (link::kIdConfigRequest; it may change from run to run) and runs it once its controller part
  // equals `scenario_controller` and its device is the scenario's.
  ControllerNode(const ControllerSpec& scenario_controller, bool hal3, std::string scenario_source, CanLink* link,
                 std::ostream& log);
  // Runs until an NMT stop (returns 0), a stop signal (StopSignal(), core/stop_signal.h: commands
  // zero torque with the drives disabled, then returns 0), or a downloaded controller file that does
  // not fit the scenario (returns 2, the difference logged).
  int Run();

 private:
  // The control loop's view of the link: the frames queued for the next tick, and sends to the link.
  class TickBus : public CanBus {
   public:
    explicit TickBus(CanLink* link) : link_(link) {}
    CanStatus Send(const CanFrame& f) override { return link_->Send(f); }
    CanStatus Receive(CanFrame* out) override;
    std::deque<CanFrame> pending;
   private:
    CanLink* link_;
  };

  void Handle(const CanFrame& f);
  void Tick(double t);
  void ZeroTorque();
  void Summary(const char* why);

  void Configure(const controller::ControllerFile& cfg);
  void TakeConfiguration(const CanFrame& end);
  void StartLoop(uint16_t sequence);
  void SendHalTelemetry();

  controller::ControllerFile cfg_;
  controller::ExoControllerConfig exo_cfg_;
  bool configured_ = false;
  bool scenario_mode_ = false, scenario_hal_ = false;  // started on a scenario file (of device hal3)
  ControllerSpec scenario_controller_;  // scenario mode: what the downloaded file must say
  std::string scenario_source_;         // scenario mode: the scenario file
  std::string config_text_;             // scenario mode: the download so far
  bool awaiting_config_ = false;        // scenario mode: a configuration request is open
  uint16_t start_sequence_ = 0;         // scenario mode: the NMT start the download answers
  int configured_start_ = -1;           // scenario mode: the NMT start whose configuration is held
  int exit_code_ = 0;
  CanLink* link_;
  std::ostream& log_;
  TickBus bus_;
  std::unique_ptr<controller::ExoController> ctrl_;  // the EXOwheel loop
  std::unique_ptr<controller::HalLoop> hal_;         // the HAL-3 loop
  int trial_ = -1;
  bool have_stamp_ = false, done_ = false;
  double stamp_ = 0, last_sync_ = 0;
  uint64_t ticks_ = 0, syncs_ignored_ = 0;
  int state_ = 0;
  uint32_t faults_ = 0;
};

}  // namespace exotwin
