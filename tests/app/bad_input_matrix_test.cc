// The bad-input matrix of issues 8 and 21: one test per case of bad input over MJCF models, MODEL.yaml
// parameter files, measured-data CSV, column maps and scenario YAML (truncated files, wrong types,
// units out of range, NaN and inf, empty files, huge values, duplicated keys/columns, binary junk).
// Each goes through the command line (`exotwin predict` for MJCF / parameters / CSV / maps, `exotwin
// run` for scenarios) and must exit 2 with a message naming the place (file, line or field) and what was
// expected. Complements tests/app/predict_cli_test.cc (whose cases are not repeated here).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::WriteText;

constexpr const char* kModel = testing::kSubjectModelYaml;
const char kExo[] = "exo: {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n";

// A valid scenario that runs in a blink; cases append or replace lines.
const char kScenarioHead[] = "name: bad_input\ndevice: exowheel\n";
const char kScenarioSubject[] = "subject: {preset: S1}\n";
const char kScenarioProtocol[] = "protocol: {trajectory: hold, duration: 0.05, ramp: 0}\n";

// 200 rows at 1 kHz; data row i is on line i + 2.
std::string GoodCsv(int n = 200, const std::string& extra_header = "", const std::string& extra = "") {
  std::ostringstream os;
  os << "t,q_hip,q_knee,tau_hip,tau_knee" << extra_header << "\n";
  for (int i = 0; i < n; ++i) {
    const double t = i * 0.001;
    os << t << "," << 0.3 + 0.1 * std::sin(2 * t) << "," << -0.7 + 0.2 * std::sin(3 * t) << ",-20,-5" << extra
       << "\n";
  }
  return os.str();
}
// GoodCsv with data row `row` (0-based) replaced.
std::string CsvWithRow(int row, const std::string& line) {
  std::istringstream in(GoodCsv());
  std::string out, l;
  for (int i = -1; std::getline(in, l); ++i) out += (i == row ? line : l) + "\n";
  return out;
}

// A foreign log (another rig's names, the actuator's torque sign, one angle in degrees) and a map
// that reads it; map cases replace parts of the map. Map line 2 is `t`, line 4 `q_knee`.
std::string ForeignCsv() {
  std::ostringstream os;
  os << "time,pos1,pos2_deg,trq1,trq2,counts\n";
  for (int i = 0; i < 200; ++i) {
    const double t = i * 0.001;
    os << t << "," << 0.3 + 0.1 * std::sin(2 * t) << "," << -40 + 10 * std::sin(3 * t) << ",20,5," << 4096 + i
       << "\n";
  }
  return os.str();
}
const char kMap[] =
    "columns:\n"
    "  t:        {from: time}\n"
    "  q_hip:    {from: pos1}\n"
    "  q_knee:   {from: pos2_deg, unit: deg}\n"
    "  tau_hip:  {from: trq1, sign: -1}\n"
    "  tau_knee: {from: trq2, scale: -1}\n";
std::string MapReplace(const std::string& from, const std::string& to) {
  std::string m = kMap;
  const size_t p = m.find(from);
  return p == std::string::npos ? "pattern not found: " + from : m.replace(p, from.size(), to);
}

std::string ShippedMjcf() { return testing::ReadText(std::string(EXOTWIN_SOURCE_DIR) + "/mjcf/leg_exowheel.xml"); }
std::string MjcfReplace(const std::string& from, const std::string& to) {
  std::string x = ShippedMjcf();
  const size_t p = x.find(from);
  if (p == std::string::npos) return "<!-- pattern not found: " + from + " -->";
  return x.replace(p, from.size(), to);
}

std::string Junk(size_t n, bool with_nul, unsigned seed) {
  std::string s(n, '\0');
  unsigned x = seed;
  for (auto& c : s) {
    x = x * 1103515245u + 12345u;
    c = static_cast<char>(0x80 | ((x >> 16) & 0x7F));  // high bytes: invalid UTF-8, no NUL
  }
  if (with_nul) s[n / 2] = '\0';
  return s;
}

enum class Kind { kParams, kCsv, kMjcf, kScenario, kMap };

struct Case {
  std::string name;
  Kind kind;
  std::string content;   // the bad file's content (the other inputs are valid)
  std::string place;     // must appear in the message: file/line/column or field
  std::string expected;  // must appear in the message: what was expected
  std::string args = {};  // replaces the bad file's path on the command line when not empty
};

// gtest prints a parameter in test names and failures: the case name, not its bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> Cases() {
  const std::string S = std::string(kScenarioHead) + kScenarioSubject + kScenarioProtocol;
  std::vector<Case> c = {
      // ---- MJCF (predict --mjcf) ----
      {"MjcfEmptyFile", Kind::kMjcf, "", "x.xml: cannot load MJCF model", "XML_ERROR_EMPTY_DOCUMENT"},
      {"MjcfTruncated", Kind::kMjcf, ShippedMjcf().substr(0, 1900), "x.xml: cannot load MJCF model", "XML_ERROR_PARSING"},
      {"MjcfBinaryJunk", Kind::kMjcf, Junk(512, true, 1), "x.xml: cannot load MJCF model", "XML parse error"},
      {"MjcfMissingFile", Kind::kMjcf, "", "nonexistent.xml: cannot load MJCF model", "XML_ERROR_FILE_NOT_FOUND", "/nonexistent.xml"},
      {"MjcfWrongAttributeType", Kind::kMjcf, MjcfReplace("timestep=\"0.001\"", "timestep=\"fast\""),
       "x.xml: cannot load MJCF model", "problem reading attribute 'timestep'"},
      {"MjcfNaNDamping", Kind::kMjcf, MjcfReplace("damping=\"0\"", "damping=\"nan\""),
       "x.xml: MJCF model value dof_damping[0] = nan", "expected a finite number"},
      {"MjcfInfArmature", Kind::kMjcf, MjcfReplace("damping=\"0\"", "damping=\"0\" armature=\"inf\""),
       "x.xml: MJCF model value dof_armature[0] = inf", "expected a finite number"},
      {"MjcfHugeGear", Kind::kMjcf, MjcfReplace("joint=\"hip\" gear=\"1\"", "joint=\"hip\" gear=\"1e300\""),
       "x.xml: MJCF model value actuator_gear[0] = 1e+300", "of magnitude at most 1e9"},
      {"MjcfGearNotOne", Kind::kMjcf, MjcfReplace("joint=\"knee\" gear=\"1\"", "joint=\"knee\" gear=\"2\""),
       "x.xml: actuator 1 ('knee_motor')", "expected a <motor> on joint 'knee' with gear 1"},
      {"MjcfActuatorsSwapped", Kind::kMjcf,
       MjcfReplace("name=\"hip_motor\" joint=\"hip\"", "name=\"hip_motor\" joint=\"knee\""),
       "x.xml: actuator 0 ('hip_motor')", "expected a <motor> on joint 'hip'"},
      {"MjcfNoActuators", Kind::kMjcf,
       MjcfReplace("<motor name=\"hip_motor\" joint=\"hip\" gear=\"1\" ctrlrange=\"-150 150\"/>", ""), "x.xml",
       "expected two torque actuators (hip, knee), found 1"},
      // ---- MODEL.yaml (predict --params) ----
      {"ParamsEmptyFile", Kind::kParams, "", "m.yaml: empty model file", "expected L1 and exo:"},
      {"ParamsTruncated", Kind::kParams, std::string(kModel).substr(0, 40), "m.yaml: line", "malformed YAML"},
      {"ParamsBinaryJunkWithNul", Kind::kParams, Junk(300, true, 2), "m.yaml: binary data", "expected a YAML text"},
      {"ParamsBinaryJunk", Kind::kParams, Junk(300, false, 3), "m.yaml: invalid UTF-8 (byte 0x", "at line 1, byte 1, expected a YAML text file"},
      {"ParamsNaN", Kind::kParams, std::string("L1: .nan\n") + kExo, "m.yaml: L1", "expected a finite number"},
      {"ParamsInf", Kind::kParams, std::string("L1: 0.41\nexo: {J1: .inf, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n"),
       "m.yaml: exo.J1", "expected a finite number"},
      {"ParamsLengthOutOfRange", Kind::kParams, std::string("L1: 4.1\n") + kExo, "m.yaml: L1",
       "expected 0.1 .. 1 m"},
      {"ParamsHugeValue", Kind::kParams,
       "L1: 0.41\nexo: {J1: 1e300, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n", "m.yaml: exo.J1",
       "expected 0 .. 50 kg m^2"},
      {"ParamsOverflowingNumber", Kind::kParams,
       "L1: 0.41\nexo: {J1: 3.02, J2: 0.74, X1: 1e999, X2: 1.74, Y1: 0.15, Y2: 0.16}\n", "m.yaml: exo.X1",
       "is not a number"},
      {"ParamsNegativeGravity", Kind::kParams, std::string("L1: 0.41\ng: -9.81\n") + kExo, "m.yaml: g",
       "expected 0 .. 20 m/s^2"},
      {"ParamsDuplicatedKey", Kind::kParams, std::string("L1: 0.41\nL1: 0.45\n") + kExo, "m.yaml: L1",
       "duplicated key"},
      {"ParamsBlockWrongType", Kind::kParams, "L1: 0.41\nexo: [3.02, 0.74, 3.85, 1.74, 0.15, 0.16]\n",
       "m.yaml: exo", "expected a mapping"},
      {"ParamsNonScalarKey", Kind::kParams, std::string("L1: 0.41\n") + kExo + "? [a, b]\n: 1\n", "m.yaml",
       "expected plain keys"},
      {"ParamsUnknownPassive", Kind::kParams, std::string(kModel).replace(std::string(kModel).find("riener1999"), 10, "hill"),
       "m.yaml: passive", "expected 'none' or 'riener1999'"},
      {"ParamsEffectsNotAList", Kind::kParams, std::string("L1: 0.41\n") + kExo + "effects: 3\n",
       "m.yaml: effects", "expected a list"},
      {"ParamsUnknownEffect", Kind::kParams,
       std::string("L1: 0.41\n") + kExo + "effects:\n  - {name: warp_drive, joint: knee, value: 1}\n",
       "m.yaml: effects[0].name", "expected one of"},
      {"ParamsEffectWrongJoint", Kind::kParams,
       std::string("L1: 0.41\n") + kExo + "effects:\n  - {name: backlash, joint: ankle, value: 0.01}\n",
       "m.yaml: effects[0].joint", "expected 'hip' or 'knee'"},
      {"ParamsEffectOutOfRange", Kind::kParams,
       std::string("L1: 0.41\n") + kExo + "effects:\n  - {name: backlash, joint: knee, value: 2}\n",
       "m.yaml: effects[0].value", "expected 0 .. 0.5 rad"},
      {"ParamsEffectWrongUnit", Kind::kParams,
       std::string("L1: 0.41\n") + kExo + "effects:\n  - {name: coulomb_friction, joint: knee, value: 1, unit: kg}\n",
       "m.yaml: effects[0].unit", "expected 'N m'"},
      {"ParamsEffectMissingField", Kind::kParams,
       std::string("L1: 0.41\n") + kExo + "effects:\n  - {name: joint_stiffness, joint: knee, value: 5}\n",
       "m.yaml: effects[0].q0", "missing, required by joint_stiffness"},
      {"ParamsMissingFile", Kind::kParams, "", "nonexistent.yaml", "cannot open model file", "/nonexistent.yaml"},
      // ---- measured CSV (predict --measured) ----
      {"CsvTruncatedHeader", Kind::kCsv, "t,q_hip,q_kn", "d.csv", "missing required column 'q_knee'"},
      {"CsvTruncatedLastRow", Kind::kCsv, GoodCsv().substr(0, GoodCsv().size() - 12), "d.csv:201",
       "expected 5 fields"},
      {"CsvDuplicatedColumn", Kind::kCsv, "t,q_hip,q_knee,q_hip,tau_hip,tau_knee\n0,0,0,0,0,0\n", "d.csv:1",
       "duplicated column 'q_hip'"},
      {"CsvBinaryJunkWithNul", Kind::kCsv, Junk(400, true, 4), "d.csv: binary data", "expected a text CSV file"},
      {"CsvBinaryJunk", Kind::kCsv, Junk(400, false, 5), "d.csv: invalid UTF-8 (byte 0x", "at line 1, byte 3, expected a text CSV file"},
      {"CsvInfTorque", Kind::kCsv, CsvWithRow(50, "0.05,0.3,-0.7,inf,-5"), "d.csv:52: column 'tau_hip'",
       "expected a finite number"},
      {"CsvNegativeInfTime", Kind::kCsv, CsvWithRow(0, "-inf,0.3,-0.7,-20,-5"), "d.csv:2: column 't'",
       "expected a finite number"},
      {"CsvOverflowingNumber", Kind::kCsv, CsvWithRow(10, "0.01,1e999,-0.7,-20,-5"), "d.csv:12: column 'q_hip'",
       "expected a finite number"},
      // A record may turn a joint through revolutions (up to 1e4 rad); a leg (human: block) may not.
      {"CsvAngleBeyondHumanRange", Kind::kCsv, CsvWithRow(20, "0.02,0.3,-7.5,-20,-5"), "d.csv:22: column 'q_knee'",
       "expected |q| <= 6.28"},
      {"CsvAngleBeyondSanityBound", Kind::kCsv, CsvWithRow(20, "0.02,0.3,-2e4,-20,-5"), "d.csv:22: column 'q_knee'",
       "expected |x| <= 10000"},
      {"CsvHugeTorque", Kind::kCsv, CsvWithRow(30, "0.03,0.3,-0.7,1e300,-5"), "d.csv:32: column 'tau_hip'",
       "expected |x| <= 1000"},
      {"CsvEmgOutOfRange", Kind::kCsv, GoodCsv(200, ",emg_VM", ",250"), "d.csv:2: column 'emg_VM'",
       "expected |x| <= 100"},
      {"CsvEmptyField", Kind::kCsv, CsvWithRow(40, "0.04,,-0.7,-20,-5"), "d.csv:42: column 'q_hip'",
       "is not a number"},
      {"CsvHeaderOnly", Kind::kCsv, "t,q_hip,q_knee,tau_hip,tau_knee\n", "d.csv", "expected at least 20"},
      {"CsvOnlyComments", Kind::kCsv, "# nothing measured\n\n# still nothing\n", "d.csv", "no header row"},
      {"CsvEmptyColumnName", Kind::kCsv, "t,,q_hip,q_knee,tau_hip,tau_knee\n", "d.csv:1", "empty column name"},
      {"CsvRowEndsWithComma", Kind::kCsv, CsvWithRow(60, "0.06,0.3,-0.7,-20,-5,"), "d.csv:62",
       "row ends with ','"},
      {"CsvSampledTooSlowly", Kind::kCsv, "", "d.csv", "expected a sample rate above 40"},
      {"CsvSamplingGap", Kind::kCsv, "", "d.csv: column 't'", "expected roughly uniform sampling"},
      {"CsvMissingFile", Kind::kCsv, "", "nonexistent.csv", "cannot open file", "/nonexistent.csv"},
      {"CsvMeasuredIsAFolder", Kind::kCsv, "", "/.: is a folder", "expected a CSV file", "/."},
      {"CsvSemicolonsAndDecimalCommas", Kind::kCsv, "t;q_hip;q_knee;tau_hip;tau_knee\n0;0,3;-0,7;-20;-5\n",
       "d.csv:1: the header is separated by ';'", "'.' as the decimal separator"},
      {"CsvUnclosedQuote", Kind::kCsv, CsvWithRow(30, "0.03,\"0.3,-0.7,-20,-5"), "d.csv:32: field 2",
       "expected a closing '\"'"},
      {"CsvTrailingCommaMissingOnARow", Kind::kCsv, "", "d.csv:42", "expected 5 fields and a trailing ','"},
      // ---- column maps (predict --measured foreign.csv --map) ----
      {"MapMissingColumn", Kind::kMap, MapReplace("from: pos1", "from: pos_meas1"), "map.yaml: columns.q_hip.from (line 3)",
       "missing required column 'pos_meas1' in"},
      {"MapZeroScale", Kind::kMap, MapReplace("scale: -1", "scale: 0"), "map.yaml: columns.tau_knee.scale",
       "expected a non-zero number"},
      {"MapUnknownTarget", Kind::kMap, std::string(kMap) + "  q_ankle: {from: counts}\n", "map.yaml: columns.q_ankle",
       "expected one of: t, q_hip"},
      {"MapMissingTarget", Kind::kMap, MapReplace("  t:        {from: time}\n", ""), "map.yaml: columns",
       "missing required target 't'"},
      {"MapDegreesBeyond720", Kind::kMap, MapReplace("from: pos2_deg", "from: counts"),
       "foreign.csv:2: column 'counts' (q_knee in deg", "beyond +-720 deg, expected an angle in degrees"},
      {"MapBadSign", Kind::kMap, MapReplace("sign: -1", "sign: 2"), "map.yaml: columns.tau_hip.sign",
       "expected +1 or -1"},
      {"MapBadUnit", Kind::kMap, MapReplace("unit: deg", "unit: turns"), "map.yaml: columns.q_knee.unit",
       "expected one of: rad, deg"},
      {"MapNotYaml", Kind::kMap, "columns: {t: [time\n", "map.yaml: line", "malformed YAML"},
      {"MapBinaryJunk", Kind::kMap, Junk(300, true, 8), "map.yaml: binary data", "expected a YAML text file"},
      {"MapEmptyFile", Kind::kMap, "", "map.yaml: empty column map", "expected columns:"},
      {"MapMissingFile", Kind::kMap, "", "nonexistent.yaml", "cannot open column map file", "/nonexistent.yaml"},
      // ---- scenario YAML (run) ----
      {"ScenarioEmptyFile", Kind::kScenario, "", "s.yaml: empty scenario file", ""},
      {"ScenarioTruncated", Kind::kScenario, S.substr(0, 45), "s.yaml: line", "malformed YAML"},
      {"ScenarioBinaryJunkWithNul", Kind::kScenario, Junk(300, true, 6), "s.yaml: binary data",
       "expected a YAML text file"},
      {"ScenarioBinaryJunk", Kind::kScenario, Junk(300, false, 7), "s.yaml: invalid UTF-8 (byte 0x", "at line 1, byte 1, expected a YAML text file"},
      {"ScenarioWrongType", Kind::kScenario,
       std::string(kScenarioHead) + kScenarioSubject + "protocol: {trajectory: hold, duration: long}\n",
       "s.yaml: protocol.duration", "'long' is not a number"},
      {"ScenarioNaN", Kind::kScenario,
       std::string(kScenarioHead) + kScenarioSubject + "protocol: {trajectory: hold, duration: .nan}\n",
       "s.yaml: protocol.duration", "expected 0.01 .. 3600"},
      {"ScenarioInf", Kind::kScenario, S + "hardware: {can_latency: .inf}\n", "s.yaml: hardware.can_latency",
       "expected 0 .. 0.1"},
      {"ScenarioHugeValue", Kind::kScenario, S + "controller: {kp: [1e300, 400]}\n", "s.yaml: controller.kp[0]",
       "expected 0 .. 100000"},
      {"ScenarioUnitOutOfRange", Kind::kScenario, S + "hardware: {can_bitrate: 5e7}\n",
       "s.yaml: hardware.can_bitrate", "expected 10000 .. 1e+06"},
      {"ScenarioAngleOutOfRange", Kind::kScenario, S + "fixed_joints: {hip: 90}\n", "s.yaml: fixed_joints.hip",
       "expected -2.5 .. 2.5"},
      {"ScenarioDuplicatedKey", Kind::kScenario, S + "device: hal3\n", "s.yaml: device", "duplicated key"},
      {"ScenarioPairWrongType", Kind::kScenario, S + "controller: {kd: 30}\n", "s.yaml: controller.kd",
       "expected [hip, knee]"},
      {"ScenarioBoolWrongType", Kind::kScenario, S + "controller: {feedforward: maybe}\n",
       "s.yaml: controller.feedforward", "is not true/false"},
      {"ScenarioUnknownFault", Kind::kScenario, S + "faults:\n  - {type: meltdown, at: 0.01}\n",
       "s.yaml: faults[0].type", "is not one of"},
      {"ScenarioUnknownPreset", Kind::kScenario, std::string(kScenarioHead) + "subject: {preset: S99}\n" +
       kScenarioProtocol, "s.yaml: subject.preset: 'S99' is not one of: S1, S10, S2", "(line 3)"},
      {"ScenarioMissingParamsFile", Kind::kScenario,
       std::string(kScenarioHead) + "subject: {params: /nonexistent/model.yaml}\n" + kScenarioProtocol,
       "/nonexistent/model.yaml", "cannot open model file"},
      {"ScenarioNonScalarKey", Kind::kScenario, S + "? {a: b}\n: c\n", "s.yaml", "expected plain keys"},
      {"ScenarioMissingFile", Kind::kScenario, "", "nonexistent.yaml", "cannot open scenario file",
       "/nonexistent.yaml"},
      // ---- one joint against two (DESIGN.md "One-joint devices") ----
      {"CsvOneJointForTwoJointModel", Kind::kCsv, "", "d.csv: a one-joint record",
       "m_ok.yaml, expected t, q_hip, q_knee, tau_hip, tau_knee, or a one-joint model file"},
      {"ParamsOneJointForTwoJointRecord", Kind::kParams, "joint: knee\ndevice: {I: 0.17, mgl: 3.3}\n",
       "d_ok.csv: a record with hip columns (q_hip, tau_hip, ...) given the one-joint model file",
       "m.yaml, expected a one-joint record (t, q_knee, tau_knee"},
  };
  // Cases whose content is easier to build in code.
  for (auto& k : c) {
    if (k.name == "CsvSampledTooSlowly") {  // 1 Hz: nothing left below the 20 Hz derivative filter
      std::ostringstream os;
      os << "t,q_hip,q_knee,tau_hip,tau_knee\n";
      for (int i = 0; i < 30; ++i) os << i << ",0.3,-0.7,-20,-5\n";
      k.content = os.str();
    } else if (k.name == "CsvTrailingCommaMissingOnARow") {  // the header and every row but one end with ','
      std::istringstream in(GoodCsv(200, ",", ","));
      std::string l;
      for (int i = -1; std::getline(in, l); ++i) k.content += (i == 40 ? l.substr(0, l.size() - 1) : l) + "\n";
    } else if (k.name == "CsvOneJointForTwoJointModel") {  // a one-joint record: t, q_knee, tau_knee
      std::ostringstream os;
      os << "t,q_knee,tau_knee\n";
      for (int i = 0; i < 200; ++i) os << i * 0.001 << "," << 0.3 + 0.1 * std::sin(0.002 * i) << ",-5\n";
      k.content = os.str();
    } else if (k.name == "CsvSamplingGap") {  // 1 kHz, then one sample a day later
      k.content = GoodCsv() + "86400,0.3,-0.7,-20,-5\n";
    }
  }
  return c;
}

class BadInputMatrix : public ::testing::TestWithParam<Case> {};

TEST_P(BadInputMatrix, ExitsTwoNamingPlaceAndExpectation) {
  const Case& k = GetParam();
  const testing::ScopedTempDir tmp("badinput");
  const std::string dir = tmp.path();
  std::string bad = dir + (k.kind == Kind::kParams ? "/m.yaml"
                           : k.kind == Kind::kCsv  ? "/d.csv"
                           : k.kind == Kind::kMjcf ? "/x.xml"
                           : k.kind == Kind::kMap  ? "/map.yaml"
                                                   : "/s.yaml");
  WriteText(bad, k.content);
  if (!k.args.empty()) bad = dir + k.args;  // a path that does not exist
  WriteText(dir + "/m_ok.yaml", kModel);
  WriteText(dir + "/d_ok.csv", GoodCsv());
  WriteText(dir + "/foreign.csv", ForeignCsv());
  std::string args;
  switch (k.kind) {
    case Kind::kParams: args = "predict --params " + bad + " --measured " + dir + "/d_ok.csv"; break;
    case Kind::kCsv: args = "predict --params " + dir + "/m_ok.yaml --measured " + bad; break;
    case Kind::kMjcf:
      args = "predict --params " + dir + "/m_ok.yaml --measured " + dir + "/d_ok.csv --mjcf " + bad;
      break;
    case Kind::kMap:
      args = "predict --params " + dir + "/m_ok.yaml --measured " + dir + "/foreign.csv --map " + bad;
      break;
    case Kind::kScenario: args = "run " + bad; break;
  }
  args += k.kind == Kind::kScenario ? " --out " + dir + "/run" : " --out " + dir + "/pred.csv";
  const auto r = RunExotwin(args);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("exotwin: error: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(k.place), std::string::npos) << "message should name '" << k.place << "': " << r.output;
  EXPECT_NE(r.output.find(k.expected), std::string::npos)
      << "message should say what was expected ('" << k.expected << "'): " << r.output;
  // Never a partial result.
  EXPECT_FALSE(std::ifstream(dir + "/pred.csv").good());
  EXPECT_FALSE(std::ifstream(dir + "/run/result.json").good());
}

INSTANTIATE_TEST_SUITE_P(Cases, BadInputMatrix, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

// The map cases start from a foreign log and map that read fine.
TEST(BadInputMatrixControl, ForeignCsvThroughTheBaseMapPredicts) {
  const testing::ScopedTempDir tmp("badinput_control");
  const std::string dir = tmp.path();
  WriteText(dir + "/m.yaml", kModel);
  WriteText(dir + "/foreign.csv", ForeignCsv());
  WriteText(dir + "/map.yaml", kMap);
  const auto r = RunExotwin("predict --params " + dir + "/m.yaml --measured " + dir + "/foreign.csv --map " + dir +
                            "/map.yaml --out " + dir + "/pred.csv");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST(BadInputMatrixSize, AtLeastThirtyCases) { EXPECT_GE(Cases().size(), 30u); }

}  // namespace
}  // namespace exotwin
