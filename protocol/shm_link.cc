#include "protocol/shm_link.h"

#include <fcntl.h>
#include <linux/futex.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <type_traits>

#include "core/error.h"

namespace exotwin {

// The shared layout. A fresh segment is all zero bytes (ftruncate), a valid empty state: magic 0 until
// the first opener sets it, both mailboxes empty. The sequence numbers and flags are
// std::atomic<uint32_t> placed in the shared mapping: lock-free and of the size and alignment of a
// uint32_t (checked below), so both processes (and the futex) act on the same 4 bytes.
struct ShmLink::Segment {
  struct Slot {
    uint32_t bytes;         // the datagram's length
    uint32_t reserved[3];   // zero
    unsigned char data[kShmDatagramBytes];
  };
  struct Mailbox {
    alignas(64) std::atomic<uint32_t> head;      // datagrams published (producer), the futex word
    alignas(64) std::atomic<uint32_t> tail;      // datagrams taken (consumer)
    alignas(64) std::atomic<uint32_t> sleeping;  // 1 while the consumer sleeps on the futex
    alignas(64) Slot slots[kShmSlots];
  };
  std::atomic<uint32_t> magic;  // kMagic once opened
  uint32_t layout;              // sizeof(Segment) of the opener
  std::atomic<uint32_t> cpu[2];  // 1 + the CPU end i last waited on (0: not known yet)
  alignas(64) Mailbox to[2];    // to[i]: the mailbox end i reads (0 the twin, 1 the controller)
};

namespace {

using Segment = ShmLink::Segment;

static_assert(std::atomic<uint32_t>::is_always_lock_free, "the mailboxes need lock-free 32-bit atomics");
static_assert(sizeof(std::atomic<uint32_t>) == sizeof(uint32_t) && alignof(std::atomic<uint32_t>) == alignof(uint32_t),
              "a futex word is a plain 32-bit integer");
static_assert(std::is_standard_layout<Segment>::value, "the segment is shared between processes");
static_assert((kShmSlots & (kShmSlots - 1)) == 0, "sequence numbers wrap at 2^32");

constexpr uint32_t kMagic = 0x4C4D5358;  // "XSML"
constexpr off_t kOpenLockByte = 2;       // held while an end opens or removes the segment

int Index(LinkEnd end) { return end == LinkEnd::kTwin ? 0 : 1; }

[[noreturn]] void Fail(const BusAddress& a, const std::string& what, int err) {
  throw InputError("--bus " + a.text + ": /dev/shm/" + a.path + ": " + what + (err ? std::string(": ") + std::strerror(err) : ""));
}

// An open-file-description lock on `byte`: set (F_WRLCK, waiting when `wait`) or released (F_UNLCK).
bool Lock(int fd, off_t byte, short type, bool wait) {
  struct flock l{};
  l.l_type = type;
  l.l_whence = SEEK_SET;
  l.l_start = byte;
  l.l_len = 1;
  int rc;
  while ((rc = ::fcntl(fd, wait ? F_OFD_SETLKW : F_OFD_SETLK, &l)) != 0 && errno == EINTR) {
  }
  return rc == 0;
}

// True when another open file description (another process's end) holds `byte`.
bool LockedElsewhere(int fd, off_t byte) {
  struct flock l{};
  l.l_type = F_WRLCK;
  l.l_whence = SEEK_SET;
  l.l_start = byte;
  l.l_len = 1;
  return ::fcntl(fd, F_OFD_GETLK, &l) == 0 && l.l_type != F_UNLCK;
}

// True when `name` names the file open as `st` (it was not removed or replaced meanwhile).
bool NamesThisFile(const std::string& name, const struct stat& st) {
  const int fd = ::shm_open(name.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd < 0) return false;
  struct stat now{};
  const bool same = ::fstat(fd, &now) == 0 && now.st_dev == st.st_dev && now.st_ino == st.st_ino;
  ::close(fd);
  return same;
}

long Futex(std::atomic<uint32_t>* word, int op, uint32_t value, const timespec* timeout) {
  return ::syscall(SYS_futex, reinterpret_cast<uint32_t*>(word), op, value, timeout, nullptr, 0);
}

}  // namespace

std::unique_ptr<ShmLink> ShmLink::Open(const BusAddress& a, LinkEnd end) {
  const std::string name = "/" + a.path;
  const int me = Index(end), peer = 1 - me;
  std::unique_ptr<ShmLink> link(new ShmLink());
  link->address_ = a;
  link->end_ = end;
  for (int attempt = 0; attempt < 8; ++attempt) {
    const mode_t old = ::umask(0177);  // created mode 0600
    const int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0600);
    const int err = errno;
    ::umask(old);
    if (fd < 0) Fail(a, "cannot create or open the shared-memory segment", err);
    link->fd_ = fd;  // closed by the destructor if a check below throws
    Lock(fd, kOpenLockByte, F_WRLCK, true);
    struct stat st{};
    if (::fstat(fd, &st) != 0) Fail(a, "cannot stat the segment", errno);
    if (!NamesThisFile(name, st)) {  // replaced while this end waited for the open lock
      ::close(fd), link->fd_ = -1;
      continue;
    }
    if (!S_ISREG(st.st_mode)) Fail(a, "is not a shared-memory segment", 0);
    if (st.st_uid != ::geteuid()) Fail(a, "belongs to another user (uid " + std::to_string(st.st_uid) + ")", 0);
    if ((st.st_mode & 077) != 0) {
      char mode[8];
      std::snprintf(mode, sizeof mode, "%03o", static_cast<unsigned>(st.st_mode & 0777));
      Fail(a, std::string("is accessible to other users (mode ") + mode + ", expected 600)", 0);
    }
    if (st.st_size == 0) {
      if (::ftruncate(fd, sizeof(Segment)) != 0) Fail(a, "cannot size the segment", errno);
    } else if (st.st_size != static_cast<off_t>(sizeof(Segment))) {
      Fail(a, "is not a link segment of this version (" + std::to_string(st.st_size) + " bytes, expected " +
                  std::to_string(sizeof(Segment)) + "); remove it if no process uses it",
           0);
    }
    if (!Lock(fd, me, F_WRLCK, false))
      Fail(a, std::string("its ") + (end == LinkEnd::kTwin ? "twin" : "controller") + " end is in use by another process", 0);
    void* p = ::mmap(nullptr, sizeof(Segment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) Fail(a, "cannot map the segment", errno);
    link->seg_ = static_cast<Segment*>(p);
    Segment& s = *link->seg_;
    const uint32_t magic = s.magic.load(std::memory_order_acquire);
    if (magic != 0 && (magic != kMagic || s.layout != sizeof(Segment)))
      Fail(a, "is not a link segment of this version; remove it if no process uses it", 0);
    if (magic == kMagic && !LockedElsewhere(fd, peer)) {  // stale: both ends left by dead processes
      ::munmap(p, sizeof(Segment)), link->seg_ = nullptr;
      ::shm_unlink(name.c_str());
      ::close(fd), link->fd_ = -1;  // releases this end's locks
      continue;
    }
    if (magic == 0) {
      s.layout = sizeof(Segment);
      s.magic.store(kMagic, std::memory_order_release);
    }
    // What a dead predecessor of this end left unread is not for this process (a new Unix socket
    // starts empty too); this end is the mailbox's only consumer.
    Segment::Mailbox& in = s.to[me];
    in.sleeping.store(0);
    in.tail.store(in.head.load(std::memory_order_acquire), std::memory_order_release);
    Lock(fd, kOpenLockByte, F_UNLCK, false);
    link->opened_ = true;
    return link;
  }
  Fail(a, "was replaced by other processes at every attempt to open it", 0);
}

ShmLink::~ShmLink() {
  if (fd_ < 0) return;
  if (!opened_) {  // a refused open leaves the segment as it found it
    if (seg_) ::munmap(seg_, sizeof(Segment));
    ::close(fd_);
    return;
  }
  Lock(fd_, kOpenLockByte, F_WRLCK, true);
  struct stat st{};
  const std::string name = "/" + address_.path;
  // Removed by the last end to leave (the peer not attached): a peer that stays keeps it for this
  // end's successor, as a Unix peer's socket stays.
  if (!LockedElsewhere(fd_, 1 - Index(end_)) && ::fstat(fd_, &st) == 0 && NamesThisFile(name, st))
    ::shm_unlink(name.c_str());
  ::munmap(seg_, sizeof(Segment));
  ::close(fd_);  // releases this end's locks
}

bool ShmLink::TryPut(const void* data, size_t bytes) {
  Segment::Mailbox& m = seg_->to[1 - Index(end_)];
  const uint32_t head = m.head.load(std::memory_order_relaxed);  // written by this end only
  if (head - m.tail.load(std::memory_order_acquire) >= kShmSlots) return false;
  Segment::Slot& slot = m.slots[head % kShmSlots];
  slot.bytes = static_cast<uint32_t>(bytes);
  std::memcpy(slot.data, data, bytes);
  m.head.store(head + 1, std::memory_order_seq_cst);  // publish; then see whether the consumer sleeps
  if (m.sleeping.load(std::memory_order_seq_cst) != 0) Futex(&m.head, FUTEX_WAKE, 1, nullptr);
  return true;
}

bool ShmLink::InputWaiting() const {
  const Segment::Mailbox& m = seg_->to[Index(end_)];
  return m.head.load(std::memory_order_acquire) != m.tail.load(std::memory_order_relaxed);
}

bool ShmLink::TryTake(void* buf, size_t* bytes) {
  Segment::Mailbox& m = seg_->to[Index(end_)];
  const uint32_t tail = m.tail.load(std::memory_order_relaxed);  // written by this end only
  if (m.head.load(std::memory_order_acquire) == tail) return false;
  const Segment::Slot& slot = m.slots[tail % kShmSlots];
  *bytes = slot.bytes;
  if (*bytes > 0 && *bytes <= kShmDatagramBytes) std::memcpy(buf, slot.data, *bytes);
  m.tail.store(tail + 1, std::memory_order_release);  // the slot is the producer's again
  return true;
}

int ShmLink::BlockForInput(double timeout_s) {
  Segment::Mailbox& m = seg_->to[Index(end_)];
  m.sleeping.store(1, std::memory_order_seq_cst);  // announce, then look (the producer: publish, then look)
  const uint32_t head = m.head.load(std::memory_order_seq_cst);
  int result = 0;
  if (head == m.tail.load(std::memory_order_relaxed) && timeout_s > 0) {
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(timeout_s);
    ts.tv_nsec = static_cast<long>((timeout_s - std::floor(timeout_s)) * 1e9);
    if (Futex(&m.head, FUTEX_WAIT, head, &ts) != 0 && errno == EINTR) result = -1;
  }
  m.sleeping.store(0, std::memory_order_relaxed);
  return InputWaiting() ? 1 : result;
}

bool ShmLink::PeerOnThisCpu() {
  const int cpu = ::sched_getcpu();  // a read of the thread's rseq area: about 2 ns
  if (cpu < 0) return false;
  seg_->cpu[Index(end_)].store(static_cast<uint32_t>(cpu) + 1, std::memory_order_relaxed);
  return seg_->cpu[1 - Index(end_)].load(std::memory_order_relaxed) == static_cast<uint32_t>(cpu) + 1;
}

bool ShmLink::PeerAlive() const { return LockedElsewhere(fd_, 1 - Index(end_)); }

std::string ShmLink::Path() const { return "/dev/shm/" + address_.path; }

bool OnOneCpu() {
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  return ::sched_getaffinity(0, sizeof cpus, &cpus) == 0 && CPU_COUNT(&cpus) == 1;
}

void SpinPause(bool yield) {
  if (yield) {
    ::sched_yield();
    return;
  }
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

}  // namespace exotwin
