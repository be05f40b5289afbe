// The virtual CAN bus: timing from hand-counted frames, arbitration, queues, filters, latency and
// jitter, faults (drops, error frames and fault confinement, spikes, bus-off), bus load, determinism.
#include "hwsim/virtual_can_bus.h"

#include <gtest/gtest.h>

#include <cmath>

#include "protocol/can_bits.h"
#include "protocol/candump.h"
#include "protocol/messages.h"
#include "tests/temp_dir.h"

namespace exotwin::hwsim {
namespace {

constexpr double kUs = 1e-6;

CanFrame Frame(uint16_t id, std::vector<uint8_t> bytes = {}) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<uint8_t>(bytes.size());
  for (size_t i = 0; i < bytes.size(); ++i) f.data[i] = bytes[i];
  return f;
}

std::vector<CanFrame> Drain(CanBus* ep) {
  std::vector<CanFrame> out;
  CanFrame f;
  for (CanStatus s; (s = ep->Receive(&f)) != CanStatus::kNoFrame;) out.push_back(f);
  return out;
}

TEST(VirtualCanBus, FrameTimingFromHandCountedBits) {
  // ID 0x000 without data: 53 bits (34 stuffed-region zeros + 6 stuff + 10 trailer + 3 IFS, see
  // tests/protocol/can_bits_test.cc). At 1 Mbit/s the receiver has it at the end of EOF = 50 us and
  // the bus is free at 53 us; the next frame (ID 0x555, one byte 0x55: 57 bits) ends EOF at 53 + 54.
  VirtualCanBus bus;
  auto* tx = bus.AddNode("tx");
  auto* rx = bus.AddNode("rx");
  ASSERT_EQ(tx->Send(Frame(0x000)), CanStatus::kOk);
  ASSERT_EQ(tx->Send(Frame(0x555, {0x55})), CanStatus::kOk);
  bus.AdvanceTo(49.9 * kUs);
  CanFrame f;
  EXPECT_EQ(rx->Receive(&f), CanStatus::kNoFrame);
  bus.AdvanceTo(1e-3);
  const auto got = Drain(rx);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_NEAR(got[0].t, 50 * kUs, 1e-12);
  EXPECT_NEAR(got[1].t, (53 + 54) * kUs, 1e-12);
  EXPECT_EQ(bus.Statistics().bits, 53u + 57u);
  EXPECT_NEAR(VirtualCanBus::FrameDuration(Frame(0x000), 500e3), 106 * kUs, 1e-12);
  // At 500 kbit/s everything takes twice as long.
  VirtualCanBus slow(VirtualCanBusConfig{500e3});
  auto* stx = slow.AddNode("tx");
  auto* srx = slow.AddNode("rx");
  stx->Send(Frame(0x000));
  slow.AdvanceTo(1e-3);
  ASSERT_EQ(srx->Receive(&f), CanStatus::kOk);
  EXPECT_NEAR(f.t, 100 * kUs, 1e-12);
}

TEST(VirtualCanBus, LowestIdWinsArbitration) {
  VirtualCanBus bus;
  auto* emg = bus.AddNode("emg");
  auto* joint = bus.AddNode("joint");
  auto* ctrl = bus.AddNode("ctrl");
  auto* mon = bus.AddNode("monitor");
  emg->Send(Frame(0x200, {1}));
  joint->Send(Frame(0x181, {2}));
  ctrl->Send(Frame(0x010, {3}));
  bus.AdvanceTo(1e-3);
  const auto got = Drain(mon);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].id, 0x010);
  EXPECT_EQ(got[1].id, 0x181);
  EXPECT_EQ(got[2].id, 0x200);
  EXPECT_LT(got[0].t, got[1].t);
  EXPECT_LT(got[1].t, got[2].t);
}

TEST(VirtualCanBus, NoPreemptionAndLateHighPriorityOvertakesWaitingFrame) {
  // t = 0: A queues 0x300, C queues 0x400 -> A wins. At 10 us (A on the wire) B queues 0x050.
  // When A ends, B's 0x050 wins over C's 0x400 although C waited longer.
  VirtualCanBus bus;
  auto* a = bus.AddNode("A");
  auto* b = bus.AddNode("B");
  auto* c = bus.AddNode("C");
  auto* mon = bus.AddNode("monitor");
  a->Send(Frame(0x300, {0, 0, 0, 0}));
  c->Send(Frame(0x400, {0, 0, 0, 0}));
  bus.AdvanceTo(10 * kUs);
  b->Send(Frame(0x050));
  bus.AdvanceTo(1e-3);
  const auto got = Drain(mon);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].id, 0x300);
  EXPECT_EQ(got[1].id, 0x050);
  EXPECT_EQ(got[2].id, 0x400);
  // Back to back: each frame starts when the previous one (with its IFS) ends.
  const double d0 = VirtualCanBus::FrameDuration(Frame(0x300, {0, 0, 0, 0}), 1e6);
  const double d1 = VirtualCanBus::FrameDuration(Frame(0x050), 1e6);
  EXPECT_NEAR(got[1].t, d0 + d1 - 3 * kUs, 1e-12);
}

TEST(VirtualCanBus, TxQueueLimitAndFilters) {
  VirtualCanBusConfig cfg;
  cfg.tx_queue_limit = 2;
  VirtualCanBus bus(cfg);
  auto* tx = bus.AddNode("tx");
  auto* only_100 = bus.AddNode("f", {0x100});
  auto* all = bus.AddNode("all");
  EXPECT_EQ(tx->Send(Frame(0x100)), CanStatus::kOk);
  EXPECT_EQ(tx->Send(Frame(0x101)), CanStatus::kOk);
  EXPECT_EQ(tx->Send(Frame(0x102)), CanStatus::kQueueFull);
  EXPECT_EQ(tx->Send(Frame(0x800)), CanStatus::kError);
  CanFrame bad = Frame(0x100);
  bad.dlc = 9;
  EXPECT_EQ(tx->Send(bad), CanStatus::kError);
  EXPECT_EQ(bus.Statistics().queue_full, 1u);
  bus.AdvanceTo(1e-3);
  EXPECT_EQ(Drain(only_100).size(), 1u);
  EXPECT_EQ(Drain(all).size(), 2u);
  EXPECT_EQ(Drain(tx).size(), 0u);  // no loopback to the sender
  EXPECT_EQ(tx->Send(Frame(0x102)), CanStatus::kOk);  // queue drained
}

TEST(VirtualCanBus, LatencyJitterAndOrder) {
  VirtualCanBusConfig cfg;
  cfg.latency = 100 * kUs;
  cfg.jitter = 50 * kUs;
  VirtualCanBus bus(cfg);
  auto* tx = bus.AddNode("tx");
  auto* rx = bus.AddNode("rx");
  double min_delay = 1, max_delay = 0, last = -1;
  const double eof = (53 - 3) * kUs;  // ID 0x000 DLC 0, sent at the start of each 1 ms period
  for (int k = 0; k < 500; ++k) {
    tx->Send(Frame(0x000));
    bus.AdvanceTo((k + 1) * 1e-3);
    for (const CanFrame& f : Drain(rx)) {
      const double delay = f.t - (k * 1e-3 + eof);
      min_delay = std::min(min_delay, delay);
      max_delay = std::max(max_delay, delay);
      EXPECT_GE(f.t, last);
      last = f.t;
    }
  }
  EXPECT_GE(min_delay, 100 * kUs - 1e-12);
  EXPECT_LT(max_delay, 150 * kUs);
  EXPECT_GT(max_delay - min_delay, 40 * kUs);  // the jitter is really there
}

TEST(VirtualCanBus, DropProbability) {
  VirtualCanBusConfig cfg;
  cfg.drop_probability = 0.3;
  cfg.seed = 9;
  VirtualCanBus bus(cfg);
  auto* tx = bus.AddNode("tx");
  auto* rx = bus.AddNode("rx");
  int got = 0;
  const int n = 4000;
  for (int k = 0; k < n; ++k) {
    tx->Send(Frame(0x123, {uint8_t(k)}));
    bus.AdvanceTo((k + 1) * 1e-4);
    got += static_cast<int>(Drain(rx).size());
  }
  // Binomial(4000, 0.7): mean 2800, sd 29; +-5 sd.
  EXPECT_NEAR(got, 2800, 145);
  EXPECT_EQ(bus.Statistics().drops, static_cast<uint64_t>(n - got));
  EXPECT_EQ(bus.Statistics().frames, static_cast<uint64_t>(n));  // the bus itself carried every frame
}

TEST(VirtualCanBus, CorruptionErrorFramesAndBusOff) {
  // Every transmission destroyed: the transmitter's TEC rises by 8 per attempt (ISO 11898-1 rule 3),
  // error passive at 128 (16 errors), bus-off above 255 (32 errors); each other node's REC by 1.
  VirtualCanBusConfig cfg;
  cfg.corrupt_probability = 1.0;
  VirtualCanBus bus(cfg);
  auto* tx = bus.AddNode("tx");
  auto* rx = bus.AddNode("rx");
  ASSERT_EQ(tx->Send(Frame(0x000)), CanStatus::kOk);
  // Each attempt: 40 stuffed bits + CRC delim + ACK 2 + error flag 6 + error delimiter 8 + IFS 3 = 60.
  bus.AdvanceTo(15 * 60 * kUs + 1 * kUs);  // 16 attempts started
  EXPECT_EQ(tx->tec(), 128);
  EXPECT_EQ(tx->state(), CanNodeState::kErrorPassive);
  bus.AdvanceTo(1.0);
  EXPECT_EQ(tx->state(), CanNodeState::kBusOff);
  EXPECT_EQ(bus.Statistics().error_frames, 32u);
  EXPECT_EQ(bus.Statistics().frames, 0u);
  EXPECT_EQ(bus.Statistics().bits, 32u * 60u);
  EXPECT_EQ(rx->rec(), 32);
  EXPECT_EQ(tx->Send(Frame(0x001)), CanStatus::kBusOff);
  const auto got = Drain(rx);
  ASSERT_EQ(got.size(), 32u);
  for (const CanFrame& f : got) EXPECT_TRUE(f.error);
  CanFrame f;
  EXPECT_EQ(Drain(tx).size(), 32u);  // the transmitter sees the error frames too
  EXPECT_EQ(rx->Receive(&f), CanStatus::kNoFrame);
  // Recovery, with healthy wiring now: transmissions succeed again, REC of the receiver decreases.
  bus.config().corrupt_probability = 0;
  tx->RecoverBusOff();
  EXPECT_EQ(tx->state(), CanNodeState::kErrorActive);
  ASSERT_EQ(tx->Send(Frame(0x001)), CanStatus::kOk);
  bus.AdvanceTo(2.0);
  ASSERT_EQ(rx->Receive(&f), CanStatus::kOk);
  EXPECT_EQ(f.id, 0x001);
  EXPECT_EQ(rx->rec(), 31);
}

TEST(VirtualCanBus, ErrorFramesCanBeHiddenFromReceivers) {
  VirtualCanBusConfig cfg;
  cfg.corrupt_probability = 0.5;
  cfg.deliver_error_frames = false;
  VirtualCanBus bus(cfg);
  auto* tx = bus.AddNode("tx");
  auto* rx = bus.AddNode("rx");
  for (int k = 0; k < 10; ++k) tx->Send(Frame(0x100, {uint8_t(k)}));
  bus.AdvanceTo(0.1);
  const auto got = Drain(rx);
  ASSERT_EQ(got.size(), 10u);  // automatic retransmission: every frame arrives, in order
  for (int k = 0; k < 10; ++k) {
    EXPECT_FALSE(got[k].error);
    EXPECT_EQ(got[k].data[0], k);
  }
  EXPECT_GT(bus.Statistics().error_frames, 0u);
}

TEST(VirtualCanBus, DelaySpikes) {
  VirtualCanBusConfig cfg;
  cfg.spike_probability = 1.0;
  cfg.spike_delay = 2e-3;
  VirtualCanBus bus(cfg);
  auto* tx = bus.AddNode("tx");
  auto* rx = bus.AddNode("rx");
  tx->Send(Frame(0x000));
  bus.AdvanceTo(2e-3);
  CanFrame f;
  EXPECT_EQ(rx->Receive(&f), CanStatus::kNoFrame);
  bus.AdvanceTo(3e-3);
  ASSERT_EQ(rx->Receive(&f), CanStatus::kOk);
  EXPECT_NEAR(f.t, 50 * kUs + 2e-3, 1e-12);
  EXPECT_EQ(bus.Statistics().spikes, 1u);
}

TEST(VirtualCanBus, ForcedBusOffAndAutomaticRecovery) {
  VirtualCanBusConfig cfg;
  cfg.auto_bus_off_recovery = true;
  VirtualCanBus bus(cfg);
  auto* tx = bus.AddNode("tx");
  auto* rx = bus.AddNode("rx");
  tx->Send(Frame(0x100));
  tx->ForceBusOff();  // flushes the queue
  EXPECT_EQ(tx->Send(Frame(0x100)), CanStatus::kBusOff);
  bus.AdvanceTo(1400 * kUs);  // recovery needs 128 x 11 = 1408 bit times
  EXPECT_EQ(tx->state(), CanNodeState::kBusOff);
  bus.AdvanceTo(1410 * kUs);
  EXPECT_EQ(tx->state(), CanNodeState::kErrorActive);
  EXPECT_EQ(Drain(rx).size(), 0u);
  EXPECT_EQ(tx->Send(Frame(0x100)), CanStatus::kOk);
}

TEST(VirtualCanBus, BusLoad) {
  // One 53-bit frame per millisecond at 1 Mbit/s: 5.3 % load.
  VirtualCanBus bus;
  auto* tx = bus.AddNode("tx");
  bus.AddNode("rx");
  for (int k = 0; k < 200; ++k) {
    tx->Send(Frame(0x000));
    bus.AdvanceTo((k + 1) * 1e-3);
  }
  const CanBusStatistics s = bus.Statistics();
  EXPECT_NEAR(s.load_percent, 5.3, 1e-6);
  EXPECT_NEAR(s.mean_load_percent, 5.3, 1e-6);
  EXPECT_EQ(s.frames, 200u);
  EXPECT_EQ(s.bits, 200u * 53u);
  // The exoskeleton's traffic: 1 kHz commands, statuses and EMG, heartbeat at 100 Hz.
  VirtualCanBus exo;
  auto* c = exo.AddNode("ctrl");
  auto* hip = exo.AddNode("hip");
  auto* knee = exo.AddNode("knee");
  auto* emg = exo.AddNode("emg");
  double expected_bits = 0;
  for (int k = 0; k < 300; ++k) {
    const uint8_t n = static_cast<uint8_t>(k);
    const std::vector<std::pair<CanBus*, CanFrame>> sends = {
        {c, msg::Encode(msg::ControllerHeartbeat{0, 0, 0, n})},
        {c, msg::Encode(msg::JointCommand{msg::Joint::kHip, 0.01 * k, n, true})},
        {c, msg::Encode(msg::JointCommand{msg::Joint::kKnee, -0.01 * k, n, true})},
        {hip, msg::Encode(msg::JointStatus{msg::Joint::kHip, 0.001 * k, 0.015 * k, 1, n})},
        {knee, msg::Encode(msg::JointStatus{msg::Joint::kKnee, -0.001 * k, -0.015 * k, 1, n})},
        {emg, msg::Encode(msg::EmgSamples{{0.01 * k, 0, 0, 0, 0}, uint8_t(k % 16)})}};
    for (const auto& [ep, f] : sends) {
      if (f.id == msg::kIdControllerHeartbeat && k % 10 != 0) continue;
      ASSERT_EQ(ep->Send(f), CanStatus::kOk);
      if (k >= 200) expected_bits += CanFrameBits(f);
    }
    exo.AdvanceTo((k + 1) * 1e-3);
  }
  EXPECT_NEAR(exo.Statistics().load_percent, 100.0 * expected_bits * 1e-6 / 0.1, 1e-6);
  EXPECT_LT(exo.Statistics().load_percent, 60.0);  // headroom for retransmissions and HAL-3
}

// A run with every random feature on; returns what the receivers saw.
std::vector<CanFrame> RandomRun(uint64_t seed) {
  VirtualCanBusConfig cfg;
  cfg.seed = seed;
  cfg.latency = 20 * kUs;
  cfg.jitter = 30 * kUs;
  cfg.drop_probability = 0.05;
  cfg.corrupt_probability = 0.05;
  cfg.spike_probability = 0.01;
  cfg.spike_delay = 500 * kUs;
  VirtualCanBus bus(cfg);
  auto* c = bus.AddNode("ctrl", {0x180, 0x181});
  auto* hip = bus.AddNode("hip", {0x010, 0x100});
  auto* knee = bus.AddNode("knee", {0x010, 0x101});
  std::vector<CanFrame> seen;
  for (int k = 0; k < 500; ++k) {
    const uint8_t n = static_cast<uint8_t>(k);
    c->Send(msg::Encode(msg::ControllerHeartbeat{0, 0, 0, n}));
    c->Send(msg::Encode(msg::JointCommand{msg::Joint::kHip, std::sin(k * 0.01), n, true}));
    c->Send(msg::Encode(msg::JointCommand{msg::Joint::kKnee, std::cos(k * 0.01), n, true}));
    hip->Send(msg::Encode(msg::JointStatus{msg::Joint::kHip, 0.001 * k, 0.015 * k, 1, n}));
    knee->Send(msg::Encode(msg::JointStatus{msg::Joint::kKnee, -0.001 * k, -0.015 * k, 1, n}));
    bus.AdvanceTo((k + 1) * 1e-3);
    for (CanBus* ep : {static_cast<CanBus*>(c), static_cast<CanBus*>(hip), static_cast<CanBus*>(knee)})
      for (const CanFrame& f : Drain(ep)) seen.push_back(f);
  }
  return seen;
}

bool Identical(const std::vector<CanFrame>& a, const std::vector<CanFrame>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!SamePayload(a[i], b[i]) || a[i].t != b[i].t) return false;  // bit-identical time stamps
  return true;
}

TEST(VirtualCanBus, SameSeedSameBytesAndTimes) {
  const auto a = RandomRun(42), b = RandomRun(42), c = RandomRun(43);
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(Identical(a, b));
  EXPECT_FALSE(Identical(a, c));
}

TEST(VirtualCanBus, TapWritesACandumpLogOfTheWire) {
  const testing::ScopedTempDir tmp("tap");
  const std::string path = tmp.File("tap.log");
  VirtualCanBusConfig cfg;
  cfg.corrupt_probability = 0.2;
  cfg.seed = 3;
  VirtualCanBus bus(cfg);
  auto* tx = bus.AddNode("tx");
  bus.AddNode("rx");
  std::vector<CanFrame> wire;
  {
    CandumpWriter writer(path, "can0", 1700000000);
    bus.SetTap([&](const CanFrame& f) {
      writer.Write(f);
      wire.push_back(f);
    });
    for (int k = 0; k < 50; ++k) {
      tx->Send(Frame(0x100 + k, {uint8_t(k), 0xAA}));
      bus.AdvanceTo((k + 1) * 1e-3);
    }
  }
  const auto back = CandumpReader::ReadAll(path, 1700000000);
  ASSERT_EQ(back.size(), wire.size());
  EXPECT_EQ(wire.size(), bus.Statistics().frames + bus.Statistics().error_frames);
  EXPECT_EQ(bus.Statistics().frames, 50u);
  for (size_t i = 0; i < wire.size(); ++i) {
    EXPECT_TRUE(SamePayload(back[i].frame, wire[i]));
    EXPECT_NEAR(back[i].frame.t, wire[i].t, 0.5e-6 + 1e-9);
  }
}

}  // namespace
}  // namespace exotwin::hwsim
