// A CanBus backend that plays a candump log back in simulated time: Receive() returns the logged
// frames whose time stamp is <= the time set with SetTime(), in log order; Send() records the frame
// (stamped with the current time) and, when a writer is attached, appends it to a candump log.
// Lets controller code be run open-loop against recorded bus traffic.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "protocol/can_bus.h"
#include "protocol/candump.h"

namespace exotwin {

class CandumpReplayBus : public CanBus {
 public:
  // Replays frames (sorted by time stably); accept_ids empty = every ID (error frames always pass).
  explicit CandumpReplayBus(std::vector<CanFrame> frames, std::vector<uint16_t> accept_ids = {});
  // Reads a log (only lines of `interface` when it is non-empty). Throws InputError like CandumpReader.
  static std::unique_ptr<CandumpReplayBus> FromLog(const std::string& path, const std::string& interface = "",
                                                   int64_t epoch_s = 0, std::vector<uint16_t> accept_ids = {});
  // Sets the current simulated time (s); frames logged at or before it become receivable.
  void SetTime(double t) { now_ = t; }
  // Sends go nowhere but are recorded (and logged to the writer, if any); kError for invalid frames.
  CanStatus Send(const CanFrame& frame) override;
  // Next logged frame due by now: kOk (data frame), kError (error frame) or kNoFrame.
  CanStatus Receive(CanFrame* out) override;
  // Appends every sent frame to w (not owned; nullptr detaches).
  void SetWriter(CandumpWriter* w) { writer_ = w; }
  const std::vector<CanFrame>& sent() const { return sent_; }
  // Frames not yet received.
  size_t remaining() const { return frames_.size() - next_; }

 private:
  std::vector<CanFrame> frames_;
  std::vector<uint16_t> accept_;
  size_t next_ = 0;
  double now_ = 0;
  std::vector<CanFrame> sent_;
  CandumpWriter* writer_ = nullptr;
};

}  // namespace exotwin
