// OpenSim motion files as leg kinematics (formats/opensim_kinematics.h): every header variant and
// separator the format allows, written by the test itself, read into the twin's conventions; and the
// bad input that must throw InputError naming the file and the line.
#include "formats/opensim_kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "tests/motion_file.h"
#include "tests/expect_input_error.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

using testing::ExpectInputError;

using testing::MotText;
using testing::MotVariant;

// One second of a gait-like swing at 100 Hz: hip 0.1 + 0.35 sin, knee -0.5 + 0.45 sin (rad, knee <= 0).
struct Swing {
  std::vector<double> t, hip, knee;
  Swing() {
    for (int i = 0; i < 100; ++i) {
      t.push_back(0.25 + 0.01 * i);
      hip.push_back(0.1 + 0.35 * std::sin(2 * M_PI * 0.01 * i));
      knee.push_back(-0.5 + 0.45 * std::sin(2 * M_PI * 0.01 * i + 1.0));
    }
  }
};


MeasuredData Parse(const std::string& text, const std::string& side = "r") {
  return KinematicsFromStorage(ParseStorage(text, "walk.mot"), CoordinatesOfSide(side, "side"));
}

void ExpectSwing(const MeasuredData& m, const Swing& s, double tol) {
  ASSERT_EQ(m.size(), s.t.size());
  EXPECT_FALSE(HasTorque(m));
  for (size_t i = 0; i < s.t.size(); ++i) {
    EXPECT_DOUBLE_EQ(m.t()[i], s.t[i]);
    EXPECT_NEAR(m.q_hip()[i], s.hip[i], tol) << i;
    EXPECT_NEAR(m.q_knee()[i], s.knee[i], tol) << i;
  }
}

TEST(OpenSimKinematics, EveryHeaderSeparatorAndUnitVariantReadsTheSameAngles) {
  const Swing s;
  using H = MotVariant::Header;
  int variants = 0;
  for (H h : {H::kVersion1, H::kToolLines, H::kSimm})
    for (bool deg : {true, false})
      for (char sep : {'\t', ' '})
        for (bool trailing : {false, true})
          for (bool crlf : {false, true}) {
            MotVariant v;
            v.header = h, v.in_degrees = deg, v.sep = sep, v.trailing_sep = trailing, v.crlf = crlf;
            SCOPED_TRACE("header " + std::to_string(static_cast<int>(h)) + (deg ? " deg" : " rad") +
                         (sep == ' ' ? " space" : " tab") + (trailing ? " trailing" : "") + (crlf ? " crlf" : ""));
            // degrees: one rounding of x * 180/pi then one of y * pi/180
            ExpectSwing(Parse(MotText(s.t, s.hip, s.knee, v)), s, deg ? 1e-15 : 0.0);
            ++variants;
          }
  EXPECT_EQ(variants, 48);
}

TEST(OpenSimKinematics, SideChoosesTheColumns) {
  const Swing s;
  MotVariant v;
  v.side = "l";
  ExpectSwing(Parse(MotText(s.t, s.hip, s.knee, v), "l"), s, 1e-15);
  ExpectInputError([&] { Parse(MotText(s.t, s.hip, s.knee, v), "r"); }, {"walk.mot", "no column 'hip_flexion_r'"});
  ExpectInputError([&] { CoordinatesOfSide("x", "scenario.yaml: protocol.side"); }, {"protocol.side", "expected r or l"});
}

TEST(OpenSimKinematics, AngleUnitThatCannotBeToldNamesTheLine) {
  const Swing s;
  MotVariant v;
  v.header = MotVariant::Header::kToolLines;
  v.state_unit = false;  // walk.mot, nRows, nColumns, endheader (line 4)
  ExpectInputError([&] { Parse(MotText(s.t, s.hip, s.knee, v)); }, {"walk.mot: line 4", "inDegrees"});
  v.header = MotVariant::Header::kNone;  // column names on line 1, no header at all
  ExpectInputError([&] { Parse(MotText(s.t, s.hip, s.knee, v)); }, {"walk.mot: line 1", "inDegrees", "no header"});
}

TEST(OpenSimKinematics, NoTimeColumnNamesTheLine) {
  const Swing s;
  std::string text = MotText(s.t, s.hip, s.knee, MotVariant());
  text.replace(text.find("time\t"), 4, "Time");  // not OpenSim's column name
  ExpectInputError([&] { Parse(text); }, {"walk.mot: line 11", "'time'"});
}

TEST(OpenSimKinematics, FewerColumnsThanTheHeaderSays) {
  const Swing s;
  MotVariant v;
  v.n_columns = 7;
  ExpectInputError([&] { Parse(MotText(s.t, s.hip, s.knee, v)); }, {"walk.mot: line 11", "6 column names", "nColumns=7"});
  v.header = MotVariant::Header::kSimm;  // datacolumns 7
  ExpectInputError([&] { Parse(MotText(s.t, s.hip, s.knee, v)); }, {"walk.mot: line 7", "nColumns=7"});
  // a row with fewer values than the column names
  std::string text = MotText(s.t, s.hip, s.knee, MotVariant());
  const size_t row = text.find("\n0.27");  // the third row, line 14
  text.erase(text.find('\t', row + 1), text.find('\n', row + 1) - text.find('\t', row + 1));
  ExpectInputError([&] { Parse(text); }, {"walk.mot: line 14", "1 values, 6 column names"});
}

TEST(OpenSimKinematics, NonMonotonicTimeNamesTheLine) {
  Swing s;
  std::swap(s.t[4], s.t[5]);  // rows on lines 16, 17
  ExpectInputError([&] { Parse(MotText(s.t, s.hip, s.knee, MotVariant())); }, {"walk.mot: line 17", "does not increase"});
}

TEST(OpenSimKinematics, FlexionPositiveKneeIsRefused) {
  Swing s;
  for (double& k : s.knee) k = -k + 0.2;  // Rajagopal 2015: 0..120 deg flexion positive
  ExpectInputError([&] { Parse(MotText(s.t, s.hip, s.knee, MotVariant())); },
               {"walk.mot: line", "knee_angle_r", "flexion negative", "negate"});
}

TEST(OpenSimKinematics, NonFiniteAngleNamesTheLine) {
  Swing s;
  s.hip[2] = NAN;
  ExpectInputError([&] { Parse(MotText(s.t, s.hip, s.knee, MotVariant())); },
               {"walk.mot: line 14", "hip_flexion_r", "finite"});
}

TEST(OpenSimKinematics, ReadMeasuredKinematicsDispatchesOnTheExtension) {
  const testing::ScopedTempDir tmp("osk");
  const std::string dir = tmp.path();
  Swing s;
  std::ofstream(dir + "/walk.MOT") << MotText(s.t, s.hip, s.knee, MotVariant());
  EXPECT_TRUE(IsOpenSimStoragePath(dir + "/walk.MOT"));
  EXPECT_TRUE(IsOpenSimStoragePath("ik.sto"));
  EXPECT_FALSE(IsOpenSimStoragePath("data.csv"));
  ExpectSwing(ReadMeasuredKinematics(dir + "/walk.MOT", "", "r"), s, 1e-15);
  ExpectInputError([&] { ReadMeasuredKinematics(dir + "/walk.MOT", dir + "/map.yaml", "r"); },
               {"map.yaml", "not to the OpenSim motion file"});
  ExpectInputError([&] { ReadMeasuredKinematics(dir + "/walk.MOT", "", "r", 500); }, {"100 rows", "at least 500"});
  std::ofstream(dir + "/d.csv") << "t,q_hip,q_knee,tau_hip,tau_knee\n0,0,0,1,2\n1,0,0,1,2\n";
  const MeasuredData csv = ReadMeasuredKinematics(dir + "/d.csv", "", "r", 2);
  EXPECT_TRUE(HasTorque(csv));
}

}  // namespace
}  // namespace exotwin
