// The effect registry (model/effect_families.h): DESIGN.md's effect table and the registry are one
// list (a test fails when they differ), every family's closed form against the table's formula
// written out here, and the invariants the stages rely on (a family the plant applies as a force has
// a closed form; a sensor family acts on the reading).
#include "model/effect_families.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "model/passive_torque.h"

namespace exotwin {
namespace {

// The rows of the first table after `heading` in DESIGN.md whose header starts with `| name |`:
// name (without backticks) -> the remaining cells.
std::map<std::string, std::vector<std::string>> DesignTable(const std::string& heading) {
  std::ifstream in(std::string(EXOTWIN_SOURCE_DIR) + "/DESIGN.md");
  std::string line;
  bool in_section = false, in_table = false;
  std::map<std::string, std::vector<std::string>> rows;
  while (std::getline(in, line)) {
    if (line.rfind(heading, 0) == 0) in_section = true;
    if (!in_section) continue;
    if (!in_table) {
      in_table = line.rfind("| name |", 0) == 0;
      continue;
    }
    if (line.rfind("| ---", 0) == 0) continue;
    if (line.empty() || line[0] != '|') break;
    std::vector<std::string> cells;
    std::stringstream ss(line.substr(1));
    std::string cell;
    while (std::getline(ss, cell, '|')) {
      const size_t a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
      cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
    }
    if (!cells.empty() && cells.back().empty()) cells.pop_back();
    std::string name = cells[0];
    if (name.size() > 2 && name.front() == '`') name = name.substr(1, name.size() - 2);
    cells.erase(cells.begin());
    rows[name] = cells;
  }
  return rows;
}

TEST(EffectFamilies, DesignTableIsTheRegistry) {
  const auto table = DesignTable("## Effects (what diagnose can name");
  ASSERT_FALSE(table.empty()) << "DESIGN.md's effect table not found";
  EXPECT_EQ(table.size(), EffectFamilies().size());
  for (const EffectFamily& f : EffectFamilies()) {
    const auto it = table.find(f.name);
    ASSERT_NE(it, table.end()) << f.name << " is in the registry, not in DESIGN.md's effect table";
    ASSERT_EQ(it->second.size(), 2u) << f.name;
    // The model file's "-" is the table's dash.
    const std::string unit = it->second[0] == "—" ? "-" : it->second[0];
    EXPECT_EQ(unit, f.unit) << f.name;
    EXPECT_EQ(it->second[1], f.table) << f.name;
  }
  for (const auto& row : table) EXPECT_NE(FindFamily(row.first), nullptr) << row.first << " is not in the registry";
}

TEST(EffectFamilies, EveryFamilyTheFitCanNameHasARangeRow) {
  const auto ranges = DesignTable("Physical ranges:");
  for (const EffectFamily& f : EffectFamilies())
    if (f.carrier != PlantCarrier::kNotCarried) {
      EXPECT_TRUE(ranges.count(f.name)) << f.name;
    }
}

TEST(EffectFamilies, InvariantsTheStagesRelyOn) {
  std::map<std::string, int> exclusive;
  for (const EffectFamily& f : EffectFamilies()) {
    // A family the plant applies as a generalized force is evaluated by its closed form each step.
    if (f.carrier == PlantCarrier::kAppliedForce || f.carrier == PlantCarrier::kSubjectForce) {
      EXPECT_NE(f.link_torque, nullptr) << f.name;
    }
    // Sensor families act on the reading and only there.
    EXPECT_EQ(f.stage == EffectStage::kSensor, f.carrier == PlantCarrier::kReading) << f.name;
    EXPECT_EQ(f.stage == EffectStage::kSensor, f.on_reading != nullptr) << f.name;
    if (f.stage == EffectStage::kSensor) {
      EXPECT_EQ(f.link_torque, nullptr) << f.name;
    }
    EXPECT_LT(f.lo, f.hi) << f.name;
    if (*f.exclusive) ++exclusive[f.exclusive];
  }
  // The plant carries one internal hinge per joint: a dead band and a strap exclude each other.
  EXPECT_EQ(std::string(FindFamily("backlash")->exclusive), FindFamily("series_compliance")->exclusive);
  for (const auto& g : exclusive) EXPECT_GE(g.second, 2) << "a group of one: " << g.first;
  EXPECT_EQ(FindFamily("no_such_effect"), nullptr);
}

// The closed forms against DESIGN.md's formulas, written out independently, at a state away from
// zero velocity (the sign) and at both joints.
TEST(EffectFamilies, ClosedFormsAreTheTablesFormulas) {
  EffectState s;
  s.q = {0.3, -0.7}, s.qd = {-1.2, 0.8}, s.qdd = {2.5, -3.1}, s.g = 9.81;
  for (int j = 0; j < 2; ++j) {
    auto make = [&](const char* name, double value) {
      Effect e;
      e.name = name, e.joint = j == 0 ? "hip" : "knee", e.value = value;
      return e;
    };
    auto at = [&](const Effect& e) { return FamilyOf(e).link_torque(e, s); };
    auto only = [&](double v) { Eigen::Vector2d t = Eigen::Vector2d::Zero(); t[j] = v; return t; };
    EXPECT_EQ(at(make("coulomb_friction", 0.7)), only(0.7 * (s.qd[j] > 0 ? 1 : -1)));
    EXPECT_EQ(at(make("viscous_friction", 1.3)), only(1.3 * s.qd[j]));
    EXPECT_EQ(at(make("inertia_error", 0.2)), only(0.2 * s.qdd[j]));
    Effect k = make("joint_stiffness", 9.0);
    k.fields["q0"] = 0.1;
    EXPECT_EQ(at(k), only(9.0 * (s.q[j] - 0.1)));
    Effect r = make("torque_ripple", 0.4);
    r.fields["cycles_per_rad"] = 3.0, r.fields["phase"] = 0.5;
    EXPECT_NEAR(at(r)[j], 0.4 * std::sin(2 * M_PI * 3.0 * s.q[j] + 0.5), 1e-15);
    // gravity_error, HJ15 eq. 7: the distal segment's X off by value moves g X sin(absolute angle),
    // its Y g Y cos; the thigh's (hip) the hip row only, the shank's (knee) both rows.
    Effect gx = make("gravity_error", 0.15), gy = gx;
    gx.axis = "X", gy.axis = "Y";
    const double ang = j == 0 ? s.q[0] : s.q[0] + s.q[1];
    EXPECT_NEAR(at(gx)[0], 9.81 * 0.15 * std::sin(ang), 1e-14);
    EXPECT_NEAR(at(gy)[0], 9.81 * 0.15 * std::cos(ang), 1e-14);
    EXPECT_NEAR(at(gx)[1], j == 1 ? 9.81 * 0.15 * std::sin(ang) : 0.0, 1e-14);
    const Eigen::Vector2d P = PassiveElasticTorque(PassiveModel::kRiener1999, s.q);
    EXPECT_NEAR(at(make("passive_moment", 0.5))[j], 0.5 * P[j], 1e-14);
    EXPECT_EQ(at(make("passive_moment", 0.5))[1 - j], 0.0);
  }
  // The sensor families on a reading: offset, gain, and a delay of one sample on a ramp.
  const std::vector<double> t = {0.0, 0.01, 0.02, 0.03};
  std::vector<double> tau = {1.0, 2.0, 3.0, 4.0};
  Effect e;
  e.joint = "knee";
  e.name = "sensor_offset", e.value = 0.5;
  FamilyOf(e).on_reading(e, t, &tau);
  EXPECT_EQ(tau, (std::vector<double>{1.5, 2.5, 3.5, 4.5}));
  e.name = "sensor_gain", e.value = 0.1;
  FamilyOf(e).on_reading(e, t, &tau);
  EXPECT_NEAR(tau[3], 4.95, 1e-12);
  tau = {1.0, 2.0, 3.0, 4.0};
  e.name = "sensor_delay", e.value = 0.01;
  FamilyOf(e).on_reading(e, t, &tau);
  const std::vector<double> delayed = {1.0, 1.0, 2.0, 3.0};  // held at the first sample
  for (size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(tau[i], delayed[i], 1e-12) << i;
}

// A sensor family's inverse undoes it (replay's actuator torque from the reading), and the affine
// ones compose into a joint module's gain and offset as the series form acts.
TEST(EffectFamilies, SensorFormsInvertAndCompose) {
  const std::vector<double> t = {0.0, 0.01, 0.02, 0.03, 0.04};
  const std::vector<double> tau = {1.0, -2.0, 3.5, 0.25, -1.0};
  for (const EffectFamily& f : EffectFamilies()) {
    if (f.stage != EffectStage::kSensor) continue;
    Effect e;
    e.name = f.name, e.joint = "hip", e.value = f.unit == std::string("s") ? 0.01 : 0.2;
    std::vector<double> x = tau;
    f.on_reading(e, t, &x);
    f.off_reading(e.value, t, &x);
    // A delay of one sample shifts the record: the inverse restores all but the last sample (held).
    const size_t n = f.affine ? t.size() : t.size() - 1;
    for (size_t i = 1; i < n; ++i) EXPECT_NEAR(x[i], tau[i], 1e-12) << f.name << " " << i;
    if (!f.affine) continue;
    double a = 1, b = 0;
    f.affine(e.value, &a, &b);
    std::vector<double> y = tau;
    f.on_reading(e, t, &y);
    for (size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(y[i], a * tau[i] + b, 1e-12) << f.name;
  }
}

}  // namespace
}  // namespace exotwin
