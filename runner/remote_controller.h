// The controller seat of the co-simulation rig taken by a controller in another process (`exotwin
// serve`, DESIGN.md "The CAN transport between processes"): at each controller tick the rig's
// controller endpoint hands its received frames to the link (each after a receive-stamp frame), sends
// SYNC with the tick's time, and puts the controller's answer (commands, heartbeat) on the virtual bus
// at the tick's time, as the in-process controller's sends; the controller's telemetry stands in for
// the in-process telemetry (measured.csv, metrics).
//   lockstep: the tick waits for the controller's cycle-done frame, so the run is the in-process run,
//     bit for bit; when the controller is gone (its socket refuses the SYNC, or no cycle-done within
//     timeout_s of wall clock) the run goes on without it (no more commands: the joint modules'
//     watchdogs cut the torque), an event is recorded and the run is marked non-deterministic;
//   realtime: ticks paced on absolute deadlines of the monotonic clock at the controller rate (a sleep
//     to `spin_s` before the deadline, then a spin); the tick waits for the cycle-done frame up to half
//     a period, answers arriving later are late (applied at the next tick), cycles without an answer
//     before the next SYNC are missed; the tick-start jitter is recorded (percentiles, histogram).
// A tick's frames to the controller leave as one datagram (CanLink::Hold/Flush), and so do the
// controller's answers (ControllerNode); the wait for the answer blocks in poll(2).
// Link faults (LinkFaults, `serve --link-delay/--link-jitter/--link-loss`) act on the device frames
// crossing the link, both ways, on the simulated clock: seeded, so a lockstep run stays deterministic.
#pragma once
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "controller/exo_controller.h"
#include "controller/hal_loop.h"
#include "protocol/can_bus.h"
#include "core/rng.h"
#include "protocol/can_link.h"

namespace exotwin {

enum class ServeClock { kLockstep, kRealtime };

// A poor bus on purpose, between the twin's virtual bus and the controller (DESIGN.md "Link faults"):
// every device frame crossing the link (the twin's frames to the controller, the controller's commands
// and heartbeat to the twin) is lost with probability `loss`, else delayed by delay_s + jitter_s u (u
// uniform in [0, 1), one draw per frame) of simulated time, each direction keeping its frames' order
// (a frame never overtakes the one before it). A frame to the controller reaches it at the first tick
// at or after its due time with that time as receive stamp; a command is put on the virtual bus at the
// first tick at or after its due time. The link's own frames (SYNC, done, telemetry, NMT, stamps) are
// never touched. Draws from Rng(MixSeed(seed ^ kLinkFaultStream)): the same seed, the same faults.
struct LinkFaults {
  double delay_s = 0, jitter_s = 0, loss = 0;
  uint64_t seed = 0;
  bool any() const { return delay_s > 0 || jitter_s > 0 || loss > 0; }
};
// The faults of `serve --link-delay MS --link-jitter MS --link-loss P` (the run's seed): throws
// InputError naming the option when a delay or jitter is negative or above 1000 ms, or P is outside 0..1.
LinkFaults LinkFaultsOf(double delay_ms, double jitter_ms, double loss, uint64_t seed);

// The edges (us) of the tick-start jitter histogram in result.json (`link_jitter_histogram`): bin i
// counts the ticks with edges[i] <= jitter < edges[i + 1], the last bin those at or above the last edge.
const std::vector<double>& JitterHistogramEdgesUs();

class RemoteController {
 public:
  // link outlives this; period_s: the controller period (s); timeout_s: wall-clock time without an
  // answer after which the controller is gone (also the wait for its ready frame at a trial's start).
  // spin_s (realtime): the spin before each tick's deadline (the sleep ends spin_s early).
  RemoteController(CanLink* link, ServeClock clock, double period_s, double timeout_s, LinkFaults faults = {},
                   double spin_s = 100e-6);
  // The controller file's text of the trials that follow (the device runner sets it for each run or
  // trial): sent to a controller that asks for it (one started on the scenario file asks at every NMT
  // start: link::kIdConfigRequest) before it answers the NMT start.
  void SetConfiguration(std::string text) { configuration_ = std::move(text); }
  // Starts trial `trial` (0-based) with the rig's controller endpoint `ep`: NMT start, then waits for
  // the controller's ready frame (re-sent every 100 ms). `events` gets the link's events ("t=... ...").
  void BeginTrial(int trial, CanBus* ep, std::vector<std::string>* events);
  // The controller tick at t (s).
  void Tick(double t);
  // Ends the session (after the last run): NMT stop, the controller exits.
  void EndRun();
  // The last telemetry, read as the EXOwheel loop's (link::TelemetryIndex) and as the HAL-3 loop's
  // (link::HalTelemetryIndex); the device runner reads the one of its device.
  const controller::ControllerTelemetry& telemetry() const { return tel_; }
  const controller::HalTelemetry& hal_telemetry() const { return hal_tel_; }
  double hal_I_hat() const { return hal_I_hat_; }  // kg m^2, the RLS's inertia estimate (HKS05 eq. 13)
  // The link's figures for result.json's metrics (link_*).
  void AddMetrics(std::map<std::string, double>* m) const;
  // realtime: {"edges_us": [...], "counts": [...]} (JitterHistogramEdgesUs); null in lockstep.
  nlohmann::ordered_json JitterHistogram() const;
  bool deterministic() const { return deterministic_; }
  // The sequence number the next BeginTrial's NMT start carries (link_frames.h): it starts at a
  // nonce of the session, so a controller that outlives a twin asks the new twin for its file.
  uint16_t next_sequence() const { return starts_; }

 private:
  void Lost(double t, const std::string& why);
  void Take(const CanFrame& f, double t, bool* done);
  void TakeHal(int i, double v);
  // The due time of a device frame passing the link at t (s) after the last one's `last` (s); false
  // when the frame is lost (LinkFaults).
  bool Pass(double t, double* last, double* due);
  void Release(double t);  // the controller's frames due at or before t onto the virtual bus
  CanLink* link_;
  ServeClock clock_;
  double period_, timeout_;
  CanBus* ep_ = nullptr;
  std::vector<std::string>* events_ = nullptr;
  controller::ControllerTelemetry tel_;
  controller::HalTelemetry hal_tel_;
  double hal_I_hat_ = 0;
  bool present_ = false, deterministic_ = true;
  double lost_at_ = -1;
  double wall0_ = 0;
  long ticks_ = 0;
  uint16_t starts_;  // the next NMT start's sequence number (from a per-session nonce)
  double awaited_ = 0;  // t of the cycle whose done frame is awaited (realtime)
  bool awaiting_ = false;
  uint64_t unexpected_ = 0, late_ = 0, missed_ = 0, bus_refused_ = 0;
  std::vector<double> jitter_;  // s, tick start minus its schedule (realtime)
  std::string configuration_;
  LinkFaults faults_;
  double spin_;
  Rng fault_rng_;
  struct Timed {
    double due;
    CanFrame frame;
  };
  std::deque<Timed> to_controller_, to_bus_;  // device frames on their way (due order)
  double last_to_controller_ = 0, last_to_bus_ = 0;  // due time of the last frame each way
  uint64_t dropped_ = 0;                             // device frames lost on purpose
};

}  // namespace exotwin
