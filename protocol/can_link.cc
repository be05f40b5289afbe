#include "protocol/can_link.h"

#include <arpa/inet.h>
#include <linux/can.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <deque>
#include <vector>

#include "core/error.h"
#include "protocol/shm_link.h"
#include "protocol/socketcan_bus.h"

namespace exotwin {

struct CanLink::Impl {
  int fd = -1;
  std::unique_ptr<SocketCanBus> can;  // kSocketCan
  std::unique_ptr<ShmLink> shm;       // kShm
  bool yield = false;                 // kShm: waits yield the CPU instead of spinning (OnOneCpu)
  std::string local_path;             // kUnix: unlinked on close
  sockaddr_storage peer{};
  socklen_t peer_len = 0;
  bool held = false;
  std::vector<can_frame> out;  // held frames (Hold .. Flush)
  std::deque<CanFrame> in;     // valid frames of received datagrams, not yet returned by Receive
  double rcv_timeout = -1;     // s, the SO_RCVTIMEO set on fd (-1: none set yet)
  double spin_max = 0, spin = 0;  // s, SetSpin's budget and the current one
  int spin_skip = 0;              // waits left that block at once
  ~Impl() {
    if (fd >= 0) ::close(fd);
    if (!local_path.empty()) ::unlink(local_path.c_str());
  }
};

namespace {

constexpr double kSendWait = 0.1;  // s
// Waits at least this long (s) block in a receive with SO_RCVTIMEO; shorter ones in ppoll.
constexpr double kLongWait = 0.02;
static_assert(sizeof(can_frame) * kMaxFramesPerDatagram == kShmDatagramBytes, "a slot holds the largest datagram");

[[noreturn]] void Fail(const BusAddress& a, const std::string& socket, const std::string& what, int err) {
  throw InputError("--bus " + a.text + ": " + socket + ": " + what + (err ? std::string(": ") + std::strerror(err) : ""));
}

sockaddr_un UnixAddress(const std::string& path) {
  sockaddr_un u{};
  u.sun_family = AF_UNIX;
  std::strncpy(u.sun_path, path.c_str(), sizeof u.sun_path - 1);
  return u;
}

sockaddr_in InetAddress(const std::string& host_port) {
  const size_t c = host_port.rfind(':');
  sockaddr_in in{};
  in.sin_family = AF_INET;
  in.sin_port = htons(static_cast<uint16_t>(std::stoi(host_port.substr(c + 1))));
  ::inet_pton(AF_INET, host_port.substr(0, c).c_str(), &in.sin_addr);
  return in;
}

// True when a live process has a datagram socket bound at `path` (a connect succeeds).
bool UnixSocketInUse(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  const sockaddr_un u = UnixAddress(path);
  const bool live = ::connect(fd, reinterpret_cast<const sockaddr*>(&u), sizeof u) == 0;
  ::close(fd);
  return live;
}

void BindUnix(const BusAddress& a, const std::string& path, CanLink::Impl* impl) {
  struct stat st{};
  if (::lstat(path.c_str(), &st) == 0) {
    if (!S_ISSOCK(st.st_mode)) Fail(a, path, "exists and is not a socket", 0);
    if (UnixSocketInUse(path)) Fail(a, path, "in use by another process", 0);
    ::unlink(path.c_str());  // stale: left by a process that died
  }
  impl->fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);  // blocking: see WaitInput
  if (impl->fd < 0) Fail(a, path, "cannot create a Unix datagram socket", errno);
  const sockaddr_un u = UnixAddress(path);
  const mode_t old = ::umask(0177);  // the socket file is created mode 0600
  const int rc = ::bind(impl->fd, reinterpret_cast<const sockaddr*>(&u), sizeof u);
  const int err = errno;
  ::umask(old);
  if (rc != 0) Fail(a, path, "cannot bind", err);
  impl->local_path = path;
  ::chmod(path.c_str(), 0600);
}

void BindUdp(const BusAddress& a, const std::string& local, CanLink::Impl* impl) {
  impl->fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);  // blocking: see WaitInput
  if (impl->fd < 0) Fail(a, local, "cannot create a UDP socket", errno);
  const sockaddr_in in = InetAddress(local);
  if (::bind(impl->fd, reinterpret_cast<const sockaddr*>(&in), sizeof in) != 0)
    Fail(a, local, errno == EADDRINUSE ? "port in use" : "cannot bind", errno);
}

bool SamePeer(const sockaddr_storage& from, socklen_t from_len, const CanLink::Impl& impl) {
  if (from.ss_family != impl.peer.ss_family) return false;
  if (from.ss_family == AF_UNIX) {
    const auto& a = reinterpret_cast<const sockaddr_un&>(from);
    const auto& b = reinterpret_cast<const sockaddr_un&>(impl.peer);
    const size_t off = offsetof(sockaddr_un, sun_path);
    if (from_len <= off) return false;  // unnamed sender
    return std::strncmp(a.sun_path, b.sun_path, sizeof a.sun_path) == 0;
  }
  const auto& a = reinterpret_cast<const sockaddr_in&>(from);
  const auto& b = reinterpret_cast<const sockaddr_in&>(impl.peer);
  return a.sin_port == b.sin_port && a.sin_addr.s_addr == b.sin_addr.s_addr;
}

}  // namespace

CanLink::CanLink(BusAddress address, LinkEnd end, std::unique_ptr<Impl> impl)
    : address_(std::move(address)), end_(end), impl_(std::move(impl)) {}

CanLink::~CanLink() = default;

std::unique_ptr<CanLink> CanLink::Open(const BusAddress& a, LinkEnd end) {
  auto impl = std::make_unique<Impl>();
  switch (a.kind) {
    case BusKind::kSocketCan:
      impl->can = SocketCanBus::Open(a.interface);
      break;
    case BusKind::kUnix: {
      BindUnix(a, a.LocalName(end), impl.get());
      const sockaddr_un u = UnixAddress(a.PeerName(end));
      std::memcpy(&impl->peer, &u, sizeof u);
      impl->peer_len = sizeof u;
      break;
    }
    case BusKind::kUdp: {
      BindUdp(a, a.LocalName(end), impl.get());
      const sockaddr_in in = InetAddress(a.PeerName(end));
      std::memcpy(&impl->peer, &in, sizeof in);
      impl->peer_len = sizeof in;
      break;
    }
    case BusKind::kShm:
      impl->shm = ShmLink::Open(a, end);
      impl->yield = OnOneCpu();
      break;
  }
  impl->spin_max = impl->spin = a.kind == BusKind::kSocketCan ? 0.0 : kDefaultLinkSpin;
  return std::unique_ptr<CanLink>(new CanLink(a, end, std::move(impl)));
}

std::string CanLink::Describe() const {
  if (address_.kind == BusKind::kSocketCan) return "can:" + address_.interface;
  if (address_.kind == BusKind::kShm)
    return "shm:" + address_.path + " (" + impl_->shm->Path() + ", " + (end_ == LinkEnd::kTwin ? "twin" : "controller") +
           " end)";
  const std::string scheme = address_.kind == BusKind::kUnix ? "unix:" : "udp:";
  return scheme + address_.LocalName(end_) + " (peer " + address_.PeerName(end_) + ")";
}

CanStatus CanLink::Send(const CanFrame& frame) {
  if (!IsValidDataFrame(frame)) return CanStatus::kError;
  if (impl_->can) {
    CanStatus st;
    const double give_up = MonotonicSeconds() + kSendWait;  // a full interface queue: wait as for a Unix peer
    while ((st = impl_->can->Send(frame)) == CanStatus::kQueueFull && MonotonicSeconds() < give_up) {
      const timespec pause{0, 20000};
      ::nanosleep(&pause, nullptr);
    }
    st == CanStatus::kOk ? (++stats_.sent, ++stats_.datagrams_sent) : ++stats_.send_failures;
    return st;
  }
  can_frame cf{};
  cf.can_id = frame.id;
  cf.can_dlc = frame.dlc;
  std::memcpy(cf.data, frame.data.data(), frame.dlc);
  impl_->out.push_back(cf);
  if (impl_->held && impl_->out.size() < static_cast<size_t>(kMaxFramesPerDatagram)) return CanStatus::kOk;
  return SendQueued();
}

void CanLink::Hold() { impl_->held = true; }

CanStatus CanLink::Flush() {
  impl_->held = false;
  return impl_->out.empty() ? CanStatus::kOk : SendQueued();
}

CanStatus CanLink::SendQueued() {
  const size_t frames = impl_->out.size(), bytes = frames * sizeof(can_frame);
  if (impl_->shm) {  // a full mailbox of a live peer is waited for as a full Unix queue
    const double give_up = MonotonicSeconds() + kSendWait;
    while (!impl_->shm->TryPut(impl_->out.data(), bytes)) {
      const bool alive = impl_->shm->PeerAlive();
      if (!alive || MonotonicSeconds() >= give_up) {
        impl_->out.clear();
        stats_.last_send_errno = alive ? EAGAIN : ECONNREFUSED;
        (alive ? stats_.send_failures : stats_.peer_absent) += frames;
        return alive ? CanStatus::kQueueFull : CanStatus::kError;
      }
      const timespec pause{0, 20000};
      ::nanosleep(&pause, nullptr);
    }
    impl_->out.clear();
    stats_.sent += frames;
    ++stats_.datagrams_sent;
    return CanStatus::kOk;
  }
  // A Unix datagram queue holds few datagrams (net.unix.max_dgram_qlen, 10 by default): a full queue
  // of a live peer is waited for, up to kSendWait s, before the datagram is refused (kQueueFull).
  ssize_t n;
  const double give_up = MonotonicSeconds() + kSendWait;
  while ((n = ::sendto(impl_->fd, impl_->out.data(), bytes, MSG_NOSIGNAL | MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&impl_->peer),
                       impl_->peer_len)) < 0 &&
         (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS) && MonotonicSeconds() < give_up) {
    const timespec pause{0, 20000};
    ::nanosleep(&pause, nullptr);
  }
  const int err = errno;
  impl_->out.clear();
  if (n != static_cast<ssize_t>(bytes)) stats_.last_send_errno = n < 0 ? err : EMSGSIZE;
  if (n == static_cast<ssize_t>(bytes)) {
    stats_.sent += frames;
    ++stats_.datagrams_sent;
    return CanStatus::kOk;
  }
  if (n < 0 && (err == ECONNREFUSED || err == ENOENT)) {
    stats_.peer_absent += frames;
    return CanStatus::kError;
  }
  stats_.send_failures += frames;
  if (n < 0 && (err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS)) return CanStatus::kQueueFull;
  return CanStatus::kError;
}

CanStatus CanLink::Receive(CanFrame* out) {
  if (impl_->can) {
    CanStatus st;
    while ((st = impl_->can->Receive(out)) == CanStatus::kError) ++stats_.malformed;  // error frames
    if (st == CanStatus::kOk) ++stats_.received;
    return st;
  }
  while (impl_->in.empty() && ReceiveDatagram() == 1) {
  }
  if (impl_->in.empty()) return CanStatus::kNoFrame;
  *out = impl_->in.front();
  impl_->in.pop_front();
  ++stats_.received;
  return CanStatus::kOk;
}

int CanLink::ReceiveDatagram(bool block) {
  can_frame buf[kMaxFramesPerDatagram + 1];  // one frame more: a longer datagram is seen as such
  if (impl_->shm) {  // (blocking waits are WaitInput's)
    size_t n = 0;
    if (!impl_->shm->TryTake(buf, &n)) return 0;
    TakeDatagram(buf, n);
    return 1;
  }
  sockaddr_storage from{};
  socklen_t from_len = sizeof from;
  const ssize_t n = ::recvfrom(impl_->fd, buf, sizeof buf, MSG_TRUNC | (block ? 0 : MSG_DONTWAIT),
                               reinterpret_cast<sockaddr*>(&from), &from_len);
  if (n < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK) return 0;
    if (errno == EINTR) return block ? -1 : 1;
    if (errno == ECONNREFUSED) return 1;  // UDP: a refused earlier send
    ++stats_.malformed;
    return 0;
  }
  if (!SamePeer(from, from_len, *impl_)) {
    ++stats_.foreign;
    return 1;
  }
  TakeDatagram(buf, static_cast<size_t>(n));
  return 1;
}

void CanLink::TakeDatagram(const void* datagram, size_t n) {
  const can_frame* buf = static_cast<const can_frame*>(datagram);
  const size_t frames = n / sizeof(can_frame);
  if (n == 0 || n % sizeof(can_frame) != 0 || frames > static_cast<size_t>(kMaxFramesPerDatagram)) {
    ++stats_.malformed;
    return;
  }
  const double now = MonotonicSeconds();
  for (size_t i = 0; i < frames; ++i) {
    const can_frame& cf = buf[i];
    if ((cf.can_id & ~CAN_SFF_MASK) != 0 || cf.can_dlc > 8) {  // EFF / RTR / ERR flags or a long DLC
      ++stats_.malformed;
      continue;
    }
    CanFrame f;
    f.id = static_cast<uint16_t>(cf.can_id);
    f.dlc = cf.can_dlc;
    std::memcpy(f.data.data(), cf.data, cf.can_dlc);
    f.t = now;
    impl_->in.push_back(f);
  }
}

bool CanLink::PeerAlive() const {
  if (impl_->shm) return impl_->shm->PeerAlive();
  return address_.kind != BusKind::kUnix || UnixSocketInUse(address_.PeerName(end_));
}

size_t CanLink::Queued() const { return impl_->in.size(); }

double CanLink::spin_budget() const {
  return impl_->spin_skip > 1 || impl_->spin_max <= 0 ? 0.0 : (impl_->spin > 0 ? impl_->spin : impl_->spin_max);
}

void CanLink::SetSpin(double max_spin_s) {
  impl_->spin_max = impl_->spin = std::max(0.0, max_spin_s);
  impl_->spin_skip = 0;
  if (impl_->shm) impl_->yield = OnOneCpu();
}

bool CanLink::SpinForInput(double timeout_s) {
  Impl& m = *impl_;
  if (m.spin_max <= 0) return false;
  if (m.spin_skip > 0 && --m.spin_skip > 0) return false;
  if (m.spin <= 0) m.spin = m.spin_max;  // the probe after kSpinProbe waits that blocked at once
  const double end = MonotonicSeconds() + std::min(m.spin, timeout_s);
  const bool yield = m.shm && (m.yield || m.shm->PeerOnThisCpu());
  do {
    if (ReceiveDatagram() == 1 && !m.in.empty()) {
      m.spin = m.spin_max;
      return true;
    }
    if (m.shm) SpinPause(yield);  // (a socket's read is a system call: no pause needed)
  } while (MonotonicSeconds() < end);
  m.spin *= 0.5;
  if (m.spin < 1e-6) m.spin = 0, m.spin_skip = kSpinProbe;
  return false;
}

bool CanLink::WaitInput(double timeout_s) {
  if (!impl_->in.empty()) return true;
  auto wait_poll = [&](int fd, double seconds) {  // ppoll: a timer of its own, as exact as the kernel's
    pollfd p{};
    p.fd = fd;
    p.events = POLLIN;
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(seconds);
    ts.tv_nsec = static_cast<long>((seconds - std::floor(seconds)) * 1e9);
    return ::ppoll(&p, 1, &ts, nullptr) > 0 && (p.revents & POLLIN);
  };
  if (impl_->can) return wait_poll(impl_->can->fd(), std::max(0.0, timeout_s));
  auto take = [&] {  // the datagrams waiting, until one brings frames
    while (impl_->in.empty() && ReceiveDatagram() == 1) {
    }
    return !impl_->in.empty();
  };
  if (timeout_s <= 0) return take();
  const double end = MonotonicSeconds() + timeout_s;
  if (SpinForInput(timeout_s)) return true;
  if (impl_->shm) {  // then sleep on the mailbox's futex
    for (;;) {
      if (take()) return true;
      const double left = end - MonotonicSeconds();
      if (left <= 0) return false;
      const int got = impl_->shm->BlockForInput(left);
      if (take()) return true;
      if (got < 0) return false;  // a signal
    }
  }
  for (;;) {  // foreign and malformed datagrams are dropped on the way
    const double left = end - MonotonicSeconds();
    if (left <= 0) return take();
    if (left < kLongWait) {  // short: ppoll's timer (SO_RCVTIMEO counts whole kernel ticks)
      if (!wait_poll(impl_->fd, left)) return take();
      if (take()) return true;
      continue;
    }
    // Long (a give-up guard): one blocking receive, the wait of a cycle costing one system call. The
    // timeout, whole ms (the kernel may round it up to its tick), is set only when it changes.
    const double timeout = std::floor(left * 1e3) * 1e-3;
    if (timeout != impl_->rcv_timeout) {
      timeval tv{};
      tv.tv_sec = static_cast<time_t>(timeout);
      tv.tv_usec = static_cast<suseconds_t>(std::lround((timeout - std::floor(timeout)) * 1e6));
      if (tv.tv_usec >= 1000000) ++tv.tv_sec, tv.tv_usec -= 1000000;
      ::setsockopt(impl_->fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
      impl_->rcv_timeout = timeout;
    }
    const int got = ReceiveDatagram(true);
    if (take()) return true;
    if (got < 0) return false;  // a signal
  }
}

}  // namespace exotwin
