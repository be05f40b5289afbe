// One-joint records through column maps (DESIGN.md "One-joint devices"): a map without hip targets is
// a one-joint map; the shipped maps of the DFKI simple pendulum and of HAL-3's measured.csv give the
// one-joint schema (angle as logged, tau_knee = -the actuator's torque), checked against the raw
// columns read independently.
#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

const std::string kSrc = EXOTWIN_SOURCE_DIR;

TEST(OneJointMap, ShippedPendulumMapGivesTheOneJointSchema) {
  const std::string dir = kSrc + "/examples/real_rig/simple_pendulum/";
  const MeasuredData d = ReadMeasured(dir + "pd_system_identification.csv", dir + "dfki_simple_pendulum.map.yaml");
  const CsvTable raw = ReadCsv(dir + "pd_system_identification.csv");
  ASSERT_TRUE(d.one_joint);
  EXPECT_EQ(TableAsRecorded(d).names, (std::vector<std::string>{"t", "q_knee", "tau_knee"}));
  ASSERT_EQ(d.size(), raw.rows());  // no repeated time stamps in this record
  const auto& pos = raw.columns[raw.Find("position")];
  const auto& tau = raw.columns[raw.Find("torque")];
  for (size_t i = 0; i < d.size(); ++i) {
    ASSERT_EQ(d.q_knee()[i], pos[i]);
    ASSERT_EQ(d.tau_knee()[i], -tau[i]);
    ASSERT_EQ(d.q_hip()[i], 0.0);
    ASSERT_EQ(d.tau_hip()[i], 0.0);
  }
}

TEST(OneJointMap, Hal3MeasuredMapNegatesTheStrainGauge) {
  testing::ScopedTempDir tmp("one_joint_map");
  const std::string csv = tmp.File("measured.csv");
  {
    std::ofstream os(csv);
    os << "t,q_knee,tau_knee,cmd_knee,emg_GMAX,emg_VM,emg_RF,emg_ST,emg_GAS,E_ext,E_flex,mu_hat,D_hat,K_hat\n";
    for (int i = 0; i < 40; ++i)
      os << 0.001 * i << "," << 0.02 * i << "," << 0.5 - 0.1 * i << "," << 1.5 << ",0.1,0.2,0.3,0.4,0.5,0,0,0,0,0\n";
  }
  const MeasuredData d = ReadMeasured(csv, kSrc + "/examples/hal3_measured.map.yaml");
  ASSERT_TRUE(d.one_joint);
  for (int i = 0; i < 40; ++i) {
    EXPECT_NEAR(d.q_knee()[i], 0.02 * i, 1e-12);  // as written (6 digits)
    EXPECT_NEAR(d.tau_knee()[i], -(0.5 - 0.1 * i), 1e-12);
  }
  ASSERT_TRUE(d.Column("cmd_knee"));
  EXPECT_EQ((*d.Column("cmd_knee"))[3], 1.5);
  EXPECT_EQ(d.Column("E_ext"), nullptr);  // not mapped: dropped
}

TEST(OneJointMap, OneJointMapNeedsTheJointsColumns) {
  testing::ScopedTempDir tmp("one_joint_map");
  const std::string map = tmp.File("m.yaml");
  std::ofstream(map) << "columns:\n  t: time\n  tau_knee: torque\n";
  try {
    ReadColumnMap(map);
    ADD_FAILURE() << "accepted a one-joint map without q_knee";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(map), std::string::npos) << m;
    EXPECT_NE(m.find("q_knee"), std::string::npos) << m;
    EXPECT_NE(m.find("one-joint map"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace exotwin
