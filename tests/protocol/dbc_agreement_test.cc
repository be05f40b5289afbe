// protocol/exotwin.dbc and the codec (protocol/messages.h) describe the same protocol: for every DBC
// signal, a value encoded by the codec decodes to the same physical value with the DBC definition,
// and bytes packed from the DBC definition decode to the same values with the codec.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>

#include "protocol/dbc.h"
#include "protocol/messages.h"

namespace exotwin {
namespace {

using namespace msg;

// One codec field: how to build a frame carrying value v, and how to read it back with the codec.
struct Field {
  std::function<CanFrame(double)> encode;
  std::function<double(const CanFrame&)> decode;  // NaN if the codec rejects the frame
};

template <class M>
double Get(const CanFrame& f, std::function<double(const M&)> get) {
  M m;
  return Decode(f, &m) ? get(m) : NAN;
}

template <class M>
Field MakeField(M proto, std::function<void(M&, double)> set, std::function<double(const M&)> get) {
  return {[proto, set](double v) { M m = proto; set(m, v); return Encode(m); },
          [get](const CanFrame& f) { return Get<M>(f, get); }};
}

Field Flag(bool status_hal, Joint j, uint8_t bit) {
  if (status_hal)
    return MakeField<HalKneeStatus>({}, [bit](HalKneeStatus& m, double v) { m.flags = v != 0 ? bit : 0; },
                                    [bit](const HalKneeStatus& m) { return (m.flags & bit) ? 1.0 : 0.0; });
  JointStatus p;
  p.joint = j;
  return MakeField<JointStatus>(p, [bit](JointStatus& m, double v) { m.flags = v != 0 ? bit : 0; },
                                [bit](const JointStatus& m) { return (m.flags & bit) ? 1.0 : 0.0; });
}

std::map<std::pair<std::string, std::string>, Field> CodecFields() {
  std::map<std::pair<std::string, std::string>, Field> f;
  f[{"CTRL_HEARTBEAT", "State"}] = MakeField<ControllerHeartbeat>(
      {}, [](auto& m, double v) { m.state = uint8_t(v); }, [](const auto& m) { return double(m.state); });
  f[{"CTRL_HEARTBEAT", "FaultMask"}] = MakeField<ControllerHeartbeat>(
      {}, [](auto& m, double v) { m.fault_mask = uint16_t(v); }, [](const auto& m) { return double(m.fault_mask); });
  f[{"CTRL_HEARTBEAT", "FirstFault"}] = MakeField<ControllerHeartbeat>(
      {}, [](auto& m, double v) { m.first_fault = uint8_t(v); }, [](const auto& m) { return double(m.first_fault); });
  f[{"CTRL_HEARTBEAT", "Counter"}] = MakeField<ControllerHeartbeat>(
      {}, [](auto& m, double v) { m.counter = uint8_t(v); }, [](const auto& m) { return double(m.counter); });
  for (Joint j : {Joint::kHip, Joint::kKnee}) {
    const std::string jn = j == Joint::kHip ? "JM_HIP" : "JM_KNEE";
    JointCommand c;
    c.joint = j;
    f[{jn + "_CMD", "TorqueCmd"}] = MakeField<JointCommand>(
        c, [](auto& m, double v) { m.torque = v; }, [](const auto& m) { return m.torque; });
    f[{jn + "_CMD", "Counter"}] = MakeField<JointCommand>(
        c, [](auto& m, double v) { m.counter = uint8_t(v); }, [](const auto& m) { return double(m.counter); });
    f[{jn + "_CMD", "Enable"}] = MakeField<JointCommand>(
        c, [](auto& m, double v) { m.enable = v != 0; }, [](const auto& m) { return m.enable ? 1.0 : 0.0; });
    JointStatus s;
    s.joint = j;
    f[{jn + "_STATUS", "Angle"}] = MakeField<JointStatus>(
        s, [](auto& m, double v) { m.angle = v; }, [](const auto& m) { return m.angle; });
    f[{jn + "_STATUS", "Torque"}] = MakeField<JointStatus>(
        s, [](auto& m, double v) { m.torque = v; }, [](const auto& m) { return m.torque; });
    f[{jn + "_STATUS", "Counter"}] = MakeField<JointStatus>(
        s, [](auto& m, double v) { m.counter = uint8_t(v); }, [](const auto& m) { return double(m.counter); });
    f[{jn + "_STATUS", "Enabled"}] = Flag(false, j, kStatusEnabled);
    f[{jn + "_STATUS", "Watchdog"}] = Flag(false, j, kStatusWatchdog);
    f[{jn + "_STATUS", "TorqueSensorFault"}] = Flag(false, j, kStatusTorqueSensorFault);
    f[{jn + "_STATUS", "EncoderFault"}] = Flag(false, j, kStatusEncoderFault);
    f[{jn + "_STATUS", "TorqueLimit"}] = Flag(false, j, kStatusTorqueLimit);
    f[{jn + "_STATUS", "DriverFault"}] = Flag(false, j, kStatusDriverFault);
  }
  f[{"HAL_KNEE_CMD", "TorqueCmd"}] = MakeField<HalKneeCommand>(
      {}, [](auto& m, double v) { m.torque = v; }, [](const auto& m) { return m.torque; });
  f[{"HAL_KNEE_CMD", "Counter"}] = MakeField<HalKneeCommand>(
      {}, [](auto& m, double v) { m.counter = uint8_t(v); }, [](const auto& m) { return double(m.counter); });
  f[{"HAL_KNEE_CMD", "Enable"}] = MakeField<HalKneeCommand>(
      {}, [](auto& m, double v) { m.enable = v != 0; }, [](const auto& m) { return m.enable ? 1.0 : 0.0; });
  f[{"HAL_KNEE_STATUS", "Angle"}] = MakeField<HalKneeStatus>(
      {}, [](auto& m, double v) { m.angle = v; }, [](const auto& m) { return m.angle; });
  f[{"HAL_KNEE_STATUS", "Torque"}] = MakeField<HalKneeStatus>(
      {}, [](auto& m, double v) { m.torque = v; }, [](const auto& m) { return m.torque; });
  f[{"HAL_KNEE_STATUS", "Counter"}] = MakeField<HalKneeStatus>(
      {}, [](auto& m, double v) { m.counter = uint8_t(v); }, [](const auto& m) { return double(m.counter); });
  f[{"HAL_KNEE_STATUS", "Enabled"}] = Flag(true, Joint::kKnee, kStatusEnabled);
  f[{"HAL_KNEE_STATUS", "Watchdog"}] = Flag(true, Joint::kKnee, kStatusWatchdog);
  f[{"HAL_KNEE_STATUS", "TorqueSensorFault"}] = Flag(true, Joint::kKnee, kStatusTorqueSensorFault);
  f[{"HAL_KNEE_STATUS", "EncoderFault"}] = Flag(true, Joint::kKnee, kStatusEncoderFault);
  f[{"HAL_KNEE_STATUS", "TorqueLimit"}] = Flag(true, Joint::kKnee, kStatusTorqueLimit);
  f[{"HAL_KNEE_STATUS", "DriverFault"}] = Flag(true, Joint::kKnee, kStatusDriverFault);
  const char* emg[] = {"EMG_GMAX", "EMG_VM", "EMG_RF", "EMG_ST", "EMG_GAS"};
  for (int k = 0; k < kEmgChannels; ++k)
    f[{"EMG_SAMPLES", emg[k]}] = MakeField<EmgSamples>(
        {}, [k](auto& m, double v) { m.volts[k] = v; }, [k](const auto& m) { return m.volts[k]; });
  f[{"EMG_SAMPLES", "Counter"}] = MakeField<EmgSamples>(
      {}, [](auto& m, double v) { m.counter = uint8_t(v); }, [](const auto& m) { return double(m.counter); });
  return f;
}

DbcDatabase Load() { return LoadDbc(std::string(EXOTWIN_SOURCE_DIR) + "/protocol/exotwin.dbc"); }

TEST(DbcAgreement, EverySignalHasACodecFieldAndViceVersa) {
  const DbcDatabase db = Load();
  auto fields = CodecFields();
  std::set<std::pair<std::string, std::string>> in_dbc;
  for (const DbcMessage& m : db.messages)
    for (const DbcSignal& s : m.signals) {
      in_dbc.insert({m.name, s.name});
      EXPECT_TRUE(fields.count({m.name, s.name})) << m.name << "." << s.name << " is in the DBC but not in the codec";
    }
  for (const auto& [key, field] : fields)
    EXPECT_TRUE(in_dbc.count(key)) << key.first << "." << key.second << " is in the codec but not in the DBC";
  EXPECT_EQ(db.messages.size(), 8u);
}

TEST(DbcAgreement, IdsAndLengthsMatch) {
  const DbcDatabase db = Load();
  for (const auto& [key, field] : CodecFields()) {
    const DbcMessage* m = db.FindByName(key.first);
    ASSERT_NE(m, nullptr) << key.first;
    const CanFrame f = field.encode(0);
    EXPECT_EQ(f.id, m->id) << key.first;
    EXPECT_EQ(f.dlc, m->dlc) << key.first;
  }
}

TEST(DbcAgreement, SignalsDoNotOverlap) {
  for (const DbcMessage& m : Load().messages) {
    CanFrame used;
    used.dlc = 8;
    for (const DbcSignal& s : m.signals) {
      CanFrame mine;
      s.Encode(s.is_signed ? -s.factor : ((std::ldexp(1.0, s.length) - 1) * s.factor + s.offset), &mine);
      // -1 raw (signed) or all-ones raw (unsigned) sets exactly the signal's bits.
      for (int i = 0; i < 8; ++i) {
        EXPECT_EQ(used.data[i] & mine.data[i], 0) << m.name << "." << s.name << " overlaps another signal";
        used.data[i] |= mine.data[i];
      }
    }
  }
}

TEST(DbcAgreement, CodecEncodingDecodesWithTheDbc) {
  const DbcDatabase db = Load();
  std::mt19937_64 gen(11);
  auto uni = [&]() { return (gen() >> 11) * (1.0 / 9007199254740992.0); };
  for (const auto& [key, field] : CodecFields()) {
    const DbcSignal* s = db.FindByName(key.first)->Find(key.second);
    ASSERT_NE(s, nullptr);
    // Values: the ends of the DBC range, zero, and random values in it (integers for unit-scale fields).
    std::vector<double> values = {s->minimum, s->maximum, 0.0};
    for (int k = 0; k < 50; ++k) {
      double v = s->minimum + (s->maximum - s->minimum) * uni();
      if (s->factor == 1) v = std::floor(v);
      values.push_back(v);
    }
    for (double v : values) {
      const CanFrame f = field.encode(v);
      const double via_dbc = s->Decode(f);
      const double via_codec = field.decode(f);
      EXPECT_NEAR(via_dbc, via_codec, 1e-9 * std::max(1.0, std::abs(v))) << key.first << "." << key.second << " v=" << v;
      EXPECT_NEAR(via_dbc, v, s->factor / 2 + 1e-9 * std::max(1.0, std::abs(v))) << key.first << "." << key.second;
    }
  }
}

TEST(DbcAgreement, DbcPackedBytesDecodeWithTheCodec) {
  const DbcDatabase db = Load();
  const auto fields = CodecFields();
  std::mt19937_64 gen(5);
  for (int trial = 0; trial < 200; ++trial)
    for (const DbcMessage& m : db.messages) {
      CanFrame f;
      f.id = static_cast<uint16_t>(m.id);
      f.dlc = static_cast<uint8_t>(m.dlc);
      std::vector<double> expected;
      for (const DbcSignal& s : m.signals) {
        // A random raw value of the field width (signed range for signed fields).
        int64_t raw = static_cast<int64_t>(gen() & ((s.length == 64) ? ~0ull : ((1ull << s.length) - 1)));
        if (s.is_signed && raw >= (int64_t{1} << (s.length - 1))) raw -= int64_t{1} << s.length;
        s.Encode(raw * s.factor + s.offset, &f);
        expected.push_back(raw * s.factor + s.offset);
      }
      for (size_t i = 0; i < m.signals.size(); ++i) {
        const Field& field = fields.at({m.name, m.signals[i].name});
        EXPECT_NEAR(field.decode(f), expected[i], 1e-9 * std::max(1.0, std::abs(expected[i])))
            << m.name << "." << m.signals[i].name;
        EXPECT_NEAR(m.signals[i].Decode(f), expected[i], 1e-9 * std::max(1.0, std::abs(expected[i])));
      }
    }
}

}  // namespace
}  // namespace exotwin
