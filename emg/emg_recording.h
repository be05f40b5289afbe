// A recording for the EMG-driven joint-torque model (emg-fit / emg-predict): EMG envelopes,
// joint angles and (optionally) joint moments from OpenSim storage files, mapped to the twin's hip and
// knee and put on the EMG file's time base.
//
// Conventions (DESIGN.md): angles rad, hip flexion positive, knee flexion negative (OpenSim's
// hip_flexion and knee_angle); moments N m, positive along the coordinate (OpenSim's inverse
// dynamics `<coordinate>_moment`); envelopes as recorded (normalized: fraction of the muscle's
// maximum).
#pragma once
#include <array>
#include <map>
#include <string>
#include <vector>

#include "sim/muscles.h"

namespace exotwin {

// Which EMG channel stands for which of the twin's muscles (sim/muscles.h: GMAX, VM, RF, ST, GAS; a
// muscle may have several channels, e.g. VM <- vas_med_r, vas_lat_r), and the coordinates to read.
struct MuscleMap {
  std::string source;                             // "default (OpenSim gait model names)" or the file
  bool from_file = false;                         // every channel a file names must be recorded
  std::vector<std::pair<std::string, Muscle>> channels;  // channel name -> muscle, in map order
  std::string hip_coordinate, knee_coordinate;    // e.g. hip_flexion_r; empty: from the side
  std::string ankle_coordinate;                   // e.g. ankle_angle_r; empty: ankle_angle_<side> if present
  // Strength bounds of the musculoskeletal form per channel (x F_max), narrowing the calibration's.
  std::map<std::string, std::array<double, 2>> strength_bounds;
};

// Strength bounds of the musculoskeletal form's calibration (x F_max; CEINMS-RT's calibration,
// StrengthCoefficients_ShapeFactor_TendonSlackLength_single): a map file may narrow them per channel.
constexpr double kStrengthLo = 0.5, kStrengthHi = 1.5;

// OpenSim gait models' names (gait2392 / gait2354 and Rajagopal 2015) of both sides.
MuscleMap DefaultMuscleMap();

// A muscle map file (YAML):
//   muscles:                      # twin muscle -> EMG channel names (GMAX, VM, RF, ST, GAS)
//     VM: [vas_med_r, vas_lat_r]
//     RF: [rect_fem_r]
//   coordinates: {hip: hip_flexion_r, knee: knee_angle_r, ankle: ankle_angle_r}   # optional; ankle optional
//   musculoskeletal:              # optional, per mapped channel (emg/emg_msk_model.h)
//     rect_fem_r: {joints: [hip, knee], strength: [0.6, 1.4]}
// `joints` must be the joints the channel's muscle path crosses (sim/muscles.h ActionSign: one force at
// each of them); `strength` (x F_max) must lie within [kStrengthLo, kStrengthHi].
// Throws InputError naming the file and key.
MuscleMap ReadMuscleMap(const std::string& path);

struct EmgRecording {
  std::string source;                       // the EMG file, for messages
  std::vector<double> t;                    // s, the EMG file's times inside the other files' range
  std::vector<std::string> channels;        // mapped channels present in the EMG file
  std::vector<Muscle> muscle;               // the twin's muscle of each channel
  std::vector<std::vector<double>> e;       // envelope of each channel
  std::vector<double> q[2], qd[2];          // [0] hip, [1] knee: rad, rad/s
  // Ankle angle (dorsiflexion positive, OpenSim's ankle_angle) and its rate, rad, rad/s: the
  // gastrocnemius' path (sim/musculotendon.h); empty when the kinematics file has no ankle column.
  std::vector<double> q_ankle, qd_ankle;
  std::vector<double> tau[2];               // N m; empty without a moments file
  std::vector<std::string> missing;         // twin muscles spanning hip or knee without a channel
  std::vector<std::string> notes;           // what was assumed (side, unused channels, trimmed ends)
  size_t size() const { return t.size(); }
  bool has_moments() const { return !tau[0].empty(); }
};

// Reads one recording. `moments_path` may be empty. The angles' velocities are derived as in Hwang &
// Jeon sec. 3.2 (formats/measured_data.h DeriveKinematics: zero-phase 2nd-order Butterworth at
// 20 Hz, central differences) on the kinematics file's own time base (the ankle angle's, where the file
// has it, alike); angles, velocities and moments
// are interpolated linearly onto the EMG times inside the range every file covers.
// Throws InputError (file, line or channel named) for: unreadable storage files, time bases that do
// not overlap, a map naming a channel the EMG file lacks (map from a file), no mapped channel at
// all, a NaN or infinite envelope or one below -10 % of its channel's peak (an envelope is
// non-negative; a filtered one may undershoot slightly), missing angle or moment columns, fewer than
// 20 common samples.
EmgRecording ReadEmgRecording(const std::string& emg_path, const std::string& kinematics_path,
                              const std::string& moments_path, const MuscleMap& map);

}  // namespace exotwin
