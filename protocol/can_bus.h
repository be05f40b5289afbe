// The bus interface the controller and the device nodes use. Backends: the in-process virtual bus
// (hwsim/virtual_can_bus.h), candump log replay (protocol/candump_replay_bus.h) and SocketCAN
// (protocol/socketcan_bus.h). Real-time path: status codes, never exceptions, never blocking.
#pragma once
#include "protocol/can_frame.h"

namespace exotwin {

enum class CanStatus {
  kOk,         // frame queued (Send) or a data frame returned (Receive)
  kQueueFull,  // transmit queue full: the frame was not queued
  kBusOff,     // this node is bus-off: nothing is sent until it recovers
  kNoFrame,    // Receive: nothing to read now
  kError,      // Send: invalid frame or backend failure; Receive: *out is an error frame (out->error)
};

// Human-readable name of a status ("ok", "queue_full", ...).
const char* CanStatusName(CanStatus s);

class CanBus {
 public:
  // Queues one data frame for transmission; frame.t is ignored (the backend stamps its own time).
  virtual CanStatus Send(const CanFrame& frame) = 0;
  // Non-blocking: pops the oldest received frame into *out (out != nullptr) or returns kNoFrame.
  virtual CanStatus Receive(CanFrame* out) = 0;
  virtual ~CanBus();
};

}  // namespace exotwin
