// Synthetic recordings of the identification protocol (Hwang & Jeon 2015 sec. 3.1, 3.3) from the
// MuJoCo plant, for tests, benches and the scenario runner: the moving joint tracks an exciting
// trajectory, the other is held by PD at 90 deg (hip) or -90 deg (knee); computed-torque feed-forward
// with a deliberately wrong model + PD at 1 kHz; torque sensor and encoder models; CSV rows in the
// measured-data schema of DESIGN.md with tau = tau_S = -tau_R (HJ15 eq. 8). Every draw from the seed.
// Actuators saturate at +-150 N m (the MJCF ctrlrange); the held joint's torque beyond that is carried
// by a support (the seat under the thigh in the knee swing) and is not in its sensor reading.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "identification/excitation.h"
#include "formats/measured_data.h"
#include "model/lumped_params.h"

namespace exotwin {

// Torque sensor (EXOwheel, sec. 2): reading = quantize(-tau_R + offset + noise, resolution), saturated.
struct TorqueSensorModel {
  double resolution = 0.015;  // N m per LSB (0 = no quantization)
  double noise_sd = 0.024;    // N m, 1-sigma (0.02 % of the 120 N m full scale)
  double range = 120.0;       // N m, saturation
  double offset = 0.0;        // N m
};

// Burst of muscle activity (violates tau_M = 0): torque tau_M (N m) on the links and loud EMG.
struct ActivityBurst {
  double t0 = 0, t1 = 0;                      // s, within a trial
  Eigen::Vector2d tau_M = Eigen::Vector2d::Zero();  // N m (hip, knee), acting on the link
  double emg_rms = 1.0;                       // V after the amplifier, every channel
};

struct ProtocolOptions {
  int trials = 5;                // per configuration
  double trial_s = 40.0;         // s per trial
  double ff_scale = 0.8;         // feed-forward model = truth x ff_scale (0 = plain PD)
  Eigen::Vector2d kp{2000.0, 800.0}, kd{150.0, 50.0};  // N m/rad, N m s/rad (hip, knee)
  double hold_hip = M_PI / 2, hold_knee = -M_PI / 2;   // rad, held joint references
  HarmonicTrajectory hip_traj = DefaultExcitation(IdConfiguration::kHipSwing);
  HarmonicTrajectory knee_traj = DefaultExcitation(IdConfiguration::kKneeSwing);
  TorqueSensorModel sensor;
  int encoder_bits = 19;         // absolute encoder counts per revolution = 2^bits (0 = ideal)
  double emg_rms = 0.0;          // V, relaxed EMG (5 channels emg_GMAX..emg_GAS) when > 0
  std::vector<ActivityBurst> bursts;  // every trial, human only
  uint64_t seed = 1;
};

// Trials of the two configurations; each a MeasuredData as ReadMeasuredCsv would return it.
struct ProtocolData {
  std::vector<MeasuredData> knee, hip;
  // All files, knee trials first.
  std::vector<MeasuredData> All() const;
};

// Simulates the protocol on `truth` (exo alone when truth.human is empty: models/
// exowheel_exo_only.xml, else models/leg_exowheel.xml with truth.passive acting; the bodies carry
// RegroupForRealization(truth)). Throws InputError
// if truth has no realization, SimulationError on divergence. Deterministic for a given seed.
ProtocolData SimulateProtocol(const LegParams& truth, const ProtocolOptions& opt = {});

// The same combined system (exo + human, which alone sets the dynamics, HJ15 eq. 3) split so that both
// parts have a MuJoCo realization: when the human has none, an inertia dJ1 (kg m^2, the smallest
// multiple of 0.01 leaving a 0.05 kg m^2 margin) moves from the exo's J1 to the human's. Unchanged
// when both are realizable. Throws InputError if no dJ1 <= 2 kg m^2 works. Used for S3 of Table 4.
LegParams RegroupForRealization(const LegParams& p);

// The recording read by another torque sensor: tau_* regenerated from the cmd_* columns (the applied
// tau_R) as quantize(clamp(-cmd + offset + noise)), seeded. The plant's motion does not depend on the
// sensor (the PD uses the encoders), so this equals re-simulating with `sensor`. Throws InputError
// if the cmd_* columns are absent.
MeasuredData WithTorqueSensor(const MeasuredData& d, const TorqueSensorModel& sensor, uint64_t seed);

// Writes every trial as DIR/<prefix>knee_<i>.csv and DIR/<prefix>hip_<i>.csv (i = 1..trials).
void WriteProtocolCsv(const ProtocolData& data, const std::string& dir, const std::string& prefix = "");


}  // namespace exotwin
