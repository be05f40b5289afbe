// The deployable controller's main loop (exotwin-controller): the EXOwheel control loop
// (controller/exo_controller.h) driven by the twin-controller link (protocol/link_frames.h) or a
// SocketCAN interface. It ticks on each SYNC at the SYNC's time on the frames received before it,
// sends its commands, its telemetry and a cycle-done frame; an NMT start begins a fresh control loop for
// the trial it names (answered by a ready frame), an NMT stop ends the run. It never reaches the plant.
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <ostream>

#include "controller/controller_config.h"
#include "controller/exo_controller.h"
#include "protocol/can_link.h"

namespace exotwin {

class ControllerNode {
 public:
  // cfg and link outlive the node; log gets one line per event (start, trial, safety state, end).
  ControllerNode(const controller::ControllerFile& cfg, CanLink* link, std::ostream& log);
  // Started on a scenario file: the controller part `scenario_controller` (its gains and limits) is
  // the scenario's, the feed-forward model and the reference are the twin's (computed from the
  // subject in sim/): the node asks for the controller file on the first NMT start
  // (link::kIdConfigRequest) and runs it once its controller part equals `scenario_controller`.
  ControllerNode(const ControllerSpec& scenario_controller, std::string scenario_source, CanLink* link,
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

  controller::ControllerFile cfg_;
  controller::ExoControllerConfig exo_cfg_;
  bool configured_ = false;
  ControllerSpec scenario_controller_;  // scenario mode: what the downloaded file must say
  std::string config_text_;             // scenario mode: the download so far
  int exit_code_ = 0;
  CanLink* link_;
  std::ostream& log_;
  TickBus bus_;
  std::unique_ptr<controller::ExoController> ctrl_;
  int trial_ = -1;
  bool have_stamp_ = false, done_ = false;
  double stamp_ = 0, last_sync_ = 0;
  uint64_t ticks_ = 0, syncs_ignored_ = 0;
  int state_ = 0;
  uint32_t faults_ = 0;
};

}  // namespace exotwin
