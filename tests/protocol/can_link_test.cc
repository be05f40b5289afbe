#include "protocol/can_link.h"

#include <arpa/inet.h>
#include <linux/can.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/realtime.h"
#include "protocol/link_frames.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

CanFrame Frame(uint16_t id, uint8_t b0) {
  CanFrame f;
  f.id = id;
  f.dlc = 2;
  f.data[0] = b0;
  f.data[1] = 0x5A;
  return f;
}

// Waits up to 1 s for a frame on `link`.
CanStatus ReceiveWait(CanLink& link, CanFrame* out) {
  for (int i = 0; i < 100; ++i) {
    const CanStatus st = link.Receive(out);
    if (st != CanStatus::kNoFrame) return st;
    link.WaitInput(0.01);
  }
  return CanStatus::kNoFrame;
}

// A raw Unix datagram socket bound at `path` sending `bytes` to `to`.
void SendRawUnix(const std::string& path, const std::string& to, const void* bytes, size_t n) {
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un a{}, b{};
  a.sun_family = b.sun_family = AF_UNIX;
  std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
  std::strncpy(b.sun_path, to.c_str(), sizeof b.sun_path - 1);
  if (!path.empty()) {
    ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  }
  ASSERT_EQ(::sendto(fd, bytes, n, 0, reinterpret_cast<sockaddr*>(&b), sizeof b), static_cast<ssize_t>(n));
  ::close(fd);
  if (!path.empty()) ::unlink(path.c_str());
}

TEST(CanLink, UnixFramesBothWaysSocketsOwnerOnly) {
  testing::ScopedTempDir dir("canlink");
  const BusAddress a = ParseBusAddress("unix:" + dir.path() + "/bus");
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  auto ctl = CanLink::Open(a, LinkEnd::kController);
  for (const std::string& p : {dir.path() + "/bus", dir.path() + "/bus.ctl"}) {
    struct stat st{};
    ASSERT_EQ(::stat(p.c_str(), &st), 0) << p;
    EXPECT_EQ(st.st_mode & 0777, 0600u) << p;
  }
  ASSERT_EQ(twin->Send(Frame(0x180, 1)), CanStatus::kOk);
  ASSERT_EQ(twin->Send(link::DoubleFrame(link::kIdSync, 0.0125)), CanStatus::kOk);
  CanFrame f;
  ASSERT_EQ(ReceiveWait(*ctl, &f), CanStatus::kOk);
  EXPECT_TRUE(SamePayload(f, Frame(0x180, 1)));
  ASSERT_EQ(ReceiveWait(*ctl, &f), CanStatus::kOk);
  double t = 0;
  ASSERT_TRUE(link::FrameDouble(f, &t));
  EXPECT_EQ(t, 0.0125);
  ASSERT_EQ(ctl->Send(Frame(0x100, 7)), CanStatus::kOk);
  ASSERT_EQ(ReceiveWait(*twin, &f), CanStatus::kOk);
  EXPECT_TRUE(SamePayload(f, Frame(0x100, 7)));
  EXPECT_EQ(twin->Receive(&f), CanStatus::kNoFrame);
}

TEST(CanLink, UnconfiguredPeerAndMalformedDatagramsAreDroppedAndCounted) {
  testing::ScopedTempDir dir("canlink");
  const BusAddress a = ParseBusAddress("unix:" + dir.path() + "/bus");
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  can_frame cf{};
  cf.can_id = 0x100;
  cf.can_dlc = 4;
  SendRawUnix(dir.path() + "/intruder", dir.path() + "/bus", &cf, sizeof cf);  // a second peer
  SendRawUnix("", dir.path() + "/bus", &cf, sizeof cf);                         // unnamed sender
  {
    auto ctl = CanLink::Open(a, LinkEnd::kController);
    ctl.reset();  // frees the controller's path for raw senders below
  }
  SendRawUnix(dir.path() + "/bus.ctl", dir.path() + "/bus", &cf, 15);  // wrong length, from the peer
  can_frame eff = cf;
  eff.can_id = 0x100 | CAN_EFF_FLAG;
  SendRawUnix(dir.path() + "/bus.ctl", dir.path() + "/bus", &eff, sizeof eff);  // not an 11-bit frame
  can_frame dlc = cf;
  dlc.can_dlc = 9;
  SendRawUnix(dir.path() + "/bus.ctl", dir.path() + "/bus", &dlc, sizeof dlc);
  SendRawUnix(dir.path() + "/bus.ctl", dir.path() + "/bus", &cf, sizeof cf);  // the one good frame
  CanFrame f;
  ASSERT_EQ(ReceiveWait(*twin, &f), CanStatus::kOk);
  EXPECT_EQ(f.id, 0x100);
  EXPECT_EQ(f.dlc, 4);
  EXPECT_EQ(twin->Receive(&f), CanStatus::kNoFrame);
  EXPECT_EQ(twin->statistics().foreign, 2u);
  EXPECT_EQ(twin->statistics().malformed, 3u);
  EXPECT_EQ(twin->statistics().received, 1u);
}

// DESIGN.md: a datagram carries 1 to 64 frames; Hold .. Flush sends a cycle's frames as one datagram;
// a datagram of more frames, or not a whole number of them, is malformed as a whole, a bad frame in a
// good datagram alone.
TEST(CanLink, HeldFramesLeaveAsOneDatagramOfUpTo64) {
  testing::ScopedTempDir dir("canlink");
  const BusAddress a = ParseBusAddress("unix:" + dir.path() + "/bus");
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  auto ctl = CanLink::Open(a, LinkEnd::kController);
  ctl->Hold();
  for (int i = 0; i < 70; ++i) ASSERT_EQ(ctl->Send(Frame(0x100, static_cast<uint8_t>(i))), CanStatus::kOk);
  EXPECT_EQ(ctl->statistics().datagrams_sent, 1u);  // 64 frames full: sent; 6 held
  ASSERT_EQ(ctl->Flush(), CanStatus::kOk);
  EXPECT_EQ(ctl->statistics().datagrams_sent, 2u);
  EXPECT_EQ(ctl->statistics().sent, 70u);
  ASSERT_EQ(ctl->Send(Frame(0x101, 0)), CanStatus::kOk);  // not held: a datagram of its own
  EXPECT_EQ(ctl->statistics().datagrams_sent, 3u);
  CanFrame f;
  for (int i = 0; i < 70; ++i) {
    ASSERT_EQ(ReceiveWait(*twin, &f), CanStatus::kOk) << i;
    EXPECT_TRUE(SamePayload(f, Frame(0x100, static_cast<uint8_t>(i)))) << i;
  }
  ASSERT_EQ(ReceiveWait(*twin, &f), CanStatus::kOk);
  EXPECT_EQ(f.id, 0x101);
  ctl.reset();  // raw datagrams from the controller's address
  std::vector<can_frame> frames(65);
  for (can_frame& cf : frames) cf.can_id = 0x100, cf.can_dlc = 1;
  frames[1].can_id |= CAN_EFF_FLAG;
  SendRawUnix(dir.path() + "/bus.ctl", dir.path() + "/bus", frames.data(), 3 * sizeof(can_frame));   // 2 good, 1 bad
  SendRawUnix(dir.path() + "/bus.ctl", dir.path() + "/bus", frames.data(), 65 * sizeof(can_frame));  // too many
  SendRawUnix(dir.path() + "/bus.ctl", dir.path() + "/bus", frames.data(), 2 * sizeof(can_frame) + 1);
  ASSERT_EQ(ReceiveWait(*twin, &f), CanStatus::kOk);
  ASSERT_EQ(ReceiveWait(*twin, &f), CanStatus::kOk);
  EXPECT_EQ(twin->Receive(&f), CanStatus::kNoFrame);  // the other two, queued already, dropped
  EXPECT_EQ(twin->statistics().received, 73u);
  EXPECT_EQ(twin->statistics().malformed, 3u);
}

// A wait blocks in one receive for its whole timeout (not less, whatever the spin), returns at once
// when a datagram is there, and goes on waiting after a foreign datagram (dropped, counted).
TEST(CanLink, WaitBlocksForItsTimeoutAndWakesOnADatagram) {
  testing::ScopedTempDir dir("canlink");
  const BusAddress a = ParseBusAddress("unix:" + dir.path() + "/bus");
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  auto ctl = CanLink::Open(a, LinkEnd::kController);
  for (const double spin : {0.0, 50e-6}) {
    twin->SetSpin(spin);
    double t0 = MonotonicSeconds();
    EXPECT_FALSE(twin->WaitInput(0.03)) << spin;
    const double waited = MonotonicSeconds() - t0;
    EXPECT_GE(waited, 0.03) << spin;
    EXPECT_LT(waited, 0.5) << spin;
    ASSERT_EQ(ctl->Send(Frame(0x100, 3)), CanStatus::kOk);
    t0 = MonotonicSeconds();
    EXPECT_TRUE(twin->WaitInput(5.0)) << spin;
    EXPECT_LT(MonotonicSeconds() - t0, 1.0) << spin;
    EXPECT_EQ(twin->Queued(), 1u);
    CanFrame f;
    ASSERT_EQ(twin->Receive(&f), CanStatus::kOk);
    EXPECT_TRUE(SamePayload(f, Frame(0x100, 3)));
  }
  can_frame cf{};
  cf.can_id = 0x100;
  cf.can_dlc = 1;
  SendRawUnix(dir.path() + "/intruder", dir.path() + "/bus", &cf, sizeof cf);
  const double t0 = MonotonicSeconds();
  EXPECT_FALSE(twin->WaitInput(0.03));
  EXPECT_GE(MonotonicSeconds() - t0, 0.03);
  EXPECT_EQ(twin->statistics().foreign, 1u);
}

// CanLink::SetSpin: a wait that blocks halves the budget; below 1 us the waits block at once, and the
// kSpinProbe-th one spins the whole budget again; a wait answered while spinning restores it. (A wait
// of timeout 0 is a read and leaves the budget alone.)
TEST(CanLink, SpinBudgetHalvesWhenWaitsBlockAndComesBackOnAnAnswer) {
  testing::ScopedTempDir dir("canlink");
  const BusAddress a = ParseBusAddress("unix:" + dir.path() + "/bus");
  auto twin = CanLink::Open(a, LinkEnd::kTwin);
  auto ctl = CanLink::Open(a, LinkEnd::kController);
  EXPECT_EQ(twin->spin_budget(), kDefaultLinkSpin);
  twin->SetSpin(40e-6);
  std::vector<double> budgets;
  for (int i = 0; i < 6; ++i) {
    twin->WaitInput(1e-4);
    budgets.push_back(twin->spin_budget());
  }
  EXPECT_EQ(budgets, (std::vector<double>{20e-6, 10e-6, 5e-6, 2.5e-6, 1.25e-6, 0.0}));
  for (int i = 1; i < CanLink::kSpinProbe - 1; ++i) {
    twin->WaitInput(1e-5);
    ASSERT_EQ(twin->spin_budget(), 0.0) << i;
  }
  twin->WaitInput(1e-5);  // the last one that blocks at once: the next spins again
  EXPECT_EQ(twin->spin_budget(), 40e-6);
  twin->WaitInput(1e-4);
  EXPECT_EQ(twin->spin_budget(), 20e-6);
  ASSERT_EQ(ctl->Send(Frame(0x100, 1)), CanStatus::kOk);  // there before the wait: found while spinning
  EXPECT_TRUE(twin->WaitInput(1.0));
  EXPECT_EQ(twin->spin_budget(), 40e-6);
  twin->SetSpin(0);
  EXPECT_EQ(twin->spin_budget(), 0.0);
}

TEST(CanLink, PeerAbsentIsAStatusNotACrash) {
  testing::ScopedTempDir dir("canlink");
  auto twin = CanLink::Open(ParseBusAddress("unix:" + dir.path() + "/bus"), LinkEnd::kTwin);
  EXPECT_EQ(twin->Send(Frame(0x80, 0)), CanStatus::kError);
  EXPECT_EQ(twin->statistics().peer_absent, 1u);
  EXPECT_FALSE(twin->WaitInput(0.01));
}

TEST(CanLink, BadPlacesExitWithTheAddressNamed) {
  testing::ScopedTempDir dir("canlink");
  try {
    CanLink::Open(ParseBusAddress("unix:" + dir.path() + "/no/such/dir/bus"), LinkEnd::kTwin);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/dir/bus"), std::string::npos) << e.what();
  }
  std::ofstream(dir.path() + "/file") << "x";
  EXPECT_THROW(CanLink::Open(ParseBusAddress("unix:" + dir.path() + "/file"), LinkEnd::kTwin), InputError);
  auto live = CanLink::Open(ParseBusAddress("unix:" + dir.path() + "/bus"), LinkEnd::kTwin);
  try {
    CanLink::Open(ParseBusAddress("unix:" + dir.path() + "/bus"), LinkEnd::kTwin);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("in use"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CanLink::Open(ParseBusAddress("can:nosuchcan9"), LinkEnd::kTwin), InputError);
}

TEST(CanLink, UdpOnLoopbackAndPortInUse) {
  // Port 0 is not allowed in ADDR: find a free pair by trying a few.
  std::unique_ptr<CanLink> twin, ctl;
  BusAddress a;
  for (int port = 47000; port < 47400 && !ctl; port += 2) {
    a = ParseBusAddress("udp:127.0.0.1:" + std::to_string(port));
    try {
      twin = CanLink::Open(a, LinkEnd::kTwin);
      ctl = CanLink::Open(a, LinkEnd::kController);
    } catch (const InputError&) {
      twin.reset();
    }
  }
  ASSERT_TRUE(ctl);
  ASSERT_EQ(ctl->Send(Frame(0x101, 3)), CanStatus::kOk);
  CanFrame f;
  ASSERT_EQ(ReceiveWait(*twin, &f), CanStatus::kOk);
  EXPECT_TRUE(SamePayload(f, Frame(0x101, 3)));
  try {
    CanLink::Open(a, LinkEnd::kTwin);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("port in use"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(a.text), std::string::npos) << e.what();
  }
  // A sender on another port is foreign.
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(a.port);
  ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  can_frame cf{};
  cf.can_id = 0x100;
  cf.can_dlc = 2;
  ASSERT_EQ(::sendto(fd, &cf, sizeof cf, 0, reinterpret_cast<sockaddr*>(&to), sizeof to), 16);
  ::close(fd);
  twin->WaitInput(0.5);
  EXPECT_EQ(twin->Receive(&f), CanStatus::kNoFrame);
  EXPECT_EQ(twin->statistics().foreign, 1u);
}

}  // namespace
}  // namespace exotwin
