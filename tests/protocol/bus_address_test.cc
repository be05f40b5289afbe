#include "protocol/bus_address.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace exotwin {
namespace {

TEST(BusAddress, ParsesTheFourSchemes) {
  const BusAddress u = ParseBusAddress("unix:/tmp/x.sock");
  EXPECT_EQ(u.kind, BusKind::kUnix);
  EXPECT_EQ(u.LocalName(LinkEnd::kTwin), "/tmp/x.sock");
  EXPECT_EQ(u.LocalName(LinkEnd::kController), "/tmp/x.sock.ctl");
  EXPECT_EQ(u.PeerName(LinkEnd::kController), "/tmp/x.sock");

  const BusAddress d = ParseBusAddress("udp:localhost:5000");
  EXPECT_EQ(d.kind, BusKind::kUdp);
  EXPECT_EQ(d.host, "127.0.0.1");
  EXPECT_TRUE(d.loopback());
  EXPECT_EQ(d.LocalName(LinkEnd::kTwin), "127.0.0.1:5000");
  EXPECT_EQ(d.LocalName(LinkEnd::kController), "127.0.0.1:5001");
  EXPECT_FALSE(ParseBusAddress("udp:192.168.1.2:5000").loopback());

  const BusAddress c = ParseBusAddress("can:can0");
  EXPECT_EQ(c.kind, BusKind::kSocketCan);
  EXPECT_EQ(c.interface, "can0");

  const BusAddress m = ParseBusAddress("shm:exotwin-1_a.b");
  EXPECT_EQ(m.kind, BusKind::kShm);
  EXPECT_EQ(m.path, "exotwin-1_a.b");
  EXPECT_EQ(m.LocalName(LinkEnd::kTwin), "/dev/shm/exotwin-1_a.b (twin end)");
  EXPECT_EQ(m.PeerName(LinkEnd::kTwin), "/dev/shm/exotwin-1_a.b (controller end)");
}

TEST(BusAddress, BadAddressesNameTheAddress) {
  for (const char* bad : {"", "x", "tcp:1", "unix:", "udp:127.0.0.1", "udp:127.0.0.1:0", "udp:127.0.0.1:65535",
                          "udp:no.such.host:5", "udp:127.0.0.1:12x", "can:", "can:abcdefghijklmnopq", "shm:", "shm:a/b", "shm:.hidden", "shm:a b",
                          "shm:/x"}) {
    try {
      ParseBusAddress(bad);
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace exotwin
