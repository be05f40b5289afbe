// A scripted CanBus for driving controller code without a plant (the mock-hardware pattern of
// ros2_control's mock_components): the test scripts the frames the devices would send, each with its
// reception time, advances the bus clock before every controller tick, and reads back what the
// controller sent. Faults are injected by scripting them: silence (script nothing), a bad frame
// (ScriptErrorFrame, or any frame with a wrong DLC), a stale counter (repeat a counter), a failing
// transmit path (FailSends).
//
// Contract, as protocol/can_bus.h: Receive() never blocks; it returns the oldest scripted frame whose
// reception time is <= the bus clock (stamped with that time), kError for an error frame, kNoFrame
// when none is due. Send() records the frame stamped with the bus clock.
#pragma once
#include <algorithm>
#include <deque>
#include <vector>

#include "protocol/can_bus.h"
#include "protocol/messages.h"

namespace exotwin::testing {

class FakeCanBus : public CanBus {
 public:
  // Bus clock (s). Frames scripted at or before `t` become receivable.
  void AdvanceTo(double t) { now_ = t; }
  double now() const { return now_; }

  // One frame received at time t (s); frames must be scripted in non-decreasing time.
  void Script(double t, CanFrame f) {
    f.t = t;
    inbox_.push_back(f);
  }
  template <typename Message>
  void ScriptMessage(double t, const Message& m) { Script(t, msg::Encode(m)); }
  // An error frame (a transmission destroyed on the bus) received at time t.
  void ScriptErrorFrame(double t) {
    CanFrame f;
    f.error = true;
    Script(t, f);
  }

  // From now on Send() returns `s` (kOk restores a working transmit path); failed frames are not recorded.
  void FailSends(CanStatus s) { send_status_ = s; }

  CanStatus Send(const CanFrame& frame) override {
    if (send_status_ != CanStatus::kOk) return send_status_;
    CanFrame f = frame;
    f.t = now_;
    sent_.push_back(f);
    return CanStatus::kOk;
  }
  CanStatus Receive(CanFrame* out) override {
    if (inbox_.empty() || inbox_.front().t > now_) return CanStatus::kNoFrame;
    *out = inbox_.front();
    inbox_.pop_front();
    return out->error ? CanStatus::kError : CanStatus::kOk;
  }

  // Everything sent so far, oldest first; ClearSent() forgets it (e.g. before the tick under test).
  const std::vector<CanFrame>& sent() const { return sent_; }
  void ClearSent() { sent_.clear(); }
  // The sent frames that decode as Message, oldest first.
  template <typename Message>
  std::vector<Message> SentMessages() const {
    std::vector<Message> out;
    for (const CanFrame& f : sent_) {
      Message m;
      if (msg::Decode(f, &m)) out.push_back(m);
    }
    return out;
  }
  // Scripted frames not yet received.
  size_t pending() const { return inbox_.size(); }

 private:
  double now_ = 0;
  std::deque<CanFrame> inbox_;
  std::vector<CanFrame> sent_;
  CanStatus send_status_ = CanStatus::kOk;
};

}  // namespace exotwin::testing
