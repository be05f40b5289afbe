// Leg kinematics from OpenSim motion / storage files (.mot, .sto: inverse kinematics output, a gait
// lab's recorded coordinates) in the twin's conventions (DESIGN.md "OpenSim motion files").
//
// Mapping (OpenSim gait2392 / gait2354 coordinates, one side):
//   th1 (q_hip)  = hip_flexion_<side>: the thigh's flexion relative to the pelvis, 0 standing, flexion
//                  positive. The exoskeleton's hip axis is fixed to the pelvis frame, so the pelvis'
//                  own tilt is not added.
//   th2 (q_knee) = knee_angle_<side>: 0 straight, flexion negative (gait2392's range -120..10 deg).
// Angles are converted to rad from the header's inDegrees (yes: degrees, no: rad); a file that does
// not state it is rejected. A knee beyond +15 deg (hyperextension no knee reaches) is rejected as a
// flexion-positive knee (Rajagopal 2015's knee_angle_r, 0..120 deg), whose sign the file cannot tell.
#pragma once
#include <string>

#include "formats/column_map.h"
#include "formats/measured_data.h"
#include "formats/opensim_storage.h"
#include "core/units.h"

namespace exotwin {

// Most knee extension (rad, +15 deg) a knee_angle may show before the file is taken for a
// flexion-positive model.
inline constexpr double kMaxKneeHyperextension = 15.0 * kRadPerDeg;

// True when `path` names an OpenSim storage file (ends with .mot or .sto, any case).
bool IsOpenSimStoragePath(const std::string& path);

// The hip and knee coordinate names of one side: hip_flexion_<side>, knee_angle_<side>.
struct LegCoordinates {
  std::string hip, knee;
};
// False for kinematics alone (a motion file read by KinematicsFromStorage): tau_hip, tau_knee empty.
inline bool HasTorque(const MeasuredData& d) { return !d.tau_hip().empty(); }

// side "r" or "l" (throws InputError otherwise; `where` names the setting in the message).
LegCoordinates CoordinatesOfSide(const std::string& side, const std::string& where);

// The leg's angles of a storage table as MeasuredData: t (the `time` column), q_hip, q_knee (rad, the
// mapping above). No torque columns (tau_hip, tau_knee empty: HasTorque false), no other column.
// Throws InputError naming the file and the line for: a missing coordinate column, an unstated angle
// unit, a non-finite angle or one beyond +-kMaxHumanJointAngle, a knee beyond
// kMaxKneeHyperextension, fewer than `min_samples` rows.
MeasuredData KinematicsFromStorage(const StorageTable& table, const LegCoordinates& coords,
                                   size_t min_samples = 2);

// ReadStorage(path), then KinematicsFromStorage with the coordinates of `side`.
MeasuredData ReadOpenSimKinematics(const std::string& path, const std::string& side = "r",
                                   size_t min_samples = 2);

// The --measured argument of commands that need only the kinematics (predict, render-replay): an
// OpenSim .mot/.sto (IsOpenSimStoragePath; ReadOpenSimKinematics with `side`: no torque columns, and
// a column map cannot apply: `map_path` must be empty) or else a measured-data CSV (ReadMeasured with
// the map, `report` as there). Throws InputError as those do.
MeasuredData ReadMeasuredKinematics(const std::string& path, const std::string& map_path, const std::string& side,
                                    size_t min_samples = 20, MapReport* report = nullptr);

}  // namespace exotwin
