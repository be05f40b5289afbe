// SocketCAN backend (Linux): a raw CAN socket bound to one interface (e.g. "can0", "vcan0"),
// non-blocking, with an optional kernel receive filter. Built everywhere on Linux; needs a kernel
// with CAN support and an existing interface to open, so CI only tests that opening fails cleanly.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "protocol/can_bus.h"

namespace exotwin {

class SocketCanBus : public CanBus {
 public:
  // Opens a CAN_RAW socket on interface (accept_ids empty = every ID; bus errors are always
  // delivered as error frames). Throws InputError naming the interface when the kernel has no CAN
  // support, the interface does not exist, or the socket cannot be set up.
  static std::unique_ptr<SocketCanBus> Open(const std::string& interface, std::vector<uint16_t> accept_ids = {});
  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;
  // Non-blocking write: kOk, kQueueFull (socket buffer full), kBusOff (controller bus-off or
  // interface down), kError (invalid frame, other errors).
  CanStatus Send(const CanFrame& frame) override;
  // Non-blocking read: kOk, kNoFrame, kError (error frame in *out, or a read failure). out->t is
  // the kernel receive time stamp (s since the Unix epoch) when available, else CLOCK_REALTIME.
  CanStatus Receive(CanFrame* out) override;
  // True after the controller reported bus-off, until it reports a restart.
  bool bus_off() const { return bus_off_; }
  const std::string& interface() const { return interface_; }
  // The socket's descriptor (for poll(2); owned by this object).
  int fd() const { return fd_; }

 private:
  SocketCanBus(int fd, std::string interface) : fd_(fd), interface_(std::move(interface)) {}
  int fd_ = -1;
  std::string interface_;
  bool bus_off_ = false;
};

}  // namespace exotwin
