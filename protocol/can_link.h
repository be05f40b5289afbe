// A CAN link between two processes (DESIGN.md "The CAN transport between processes"): datagrams of 1
// to kMaxFramesPerDatagram frames, each frame SocketCAN's 16-byte `struct can_frame` (can_id: 11-bit
// identifier, no flags; can_dlc 0..8; 3 padding bytes zero; data[8]), over a Unix datagram socket,
// UDP or the mailboxes of a shared-memory segment (protocol/shm_link.h), or the frames of a SocketCAN
// interface (one frame at a time: a real bus). Implements CanBus,
// non-blocking, plus a wait for input. Frames sent between Hold() and Flush() leave as one datagram
// (a controller cycle's frames: one system call per direction and cycle instead of one per frame).
//
// Security (the link carries torque commands to a device on a person): each end accepts datagrams only
// from the other end's configured address (BusAddress::PeerName), never from any other sender; those
// are dropped and counted (foreign), as are datagrams that are not a classic 11-bit data frame of 16
// bytes (malformed). Unix sockets are created with mode 0600. UDP binds where ADDR says (loopback
// unless the user names another address). A shared-memory segment is mode 0600 and each of its two
// ends is held by one live process (ShmLink), so its datagrams come from the peer by construction;
// they are checked as a socket's (malformed).
#pragma once
#include <cstdint>
#include <memory>
#include <string>

#include "core/realtime.h"  // MonotonicSeconds
#include "protocol/bus_address.h"
#include "protocol/can_bus.h"

namespace exotwin {

// The spin budget of a link's waits unless set (CanLink::SetSpin; `serve --link-spin`,
// `exotwin-controller --spin`): s.
constexpr double kDefaultLinkSpin = 50e-6;

// The most frames one datagram carries (1024 bytes: one Ethernet frame with its UDP header).
constexpr int kMaxFramesPerDatagram = 64;

struct CanLinkStatistics {
  uint64_t received = 0;        // frames returned by Receive
  uint64_t sent = 0;            // frames handed to the kernel
  uint64_t datagrams_sent = 0;  // datagrams (or SocketCAN frames) handed to the kernel
  uint64_t foreign = 0;         // datagrams from an unconfigured sender, dropped
  uint64_t malformed = 0;       // datagrams not a whole number (1..64) of frames, and frames not an
                                // 11-bit data frame, dropped
  uint64_t peer_absent = 0;     // Sends refused because the peer's socket does not exist / listen
  uint64_t send_failures = 0;   // other failed Sends (buffer full, ...)
  int last_send_errno = 0;      // errno of the last failed send (0: none failed)
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
  // While held (Hold), a valid frame is queued (kOk) and leaves at Flush, or as soon as
  // kMaxFramesPerDatagram are queued.
  CanStatus Send(const CanFrame& frame) override;
  // From now on Send queues its frames for one datagram (Unix, UDP, shared memory; SocketCAN sends at once).
  void Hold();
  // Sends the queued frames as one datagram and ends the hold: the status as Send's (kOk when none
  // were queued; the frames of a refused datagram count as send failures or peer_absent).
  CanStatus Flush();
  // kOk with the oldest valid frame from the peer (out->t: CLOCK_MONOTONIC, s); kNoFrame when none
  // is waiting (foreign and malformed datagrams are dropped on the way, and counted).
  CanStatus Receive(CanFrame* out) override;
  // Waits until input is waiting or `timeout_s` (s) passed (or a signal arrived); true if input waits.
  // Unix and UDP: first spins (non-blocking reads) for up to the adaptive spin budget (SetSpin), then
  // blocks in one receive with the remaining time as timeout (SO_RCVTIMEO), so a wait that blocks
  // costs one system call, not a poll and a read. Shared memory: spins on the mailbox (the CPU's
  // pause between looks; sched_yield instead when this process may run on one CPU only, OnOneCpu, or
  // the peer last waited on this end's CPU, ShmLink::PeerOnThisCpu: the peer then needs this CPU to
  // answer), then sleeps on its futex. SocketCAN: poll(2).
  bool WaitInput(double timeout_s);
  // The most a wait spins before it blocks (s; kDefaultLinkSpin unless set; 0: it blocks at once;
  // SocketCAN never spins). A peer running on
  // another CPU answers within microseconds, sooner than a blocked process is woken (a cross-CPU
  // wake-up costs tens of microseconds on a virtual machine); a peer that is not running (a loaded
  // machine, one CPU) cannot answer while this end spins. So the budget adapts: a wait that blocks
  // halves it, one answered while spinning restores it; once below 1 us the waits block at once, and
  // every kSpinProbe-th wait tries the whole budget again.
  void SetSpin(double max_spin_s);
  double spin_budget() const;  // s, what the next wait spins at most (0: it blocks at once)
  static constexpr int kSpinProbe = 64;
  // False when the peer is known to be gone: a Unix peer whose socket no live process holds (the file
  // of a killed process stays behind), a shared-memory peer whose end no live process holds. True
  // otherwise (UDP and SocketCAN cannot tell).
  bool PeerAlive() const;
  // The frames already read from the socket and not yet returned by Receive (Receive reads the
  // socket only when there are none).
  size_t Queued() const;
  const CanLinkStatistics& statistics() const { return stats_; }
  const BusAddress& address() const { return address_; }
  // "unix:PATH (peer PATH.ctl)" and the like, for logs.
  std::string Describe() const;

  struct Impl;  // the sockets (can_link.cc)

 private:
  CanLink(BusAddress address, LinkEnd end, std::unique_ptr<Impl> impl);
  CanStatus SendQueued();   // the held frames as one datagram
  // One datagram's valid frames into the input queue: 1 when a datagram was read (its frames may all
  // have been dropped), 0 when none waits (or, blocking, none came within the receive timeout), -1
  // when a signal interrupted a blocking read.
  int ReceiveDatagram(bool block = false);
  // A datagram's `n` bytes checked (a whole number, 1..64, of frames; each an 11-bit data frame) and
  // its valid frames queued; the rest counted malformed.
  void TakeDatagram(const void* datagram, size_t n);
  bool SpinForInput(double timeout_s);  // the spin phase of WaitInput
  BusAddress address_;
  LinkEnd end_;
  std::unique_ptr<Impl> impl_;
  CanLinkStatistics stats_;
};

}  // namespace exotwin
