#include "emg/emg_recording.h"

#include <algorithm>
#include <cmath>

#include "formats/measured_data.h"
#include "formats/number_text.h"
#include "formats/opensim_kinematics.h"
#include "formats/opensim_storage.h"
#include "core/yaml_fields.h"
#include "core/error.h"

namespace exotwin {
namespace {

constexpr double kMaxUndershoot = 0.1;  // an envelope may dip below 0 by this share of its peak
constexpr size_t kMinSamples = 20;

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

MuscleMap DefaultMuscleMap() {
  MuscleMap m;
  m.source = "default map (OpenSim gait model channel names)";
  const std::pair<Muscle, std::vector<const char*>> names[] = {
      {Muscle::kGMAX, {"glut_max1", "glut_max2", "glut_max3", "glmax1", "glmax2", "glmax3"}},
      {Muscle::kVM, {"vas_med", "vas_lat", "vas_int", "vasmed", "vaslat", "vasint"}},
      {Muscle::kRF, {"rect_fem", "recfem"}},
      {Muscle::kST, {"semimem", "semiten", "bifemlh", "bflh"}},
      {Muscle::kGAS, {"med_gas", "lat_gas", "gasmed", "gaslat"}}};
  for (const char* side : {"_r", "_l"})
    for (const auto& g : names)
      for (const char* n : g.second) m.channels.push_back({std::string(n) + side, g.first});
  return m;
}

MuscleMap ReadMuscleMap(const std::string& path) {
  const YamlContext c{path};
  const YAML::Node root = ParseYaml(ReadYamlText(path, "muscle map"), path);
  YamlCheckKeys(c, root, "", {"muscles", "coordinates", "musculoskeletal"});
  MuscleMap m;
  m.source = path;
  m.from_file = true;
  const YAML::Node mus = root["muscles"];
  if (!mus || !mus.IsMap() || mus.size() == 0)
    c.Fail("muscles", "expected a mapping of twin muscles (GMAX, VM, RF, ST, GAS) to lists of EMG channel names");
  YamlCheckKeys(c, mus, "muscles", [](const std::string& k) { Muscle x = Muscle::kGMAX; return MuscleByName(k, &x); },
                "GMAX, VM, RF, ST, GAS");
  for (const auto& kv : mus) {
    const std::string key = kv.first.as<std::string>();
    Muscle muscle = Muscle::kGMAX;
    MuscleByName(key, &muscle);
    const YAML::Node list = kv.second;
    if (!list.IsSequence() || list.size() == 0)
      c.Fail("muscles." + key, "expected a non-empty list of EMG channel names" + YamlLine(list));
    for (const auto& ch : list) {
      if (!ch.IsScalar() || ch.as<std::string>().empty())
        c.Fail("muscles." + key, "expected channel names" + YamlLine(ch));
      const std::string name = ch.as<std::string>();
      for (const auto& prev : m.channels)
        if (prev.first == name) c.Fail("muscles." + key, "channel '" + name + "' mapped twice" + YamlLine(ch));
      m.channels.push_back({name, muscle});
    }
  }
  if (const YAML::Node ms = root["musculoskeletal"]) {
    if (!ms.IsMap()) c.Fail("musculoskeletal", "expected a mapping of channels to {joints, strength}" + YamlLine(ms));
    const char* jn[2] = {"hip", "knee"};
    for (const auto& kv : ms) {
      const std::string ch = kv.first.as<std::string>(), key = "musculoskeletal." + ch;
      const auto it = std::find_if(m.channels.begin(), m.channels.end(), [&](const auto& p) { return p.first == ch; });
      if (it == m.channels.end()) c.Fail(key, "expected a channel mapped under muscles:" + YamlLine(kv.first));
      const Muscle mu = it->second;
      YamlCheckKeys(c, kv.second, key, {"joints", "strength"});
      if (const YAML::Node js = kv.second["joints"]) {
        if (!js.IsSequence()) c.Fail(key + ".joints", "expected a list of hip, knee" + YamlLine(js));
        bool listed[2] = {false, false};
        for (const auto& j : js) {
          const std::string s = j.IsScalar() ? j.as<std::string>() : "";
          const int ji = s == "hip" ? 0 : s == "knee" ? 1 : -1;
          if (ji < 0) c.Fail(key + ".joints", "expected hip or knee" + YamlLine(j));
          if (ActionSign(mu, ji) == 0)
            c.Fail(key + ".joints", std::string(MuscleName(mu)) + "'s path does not cross the " + s +
                                        " (expected the joints it crosses)" + YamlLine(j));
          listed[ji] = true;
        }
        for (int j = 0; j < 2; ++j)
          if (ActionSign(mu, j) != 0 && !listed[j])
            c.Fail(key + ".joints", std::string(MuscleName(mu)) + " crosses the " + jn[j] +
                                        " too (one force acts at every joint its path crosses)" + YamlLine(js));
      }
      if (const YAML::Node sb = kv.second["strength"]) {
        if (!sb.IsSequence() || sb.size() != 2) c.Fail(key + ".strength", "expected [low, high] (x F_max)" + YamlLine(sb));
        std::array<double, 2> b;
        b[0] = YamlNumber(c, sb[0], key + ".strength[0]", kStrengthLo, kStrengthHi, "x F_max (CEINMS-RT's calibration bounds)");
        b[1] = YamlNumber(c, sb[1], key + ".strength[1]", b[0], kStrengthHi, "x F_max (CEINMS-RT's calibration bounds)");
        m.strength_bounds[ch] = b;
      }
    }
  }
  if (const YAML::Node co = root["coordinates"]) {
    YamlCheckKeys(c, co, "coordinates", {"hip", "knee", "ankle"});
    for (const char* j : {"hip", "knee"}) {
      if (!co[j] || !co[j].IsScalar()) c.Fail(std::string("coordinates.") + j, "expected a coordinate name");
      (std::string(j) == "hip" ? m.hip_coordinate : m.knee_coordinate) = co[j].as<std::string>();
    }
    if (co["ankle"]) {
      if (!co["ankle"].IsScalar()) c.Fail("coordinates.ankle", "expected a coordinate name" + YamlLine(co["ankle"]));
      m.ankle_coordinate = co["ankle"].as<std::string>();
    }
  }
  return m;
}

EmgRecording ReadEmgRecording(const std::string& emg_path, const std::string& kinematics_path,
                              const std::string& moments_path, const MuscleMap& map) {
  const StorageTable emg = ReadStorage(emg_path);
  EmgRecording r;
  r.source = emg_path;
  // The mapped channels present; a map from a file must find every channel it names.
  std::vector<std::pair<std::string, Muscle>> present;
  for (const auto& ch : map.channels) {
    if (emg.Find(ch.first) >= 0) present.push_back(ch);
    else if (map.from_file)
      throw InputError(map.source + ": channel '" + ch.first + "' (" + MuscleName(ch.second) +
                       ") is not a column of " + emg_path);
  }
  // The side: the default map knows both; keep the side with more channels.
  std::string side = "_r";
  if (!map.from_file) {
    const auto count = [&](const char* s) {
      return std::count_if(present.begin(), present.end(), [&](const auto& p) { return EndsWith(p.first, s); });
    };
    if (count("_l") > count("_r")) side = "_l";
    present.erase(std::remove_if(present.begin(), present.end(), [&](const auto& p) { return !EndsWith(p.first, side); }),
                  present.end());
  } else if (!present.empty() && EndsWith(present[0].first, "_l")) {
    side = "_l";
  }
  if (present.empty())
    throw InputError(emg_path + ": no EMG channel of the " + map.source +
                     " (expected columns such as rect_fem_r, vas_lat_r, semimem_r, med_gas_r)");
  const std::string hip_coord = map.hip_coordinate.empty() ? "hip_flexion" + side : map.hip_coordinate;
  const std::string knee_coord = map.knee_coordinate.empty() ? "knee_angle" + side : map.knee_coordinate;
  for (int m = 0; m < kNumMuscles; ++m) {
    const bool spans = ActionSign(MuscleAt(m), 0) != 0 || ActionSign(MuscleAt(m), 1) != 0;
    const bool has = std::any_of(present.begin(), present.end(), [&](const auto& p) { return p.second == MuscleAt(m); });
    if (spans && !has) r.missing.push_back(MuscleName(MuscleAt(m)));
  }
  std::string unused;
  for (const std::string& n : emg.names)
    if (n != "time" && std::none_of(present.begin(), present.end(), [&](const auto& p) { return p.first == n; }))
      unused += (unused.empty() ? "" : ", ") + n;
  if (!unused.empty()) r.notes.push_back("EMG channels not used (not mapped to a hip or knee muscle): " + unused);
  if (!r.missing.empty()) {
    std::string s;
    for (const auto& m : r.missing) s += (s.empty() ? "" : ", ") + m;
    r.notes.push_back("no EMG channel for " + s +
                      " (the linear form goes without it; the musculoskeletal form synthesizes it from the recorded "
                      "excitations)");
  }

  // Kinematics on their own time base, derivatives there.
  const StorageTable ik = ReadStorage(kinematics_path);
  const MeasuredData md = KinematicsFromStorage(ik, {hip_coord, knee_coord});
  const Kinematics kin = DeriveKinematics(md);
  // The ankle (the gastrocnemius' path): its rate derived as the hip's and the knee's.
  const std::string ankle_coord = map.ankle_coordinate.empty() ? "ankle_angle" + side : map.ankle_coordinate;
  std::vector<double> ankle, ankle_rate;
  if (ik.Find(ankle_coord) >= 0) {
    ankle = ik.AngleRad(ankle_coord);
    for (size_t i = 0; i < ankle.size(); ++i)
      if (!std::isfinite(ankle[i]) || std::abs(ankle[i]) > kMaxHumanJointAngle)
        throw InputError(kinematics_path + ": line " + std::to_string(ik.line_of_row[i]) + ": angle " +
                         NumberText(ankle[i]) + " rad in column '" + ankle_coord + "' (expected a finite human joint angle)");
    const Sampling s = ExamineSampling(ik.Time(), kinematics_path);
    constexpr double kCutoffHz = 20.0;  // DeriveKinematics' (HJ15 sec. 3.2)
    ankle_rate = DeriveAngleRates(s, ik.Time(), ankle, kCutoffHz, kinematics_path).qd;
  } else if (!map.ankle_coordinate.empty()) {
    throw InputError(map.source + ": coordinates.ankle '" + ankle_coord + "' is not a column of " + kinematics_path);
  } else {
    r.notes.push_back("no " + ankle_coord + " in " + kinematics_path +
                      ": the gastrocnemius path at ankle angle 0 (its length and fibre states approximate)");
  }

  StorageTable id;
  if (!moments_path.empty()) id = ReadStorage(moments_path);

  // Common time range.
  const std::vector<double>& te = emg.Time();
  double lo = std::max(te.front(), md.t().front()), hi = std::min(te.back(), md.t().back());
  if (!moments_path.empty()) lo = std::max(lo, id.Time().front()), hi = std::min(hi, id.Time().back());
  const double eps = 1e-9 * std::max(1.0, std::abs(hi));
  std::vector<size_t> keep;
  for (size_t i = 0; i < te.size(); ++i)
    if (te[i] >= lo - eps && te[i] <= hi + eps) keep.push_back(i);
  if (keep.size() < kMinSamples)
    throw InputError(emg_path + ": the time bases of " + emg_path + " (" + NumberText(te.front()) + ".." +
                     NumberText(te.back()) + " s), " + kinematics_path + " (" + NumberText(md.t().front()) + ".." +
                     NumberText(md.t().back()) + " s)" +
                     (moments_path.empty() ? "" : " and " + moments_path) + " share fewer than " +
                     std::to_string(kMinSamples) + " EMG samples");
  if (keep.size() < te.size())
    r.notes.push_back("EMG samples outside the other files' time range left out: " +
                      std::to_string(te.size() - keep.size()));
  for (size_t i : keep) r.t.push_back(te[i]);

  for (const auto& p : present) {
    const std::vector<double>& col = emg.Column(p.first, "EMG envelope");
    double peak = 0;
    for (size_t i : keep) peak = std::max(peak, std::isfinite(col[i]) ? col[i] : 0.0);
    std::vector<double> e;
    for (size_t i : keep) {
      if (!std::isfinite(col[i]) || col[i] < -kMaxUndershoot * peak)
        throw InputError(emg_path + ": line " + std::to_string(emg.line_of_row[i]) + ": channel '" + p.first +
                         "': envelope " + NumberText(col[i]) +
                         " (expected a finite, non-negative envelope; filter undershoot is tolerated down to -" +
                         NumberText(100 * kMaxUndershoot) + " % of the channel's peak " + NumberText(peak) + ")");
      e.push_back(col[i]);
    }
    r.channels.push_back(p.first);
    r.muscle.push_back(p.second);
    r.e.push_back(std::move(e));
  }
  for (int j = 0; j < 2; ++j) {
    r.q[j] = Interpolate(kin.t, kin.q[j], r.t);
    r.qd[j] = Interpolate(kin.t, kin.qd[j], r.t);
  }
  if (!ankle.empty()) r.q_ankle = Interpolate(ik.Time(), ankle, r.t), r.qd_ankle = Interpolate(ik.Time(), ankle_rate, r.t);
  if (!moments_path.empty()) {
    const std::string name[2] = {hip_coord + "_moment", knee_coord + "_moment"};
    for (int j = 0; j < 2; ++j) {
      const std::vector<double>& m = id.Column(name[j], "joint moment, N m");
      for (size_t i = 0; i < m.size(); ++i)
        if (!std::isfinite(m[i]) || std::abs(m[i]) > 1e4)
          throw InputError(moments_path + ": line " + std::to_string(id.line_of_row[i]) + ": moment " +
                           NumberText(m[i]) + " in column '" + name[j] + "' (expected a finite moment in N m)");
      r.tau[j] = Interpolate(id.Time(), m, r.t);
    }
  }
  return r;
}

}  // namespace exotwin
