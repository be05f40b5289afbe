#include "formats/opensim_kinematics.h"

#include <cctype>
#include <cmath>

#include "formats/number_text.h"
#include "core/error.h"

namespace exotwin {

bool IsOpenSimStoragePath(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".mot" || ext == ".sto";
}

LegCoordinates CoordinatesOfSide(const std::string& side, const std::string& where) {
  if (side != "r" && side != "l")
    throw InputError(where + ": side '" + side + "' (expected r or l: OpenSim's hip_flexion_r/knee_angle_r or _l)");
  return {"hip_flexion_" + side, "knee_angle_" + side};
}

MeasuredData KinematicsFromStorage(const StorageTable& table, const LegCoordinates& coords, size_t min_samples) {
  MeasuredData md;
  md.source = table.source;
  if (table.rows() < min_samples)
    throw InputError(table.source + ": " + std::to_string(table.rows()) + " rows of data, expected at least " +
                     std::to_string(min_samples));
  // No torque: tau_hip and tau_knee are empty columns (HasTorque).
  md.table.names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
  md.table.columns = {table.Time(), table.AngleRad(coords.hip), table.AngleRad(coords.knee), {}, {}};
  md.BindRequired();
  for (const auto* q : {&md.q_hip(), &md.q_knee()}) {
    const std::string& name = q == &md.q_hip() ? coords.hip : coords.knee;
    for (size_t i = 0; i < q->size(); ++i) {
      const std::string at = table.source + ": line " + std::to_string(table.line_of_row[i]) + ": ";
      if (!std::isfinite((*q)[i]) || std::abs((*q)[i]) > kMaxHumanJointAngle)
        throw InputError(at + "angle " + NumberText((*q)[i]) + " rad in column '" + name +
                         "' (expected a finite human joint angle)");
      if (q == &md.q_knee() && (*q)[i] > kMaxKneeHyperextension)
        throw InputError(at + "'" + name + "' = " + NumberText((*q)[i] * kDegPerRad) +
                         " deg: a knee extended beyond +15 deg; the twin reads knee_angle as gait2392 defines it "
                         "(0 straight, flexion negative), not flexion-positive (e.g. Rajagopal 2015): negate the "
                         "column");
    }
  }
  return md;
}

MeasuredData ReadOpenSimKinematics(const std::string& path, const std::string& side, size_t min_samples) {
  return KinematicsFromStorage(ReadStorage(path), CoordinatesOfSide(side, path), min_samples);
}

MeasuredData ReadMeasuredKinematics(const std::string& path, const std::string& map_path, const std::string& side,
                                    size_t min_samples, MapReport* report) {
  if (!IsOpenSimStoragePath(path)) return ReadMeasured(path, map_path, min_samples, report);
  if (!map_path.empty())
    throw InputError(map_path + ": a column map applies to a CSV, not to the OpenSim motion file " + path +
                     " (its coordinates are read by name: hip_flexion_<side>, knee_angle_<side>)");
  return ReadOpenSimKinematics(path, side, min_samples);
}

}  // namespace exotwin
