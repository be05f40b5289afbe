// A CAN link between two processes (DESIGN.md "The CAN transport between processes"): one datagram
// per frame, the datagram being SocketCAN's 16-byte `struct can_frame` (can_id: 11-bit identifier,
// no flags; can_dlc 0..8; 3 padding bytes zero; data[8]) over a Unix datagram socket or UDP, or the
// frames of a SocketCAN interface. Implements CanBus, non-blocking, plus a wait for input.
//
// Security (the link carries torque commands to a device on a person): each end accepts datagrams only
// from the other end's configured address (BusAddress::PeerName), never from any other sender; those
// are dropped and counted (foreign), as are datagrams that are not a classic 11-bit data frame of 16
// bytes (malformed). Unix sockets are created with mode 0600. UDP binds where ADDR says (loopback
// unless the user names another address).
#pragma once
#include <cstdint>
#include <memory>
#include <string>

#include "protocol/bus_address.h"
#include "protocol/can_bus.h"

namespace exotwin {

struct CanLinkStatistics {
  uint64_t received = 0;        // frames returned by Receive
  uint64_t sent = 0;            // frames handed to the kernel
  uint64_t foreign = 0;         // datagrams from an unconfigured sender, dropped
  uint64_t malformed = 0;       // datagrams of the wrong length, or not an 11-bit data frame, dropped
  uint64_t peer_absent = 0;     // Sends refused because the peer's socket does not exist / listen
  uint64_t send_failures = 0;   // other failed Sends (buffer full, ...)
};

class CanLink : public CanBus {
 public:
  // Opens `end` of the link at `address`. Throws InputError naming the address when the socket cannot
  // be created or bound (missing folder, a path or port in use by a live process, no such interface).
  // A stale Unix socket file left by a dead process is replaced; a path that is not a socket is not.
  static std::unique_ptr<CanLink> Open(const BusAddress& address, LinkEnd end);
  ~CanLink() override;
  CanLink(const CanLink&) = delete;
  CanLink& operator=(const CanLink&) = delete;

  // kOk; kError when the frame is invalid or the peer is absent (peer_absent counted); kQueueFull
  // when the peer's queue stayed full for 0.1 s (the send waits that long for a live peer to read).
  CanStatus Send(const CanFrame& frame) override;
  // kOk with the oldest valid frame from the peer (out->t: CLOCK_MONOTONIC, s); kNoFrame when none
  // is waiting (foreign and malformed datagrams are dropped on the way, and counted).
  CanStatus Receive(CanFrame* out) override;
  // Blocks until input is waiting or `timeout_s` (s) passed (or a signal arrived); true if input waits.
  bool WaitInput(double timeout_s);
  // False when the peer is known to be gone: a Unix peer whose socket no live process holds (the file
  // of a killed process stays behind). True otherwise (UDP and SocketCAN cannot tell).
  bool PeerAlive() const;
  const CanLinkStatistics& statistics() const { return stats_; }
  const BusAddress& address() const { return address_; }
  // "unix:PATH (peer PATH.ctl)" and the like, for logs.
  std::string Describe() const;

  struct Impl;  // the sockets (can_link.cc)

 private:
  CanLink(BusAddress address, LinkEnd end, std::unique_ptr<Impl> impl);
  BusAddress address_;
  LinkEnd end_;
  std::unique_ptr<Impl> impl_;
  CanLinkStatistics stats_;
};

// Monotonic wall-clock time (s) used by the links' time stamps and the real-time clock.
double MonotonicSeconds();

}  // namespace exotwin
