// The twin's end of the controller link (runner/remote_controller.h): what reaches the virtual bus is
// only the configured controller's controller frames; a second, unconfigured peer, a datagram of the wrong
// length and a frame of a wrong identifier are dropped, counted and (wrong identifier) recorded.
#include "runner/remote_controller.h"

#include <linux/can.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "protocol/link_frames.h"
#include "protocol/messages.h"
#include "tests/controller/fake_can_bus.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

// A raw Unix datagram socket bound at `path` that sends arbitrary bytes to `to`.
class RawPeer {
 public:
  RawPeer(const std::string& path, const std::string& to) : path_(path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM, 0);
    sockaddr_un a = Address(path);
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    to_ = Address(to);
  }
  ~RawPeer() {
    ::close(fd_);
    ::unlink(path_.c_str());
  }
  void SendBytes(const void* p, size_t n) {
    EXPECT_EQ(::sendto(fd_, p, n, 0, reinterpret_cast<sockaddr*>(&to_), sizeof to_), static_cast<ssize_t>(n));
  }
  void Send(const CanFrame& f) {
    can_frame cf{};
    cf.can_id = f.id;
    cf.can_dlc = f.dlc;
    std::memcpy(cf.data, f.data.data(), 8);
    SendBytes(&cf, sizeof cf);
  }

 private:
  static sockaddr_un Address(const std::string& p) {
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, p.c_str(), sizeof a.sun_path - 1);
    return a;
  }
  int fd_ = -1;
  std::string path_;
  sockaddr_un to_{};
};

msg::JointCommand Command(msg::Joint j, double torque) {
  msg::JointCommand c;
  c.joint = j;
  c.torque = torque;
  c.enable = true;
  return c;
}

TEST(RemoteController, OnlyTheConfiguredControllersFramesReachTheBus) {
  testing::ScopedTempDir dir("remote");
  const BusAddress a = ParseBusAddress("unix:" + dir.path() + "/bus");
  auto link = CanLink::Open(a, LinkEnd::kTwin);
  RawPeer controller(a.LocalName(LinkEnd::kController), a.path);
  RawPeer intruder(dir.path() + "/intruder", a.path);
  testing::FakeCanBus ep;
  std::vector<std::string> events;
  RemoteController remote(link.get(), ServeClock::kLockstep, 1e-3, 2.0);
  controller.Send(link::ReadyFrame(0, remote.next_sequence()));
  remote.BeginTrial(0, &ep, &events);
  ASSERT_TRUE(remote.deterministic());

  const double t = 0.0005;
  intruder.Send(msg::Encode(Command(msg::Joint::kKnee, 99)));      // not the configured peer
  controller.SendBytes("\x01\x01\x00\x00\x02", 5);                   // wrong length
  CanFrame odd;
  odd.id = 0x555;
  odd.dlc = 1;
  controller.Send(odd);                                              // not a controller frame
  controller.Send(msg::Encode(Command(msg::Joint::kHip, 1.5)));      // the one command
  controller.Send(link::DoubleFrame(link::kIdTelemetryBase + link::kTelRefQHip, 0.25));
  controller.Send(link::DoubleFrame(link::kIdCycleDone, t));
  remote.Tick(t);

  ASSERT_EQ(ep.sent().size(), 1u);
  msg::JointCommand c;
  ASSERT_TRUE(msg::Decode(ep.sent()[0], &c));
  EXPECT_EQ(c.joint, msg::Joint::kHip);
  EXPECT_DOUBLE_EQ(c.torque, 1.5);
  EXPECT_EQ(remote.telemetry().ref[0].q, 0.25);
  EXPECT_TRUE(remote.deterministic());
  std::map<std::string, double> m;
  remote.AddMetrics(&m);
  EXPECT_EQ(m["link_frames_foreign"], 1.0);
  EXPECT_EQ(m["link_frames_malformed"], 1.0);
  EXPECT_EQ(m["link_frames_unexpected"], 1.0);
  EXPECT_EQ(m["link_deterministic"], 1.0);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NE(events[0].find("link_frame_refused id 1365"), std::string::npos) << events[0];
}

TEST(RemoteController, NoAnswerWithinTheTimeoutLosesTheController) {
  testing::ScopedTempDir dir("remote");
  const BusAddress a = ParseBusAddress("unix:" + dir.path() + "/bus");
  auto link = CanLink::Open(a, LinkEnd::kTwin);
  RawPeer controller(a.LocalName(LinkEnd::kController), a.path);  // alive but silent after its ready frame
  testing::FakeCanBus ep;
  std::vector<std::string> events;
  RemoteController remote(link.get(), ServeClock::kLockstep, 1e-3, 0.2);
  controller.Send(link::ReadyFrame(0, remote.next_sequence()));
  remote.BeginTrial(0, &ep, &events);
  remote.Tick(0.0005);
  remote.Tick(0.0015);  // no wait once lost
  EXPECT_FALSE(remote.deterministic());
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NE(events[0].find("t=0.0005 controller_lost"), std::string::npos) << events[0];
  EXPECT_TRUE(ep.sent().empty());
  std::map<std::string, double> m;
  remote.AddMetrics(&m);
  EXPECT_EQ(m["link_controller_lost_s"], 0.0005);
}

// LinkFaults: a command crosses the link delay_s later on the simulated clock (put on the bus at the
// first tick at or after its due time); with loss 1 every device frame is lost, and counted.
TEST(RemoteController, LinkFaultsDelayCommandsOnTheSimulatedClockAndLoseThemCounted) {
  for (const double loss : {0.0, 1.0}) {
    testing::ScopedTempDir dir("remote");
    const BusAddress a = ParseBusAddress("unix:" + dir.path() + "/bus");
    auto link = CanLink::Open(a, LinkEnd::kTwin);
    RawPeer controller(a.LocalName(LinkEnd::kController), a.path);
    testing::FakeCanBus ep;
    std::vector<std::string> events;
    LinkFaults faults;
    faults.delay_s = 2.5e-3;
    faults.loss = loss;
    RemoteController remote(link.get(), ServeClock::kLockstep, 1e-3, 2.0, faults);
    controller.Send(link::ReadyFrame(0, remote.next_sequence()));
    remote.BeginTrial(0, &ep, &events);
    std::vector<size_t> on_bus;
    for (int k = 0; k < 5; ++k) {
      const double t = 0.0005 + 1e-3 * k;
      ep.AdvanceTo(t);
      if (k == 0) controller.Send(msg::Encode(Command(msg::Joint::kHip, 1.5)));
      controller.Send(link::DoubleFrame(link::kIdCycleDone, t));
      remote.Tick(t);
      on_bus.push_back(ep.sent().size());
    }
    std::map<std::string, double> m;
    remote.AddMetrics(&m);
    EXPECT_EQ(m["link_deterministic"], 1.0);
    if (loss == 0) {  // sent at 0.5 ms, due at 3.0 ms: on the bus at the tick of 3.5 ms
      EXPECT_EQ(on_bus, (std::vector<size_t>{0, 0, 0, 1, 1}));
      ASSERT_EQ(ep.sent().size(), 1u);
      EXPECT_EQ(ep.sent()[0].t, 0.0035);
      EXPECT_EQ(m["link_frames_dropped"], 0.0);
    } else {
      EXPECT_EQ(on_bus, (std::vector<size_t>{0, 0, 0, 0, 0}));
      EXPECT_EQ(m["link_frames_dropped"], 1.0);
    }
  }
  EXPECT_THROW(LinkFaultsOf(-1, 0, 0, 1), InputError);
  EXPECT_THROW(LinkFaultsOf(0, 0, 1.01, 1), InputError);
  EXPECT_THROW(LinkFaultsOf(0, std::nan(""), 0, 1), InputError);
}

}  // namespace
}  // namespace exotwin
