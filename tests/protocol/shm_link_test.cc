// The shared-memory link (`shm:NAME`, protocol/shm_link.h) through CanLink, as serve and
// exotwin-controller use it: datagrams of 1 and 64 frames both ways in order, a full mailbox, waits
// that block and wake, a dead peer, a stale segment replaced, a live end refused, malformed datagrams.
#include "protocol/shm_link.h"

#include <fcntl.h>
#include <linux/can.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/realtime.h"
#include "protocol/can_link.h"

namespace exotwin {
namespace {

// A segment name of its own for each use (tests run in parallel processes).
std::string Name() {
  static int n = 0;
  return "exotwin_test_" + std::to_string(::getpid()) + "_" + std::to_string(n++);
}

CanFrame Frame(uint16_t id, uint8_t b0, uint8_t b1 = 0) {
  CanFrame f;
  f.id = id;
  f.dlc = 2;
  f.data[0] = b0;
  f.data[1] = b1;
  return f;
}

bool Exists(const std::string& name) {
  struct stat st{};
  return ::stat(("/dev/shm/" + name).c_str(), &st) == 0;
}

// Forks a child that opens `end` of `a`, sends `datagrams` one-frame datagrams (0x100, i), reports
// through a pipe and waits to be killed: returns its pid once it has sent.
pid_t LiveEndInChild(const BusAddress& a, LinkEnd end, int datagrams) {
  int p[2];
  EXPECT_EQ(::pipe(p), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(p[0]);
    try {
      auto link = CanLink::Open(a, end);
      for (int i = 0; i < datagrams; ++i) link->Send(Frame(0x100, static_cast<uint8_t>(i)));
      char ok = 1;
      if (::write(p[1], &ok, 1) != 1) ::_exit(1);
      for (;;) ::pause();
    } catch (...) {
      ::_exit(1);
    }
  }
  ::close(p[1]);
  char ok = 0;
  EXPECT_EQ(::read(p[0], &ok, 1), 1);
  ::close(p[0]);
  return pid;
}

void Kill(pid_t pid) {
  ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
}

TEST(ShmLink, DatagramsOfOneAnd64FramesBothWaysInOrderSegmentOwnerOnly) {
  const std::string name = Name();
  const BusAddress a = ParseBusAddress("shm:" + name);
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  auto ctl = CanLink::Open(a, LinkEnd::kController);
  struct stat st{};
  ASSERT_EQ(::stat(("/dev/shm/" + name).c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(twin->Describe(), "shm:" + name + " (/dev/shm/" + name + ", twin end)");

  ASSERT_EQ(twin->Send(Frame(0x080, 7)), CanStatus::kOk);  // one frame, one datagram
  CanFrame f;
  ASSERT_TRUE(ctl->WaitInput(1.0));
  ASSERT_EQ(ctl->Receive(&f), CanStatus::kOk);
  EXPECT_TRUE(SamePayload(f, Frame(0x080, 7)));
  EXPECT_EQ(ctl->Receive(&f), CanStatus::kNoFrame);

  ctl->Hold();  // 64 frames: one datagram; 100: 64 + 36; their order kept
  for (int i = 0; i < 64; ++i) ASSERT_EQ(ctl->Send(Frame(0x100, static_cast<uint8_t>(i))), CanStatus::kOk);
  EXPECT_EQ(ctl->statistics().datagrams_sent, 1u);
  ASSERT_EQ(ctl->Flush(), CanStatus::kOk);
  EXPECT_EQ(ctl->statistics().datagrams_sent, 1u);
  ctl->Hold();
  for (int i = 0; i < 100; ++i) ASSERT_EQ(ctl->Send(Frame(0x101, static_cast<uint8_t>(i), 1)), CanStatus::kOk);
  ASSERT_EQ(ctl->Flush(), CanStatus::kOk);
  EXPECT_EQ(ctl->statistics().datagrams_sent, 3u);
  EXPECT_EQ(ctl->statistics().sent, 164u);
  std::vector<CanFrame> got;
  while (twin->WaitInput(0.05))
    while (twin->Receive(&f) == CanStatus::kOk) got.push_back(f);
  ASSERT_EQ(got.size(), 164u);
  for (int i = 0; i < 164; ++i)
    EXPECT_TRUE(SamePayload(got[i], i < 64 ? Frame(0x100, static_cast<uint8_t>(i))
                                           : Frame(0x101, static_cast<uint8_t>(i - 64), 1))) << i;
  EXPECT_EQ(twin->statistics().received, 164u);
  EXPECT_EQ(twin->statistics().malformed + twin->statistics().foreign, 0u);
  EXPECT_TRUE(twin->PeerAlive());
  ctl.reset();
  EXPECT_FALSE(twin->PeerAlive());
  twin.reset();
  EXPECT_FALSE(Exists(name));  // removed by the last end to leave
}

// A full mailbox (kShmSlots datagrams unread): a send waits kSendWait for a live peer, then is refused
// (kQueueFull, counted); nothing published is lost or reordered. A dead peer's full mailbox refuses at
// once (peer_absent).
TEST(ShmLink, FullMailboxRefusesAfterItsWaitAndLosesNothing) {
  const BusAddress a = ParseBusAddress("shm:" + Name());
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  auto ctl = CanLink::Open(a, LinkEnd::kController);
  for (uint32_t i = 0; i < kShmSlots; ++i) ASSERT_EQ(twin->Send(Frame(0x080, static_cast<uint8_t>(i))), CanStatus::kOk) << i;
  double t0 = MonotonicSeconds();
  EXPECT_EQ(twin->Send(Frame(0x080, 0xFF)), CanStatus::kQueueFull);
  EXPECT_GE(MonotonicSeconds() - t0, 0.1);
  EXPECT_EQ(twin->statistics().send_failures, 1u);
  CanFrame f;
  for (uint32_t i = 0; i < kShmSlots; ++i) {
    ASSERT_EQ(ctl->Receive(&f), CanStatus::kOk) << i;
    EXPECT_EQ(f.data[0], i);
  }
  EXPECT_EQ(ctl->Receive(&f), CanStatus::kNoFrame);
  for (uint32_t i = 0; i < kShmSlots; ++i) ASSERT_EQ(twin->Send(Frame(0x080, 1)), CanStatus::kOk);
  ctl.reset();
  t0 = MonotonicSeconds();
  EXPECT_EQ(twin->Send(Frame(0x080, 2)), CanStatus::kError);
  EXPECT_LT(MonotonicSeconds() - t0, 0.05);
  EXPECT_EQ(twin->statistics().peer_absent, 1u);
}

// A wait sleeps (on the futex) for its whole timeout whatever the spin, wakes within a fraction of it
// when the peer sends meanwhile (from another thread), and sees a dead peer as gone.
TEST(ShmLink, WaitSleepsForItsTimeoutWakesOnADatagramAndSeesADeadPeer) {
  const BusAddress a = ParseBusAddress("shm:" + Name());
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  for (const double spin : {0.0, 50e-6}) {
    twin->SetSpin(spin);
    const double t0 = MonotonicSeconds();
    EXPECT_FALSE(twin->WaitInput(0.03)) << spin;
    const double waited = MonotonicSeconds() - t0;
    EXPECT_GE(waited, 0.03) << spin;
    EXPECT_LT(waited, 0.5) << spin;
  }
  {
    auto ctl = CanLink::Open(a, LinkEnd::kController);
    twin->SetSpin(0);  // asleep on the futex when the datagram comes
    std::thread peer([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
      ctl->Send(Frame(0x100, 9));
    });
    const double t0 = MonotonicSeconds();
    EXPECT_TRUE(twin->WaitInput(5.0));
    EXPECT_LT(MonotonicSeconds() - t0, 1.0);
    peer.join();
    CanFrame f;
    ASSERT_EQ(twin->Receive(&f), CanStatus::kOk);
    EXPECT_TRUE(SamePayload(f, Frame(0x100, 9)));
  }
  const pid_t child = LiveEndInChild(a, LinkEnd::kController, 0);
  EXPECT_TRUE(twin->PeerAlive());
  Kill(child);  // SIGKILL: no destructor ran
  EXPECT_FALSE(twin->PeerAlive());
}

// An end held by a live process is refused; a segment that both ends' processes left (killed) is
// replaced: the new one carries nothing of the old. A segment of another layout, or readable by others,
// is refused and left alone.
TEST(ShmLink, LiveEndRefusedStaleSegmentReplacedForeignSegmentLeftAlone) {
  const std::string name = Name();
  const BusAddress a = ParseBusAddress("shm:" + name);
  const pid_t twin_child = LiveEndInChild(a, LinkEnd::kTwin, 3);  // 3 datagrams for a controller
  try {
    CanLink::Open(a, LinkEnd::kTwin);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/shm/" + name + ": its twin end is in use by another process"),
              std::string::npos) << e.what();
  }
  Kill(twin_child);
  ASSERT_TRUE(Exists(name));  // stale: left by a killed process
  struct stat before{}, after{};
  ASSERT_EQ(::stat(("/dev/shm/" + name).c_str(), &before), 0);
  {
    auto ctl = CanLink::Open(a, LinkEnd::kController);
    ASSERT_EQ(::stat(("/dev/shm/" + name).c_str(), &after), 0);
    EXPECT_NE(before.st_ino, after.st_ino);
    CanFrame f;
    EXPECT_FALSE(ctl->WaitInput(0.01));
    EXPECT_EQ(ctl->Receive(&f), CanStatus::kNoFrame);
  }
  EXPECT_FALSE(Exists(name));

  // A twin restarted under a live controller joins its segment; what the controller sent to the dead
  // twin is not delivered to the new one.
  auto ctl = CanLink::Open(a, LinkEnd::kController);
  const pid_t dead = LiveEndInChild(a, LinkEnd::kTwin, 1);
  ASSERT_EQ(ctl->Send(Frame(0x010, 1)), CanStatus::kOk);  // for the twin that dies
  Kill(dead);
  CanFrame f;
  ASSERT_TRUE(ctl->WaitInput(1.0));
  ASSERT_EQ(ctl->Receive(&f), CanStatus::kOk);  // what the dead twin had sent stays for the controller
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  EXPECT_EQ(twin->Receive(&f), CanStatus::kNoFrame);
  ASSERT_EQ(ctl->Send(Frame(0x010, 2)), CanStatus::kOk);
  ASSERT_EQ(twin->Receive(&f), CanStatus::kOk);
  EXPECT_EQ(f.data[0], 2);

  for (const mode_t mode : {0600, 0644}) {
    const std::string other = Name();
    const int fd = ::shm_open(("/" + other).c_str(), O_RDWR | O_CREAT | O_EXCL, mode);
    ASSERT_GE(fd, 0);
    ::fchmod(fd, mode);
    ASSERT_EQ(::write(fd, "not a link", 10), 10);
    ::close(fd);
    try {
      CanLink::Open(ParseBusAddress("shm:" + other), LinkEnd::kTwin);
      ADD_FAILURE() << mode;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(mode == 0600 ? "is not a link segment of this version (10 bytes"
                                                        : "is accessible to other users (mode 644"),
                std::string::npos) << e.what();
    }
    EXPECT_TRUE(Exists(other));
    ::shm_unlink(("/" + other).c_str());
  }
}

// What the twin reads is checked as a socket's datagrams are: a length that is not a whole number of
// 1..64 frames, and frames that are not an 11-bit data frame, are dropped and counted (malformed).
TEST(ShmLink, MalformedDatagramsAreDroppedAndCounted) {
  const BusAddress a = ParseBusAddress("shm:" + Name());
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  auto raw = ShmLink::Open(a, LinkEnd::kController);
  can_frame cf[2]{};
  cf[0].can_id = 0x100 | CAN_EFF_FLAG;
  cf[0].can_dlc = 1;
  cf[1].can_id = 0x101;
  cf[1].can_dlc = 2;
  ASSERT_TRUE(raw->TryPut(cf, 20));          // not a whole number of frames
  ASSERT_TRUE(raw->TryPut(cf, 0));           // empty
  ASSERT_TRUE(raw->TryPut(cf, sizeof cf));   // an extended frame and a good one
  CanFrame f;
  ASSERT_EQ(twin->Receive(&f), CanStatus::kOk);
  EXPECT_EQ(f.id, 0x101);
  EXPECT_EQ(twin->Receive(&f), CanStatus::kNoFrame);
  EXPECT_EQ(twin->statistics().malformed, 3u);
  EXPECT_EQ(twin->statistics().foreign, 0u);
}

}  // namespace
}  // namespace exotwin
