// The shared-memory transport of the CAN link (`shm:NAME`, DESIGN.md "The CAN transport between
// processes"): two processes on one host exchange the link's datagrams (1 to kMaxFramesPerDatagram
// frames of 16 bytes, the bytes a Unix datagram carries) through one single-producer / single-consumer
// mailbox per direction in the POSIX shared-memory segment /NAME (/dev/shm/NAME), without a system
// call when both ends run.
//
// Segment: a header and two mailboxes, each a ring of kShmSlots datagram slots with two sequence
// numbers, `head` (datagrams published; written by the producer only) and `tail` (datagrams taken;
// written by the consumer only), std::atomic<uint32_t> (lock-free, checked), release on write and
// acquire on read: a slot is read only after its head was published and rewritten only after its tail
// was; no datagram is lost or reordered. A consumer that blocks sleeps on a futex on `head` (announced
// in `sleeping`, which the producer checks after publishing: the Dekker pattern, sequentially
// consistent), so an idle or dead peer costs no CPU.
//
// Ends and liveness: each end holds an open-file-description lock (F_OFD_SETLK) on its byte of the
// segment (0: twin, 1: controller) while it is open; the kernel drops it when the process dies, so a
// peer is alive exactly when its byte is locked. Opens and the removal at close take a third byte
// (F_OFD_SETLKW) so they never interleave. Open: the segment is created mode 0600 (the caller's user
// only: a segment of another user or readable by others is refused); an end held by a live process is
// an input error; a segment whose both ends are free (left by dead processes) is replaced by a new one;
// a segment with the peer attached is joined (the datagrams left for this end by a dead predecessor
// are discarded, as a new Unix socket starts empty). Close: the segment is removed when the peer is
// not attached.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "protocol/bus_address.h"

namespace exotwin {

// Datagram slots per direction (a power of 2: the sequence numbers wrap at 2^32).
constexpr uint32_t kShmSlots = 32;
// The bytes of the largest datagram a slot holds (kMaxFramesPerDatagram frames of 16 bytes).
constexpr size_t kShmDatagramBytes = 64 * 16;

class ShmLink {
 public:
  // Opens (creates, joins or replaces) `end` of the segment of `address` (kind kShm). Throws
  // InputError naming the address when the segment cannot be created or mapped, is another user's,
  // is readable by others, is not a link segment of this layout, or `end` is held by a live process.
  static std::unique_ptr<ShmLink> Open(const BusAddress& address, LinkEnd end);
  ~ShmLink();
  ShmLink(const ShmLink&) = delete;
  ShmLink& operator=(const ShmLink&) = delete;

  // Publishes one datagram of `bytes` (1..kShmDatagramBytes) to the peer's mailbox and wakes the peer
  // if it sleeps; false when the mailbox is full (nothing published).
  bool TryPut(const void* data, size_t bytes);
  // Takes the oldest datagram from the peer into buf (kShmDatagramBytes bytes): true with *bytes its
  // length as the peer wrote it (the caller checks it; a length of 0 or beyond kShmDatagramBytes is
  // returned as such, nothing copied); false when none waits.
  bool TryTake(void* buf, size_t* bytes);
  // True when a datagram from the peer waits (a load, no system call).
  bool InputWaiting() const;
  // Sleeps on the futex until a datagram from the peer waits, `timeout_s` (s) passed or a signal
  // arrived: 1 when one waits, 0 on time-out, -1 on a signal.
  int BlockForInput(double timeout_s);
  // Records the CPU this end runs on (it is about to wait) and returns true when the peer last waited
  // on the same CPU: the peer then most likely needs this CPU to answer (sched_getcpu, no system call).
  bool PeerOnThisCpu();
  // True when the peer's end is held by a live process (one fcntl).
  bool PeerAlive() const;
  // "/dev/shm/NAME".
  std::string Path() const;

  struct Segment;  // the shared layout (shm_link.cc)

 private:
  ShmLink() = default;
  BusAddress address_;
  LinkEnd end_ = LinkEnd::kTwin;
  int fd_ = -1;
  Segment* seg_ = nullptr;
  bool opened_ = false;  // Open succeeded: the destructor may remove the segment
};

// True when the calling thread may run on one CPU only (its affinity mask): a peer on the same CPU
// cannot answer while this end spins, so the link's waits yield the CPU (sched_yield) instead.
bool OnOneCpu();

// One step of a busy wait: the CPU's spin hint (x86 PAUSE) or, when `yield`, sched_yield.
void SpinPause(bool yield);

}  // namespace exotwin
