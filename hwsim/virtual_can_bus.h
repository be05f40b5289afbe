// The in-process CAN bus in simulated time. Nodes (controller, joint modules, HAL-3 knee, EMG
// amplifier, ...) each get an Endpoint implementing CanBus. The bus models:
// - timing: a data frame occupies CanFrameBits() bit times (actual stuffing over SOF..CRC, trailer,
//   3-bit IFS) at the bitrate; receivers get it at the end of EOF plus latency + jitter (+ spikes),
//   in bus order (a receiver's FIFO never reorders);
// - arbitration: when the bus goes idle, of the queue heads ready by then the lowest ID wins
//   (equal IDs: the node added first);
// - per-node TX queues with a limit (kQueueFull) and RX queues with a limit (overflow = drop);
// - faults as switches (VirtualCanBusConfig, changeable at run time through config()): drop
//   probability per receiver, corruption -> error frame + automatic retransmission, delay spikes,
//   forced bus-off; ISO 11898-1 fault confinement simplified: transmitter TEC += 8 and every other
//   node REC += 1 per error, TEC -= 1 / REC -= 1 per success, error passive at 128, bus-off when
//   TEC > 255 (TX queue flushed, Send returns kBusOff until RecoverBusOff() or, when
//   auto_bus_off_recovery is on, 128 x 11 bit times later);
// - statistics: frames, bits, error frames, drops, bus load over a window.
// All randomness comes from one seeded generator drawn in a fixed order: the same seed and the same
// calls give identical frames and time stamps.
#pragma once
#include <bitset>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/ring_queue.h"
#include "core/rng.h"
#include "protocol/can_bus.h"

namespace exotwin::hwsim {

enum class CanNodeState { kErrorActive, kErrorPassive, kBusOff };

struct VirtualCanBusConfig {
  double bitrate = 1e6;               // bit/s, > 0
  size_t tx_queue_limit = 64;         // frames waiting per node; Send beyond it -> kQueueFull
  size_t rx_queue_limit = 1024;       // frames held per node; beyond it the frame is dropped
  double latency = 0;                 // s, fixed delay from end of frame to the receiving software
  double jitter = 0;                  // s, extra delay uniform in [0, jitter)
  uint64_t seed = 1;                  // seed of every random draw of this bus
  // Fault switches.
  double drop_probability = 0;        // per receiver and frame: lost for that receiver (e.g. overrun)
  double corrupt_probability = 0;     // per transmission: destroyed by a bus error -> error frame
  double spike_probability = 0;       // per receiver and frame: delivery delayed by spike_delay
  double spike_delay = 0;             // s
  bool deliver_error_frames = true;   // nodes see error frames (CanFrame::error, Receive -> kError)
  bool auto_bus_off_recovery = false; // else a bus-off node stays off until RecoverBusOff()
  double load_window = 0.1;           // s, window of CanBusStatistics::load_percent
};

struct CanBusStatistics {
  uint64_t frames = 0;        // data frames transmitted successfully
  uint64_t bits = 0;          // bit times used (frames incl. stuffing and IFS, destroyed frames + error frames)
  uint64_t error_frames = 0;  // transmissions destroyed by a bus error
  uint64_t drops = 0;         // deliveries lost (drop fault or RX queue overflow)
  uint64_t spikes = 0;        // deliveries delayed by a spike
  uint64_t queue_full = 0;    // Sends refused with kQueueFull
  double busy_time = 0;       // s the bus was busy in [0, now]
  double load_percent = 0;    // % of [now - load_window, now] the bus was busy
  double mean_load_percent = 0;  // % of [0, now] the bus was busy
};

class VirtualCanBus {
 public:
  class Endpoint : public CanBus {
   public:
    // Queues a data frame at the bus's current time: kOk, kQueueFull, kBusOff, or kError (invalid frame).
    CanStatus Send(const CanFrame& frame) override;
    // Oldest frame available by the bus's current time: kOk (data), kError (error frame), kNoFrame.
    CanStatus Receive(CanFrame* out) override;
    const std::string& name() const { return name_; }
    int tec() const { return tec_; }  // transmit error counter
    int rec() const { return rec_; }  // receive error counter
    CanNodeState state() const { return state_; }
    // Fault switch: puts the node bus-off now (TEC = 256, TX queue flushed).
    void ForceBusOff();
    // Restarts a bus-off node: error active, TEC = REC = 0.
    void RecoverBusOff();
    size_t tx_pending() const { return tx_.size(); }
    uint64_t sent() const { return sent_; }          // frames transmitted successfully
    uint64_t received() const { return received_; }  // frames returned by Receive (data and error)
    uint64_t dropped() const { return dropped_; }    // frames lost for this node

   private:
    friend class VirtualCanBus;
    struct Pending {
      CanFrame frame;
      double ready;  // s, time it was queued
    };
    Endpoint(VirtualCanBus* bus, std::string name, const std::vector<uint16_t>& accept, size_t index);
    bool Accepts(uint16_t id) const;
    void EnterBusOff(double t);
    void UpdateState();

    VirtualCanBus* bus_;
    std::string name_;
    std::bitset<kCanMaxId + 1> accept_;  // the IDs it receives (all set: every ID)
    size_t index_;
    RingQueue<Pending> tx_;
    RingQueue<CanFrame> rx_;  // t = delivery time, non-decreasing
    int tec_ = 0, rec_ = 0;
    CanNodeState state_ = CanNodeState::kErrorActive;
    double recover_at_ = 0;
    uint64_t sent_ = 0, received_ = 0, dropped_ = 0;
  };

  explicit VirtualCanBus(const VirtualCanBusConfig& config = {});
  // Adds a node; accept_ids lists the IDs it receives (empty = all). The pointer lives as long as the bus.
  Endpoint* AddNode(std::string name, std::vector<uint16_t> accept_ids = {});
  // Runs the bus up to time t (s, >= now(); earlier values are ignored): every transmission that can
  // start before t is arbitrated and scheduled; frames delivered by t become receivable.
  void AdvanceTo(double t);
  double now() const { return now_; }
  // Fault switches and parameters, changeable between AdvanceTo calls (seed is used at construction).
  VirtualCanBusConfig& config() { return config_; }
  const VirtualCanBusConfig& config() const { return config_; }
  // Counters and bus load at now().
  CanBusStatistics Statistics() const;
  // Called for every transmission as seen on the wire (data frames stamped at the end of EOF, error
  // frames at the end of the error delimiter), e.g. a CandumpWriter for --can-log.
  void SetTap(std::function<void(const CanFrame&)> tap) { tap_ = std::move(tap); }
  // Duration (s) of a data frame on a bus of that bitrate (bit/s), including stuffing and IFS.
  static double FrameDuration(const CanFrame& frame, double bitrate);
  const std::vector<std::unique_ptr<Endpoint>>& nodes() const { return nodes_; }

 private:
  void Transmit(Endpoint* node, double start);
  void Deliver(Endpoint* to, const CanFrame& frame, double at, bool random_faults);
  void AddBusy(double start, double end);

  VirtualCanBusConfig config_;
  Rng rng_;
  std::vector<std::unique_ptr<Endpoint>> nodes_;
  double now_ = 0;
  double bus_free_at_ = 0;
  CanBusStatistics stats_;
  struct Interval {
    double start, end;
  };
  RingQueue<Interval> busy_;  // recent busy intervals (for the windowed load)
  std::function<void(const CanFrame&)> tap_;
};

}  // namespace exotwin::hwsim
