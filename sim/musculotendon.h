// Musculotendon units of the leg (issue 42): the path geometry of a published lower-limb model and
// a Hill-type muscle, for the EMG-driven musculoskeletal form (emg/emg_msk_model.h).
//
// Geometry: the sagittal paths of OpenSim's gait2392 model (Delp et al. 1990, IEEE TBME 37:757-767;
// Anderson & Pandy 1999), as distributed in OpenSim's leg6dof9musc example (a scaled gait2392 leg:
// pelvis, femur, tibia, calcaneus, with the knee's tibio-femoral translations as functions of the
// knee angle and the patella replaced by points of the quadriceps that move with the knee angle).
// Path points, via points active only over a range of the knee angle (OpenSim ConditionalPathPoint)
// and moving points (MovingPathPoint, natural cubic splines of the knee angle as OpenSim's
// SimmSpline) are taken as published; the hip rotates about the pelvis z axis (hip_flexion), the
// knee about the femur z axis with the translations (knee_angle), the talus about gait2392's oblique
// ankle axis (-0.10501355, -0.17402245, 0.97912632) in the tibia (ankle_angle, dorsiflexion positive;
// the gastrocnemius inserts on the calcaneus), subtalar at 0. Each of
// the twin's muscles (sim/muscles.h) has the path of one gait2392 actuator:
//   RF rect_fem; VM vas_int (Visser et al. 1990, Eur J Appl Physiol 61:453: the length changes of
//   the vastus lateralis and medialis heads adjacent to the intermedius follow it); ST bifemlh (the
//   long hamstring path; semimembranosus and biceps long head share origin and knee action); GAS
//   med_gas; GMAX glut_max2.
// The muscle-tendon length L(q) is the sum of the straight segments between the active points; the
// moment arm about a coordinate is r = -dL/dq (virtual work: positive when the muscle pulls along
// +q; OpenSim's definition), evaluated with the via points active at q.
//
// Conventions (DESIGN.md): q_hip flexion positive, q_knee flexion NEGATIVE (OpenSim's hip_flexion_r
// and knee_angle_r), rad; lengths m.
//
// Muscle: the Hill-type curves of Thelen 2003 (J Biomech Eng 125:70-77; OpenSim's Thelen2003Muscle),
// normalized by the optimal fibre length l_opt and the maximum isometric force F_max, with the
// fibre's pennation at constant thickness (l_m sin(phi) = l_opt sin(phi_0)):
//   active force-length  f_L(l) = exp(-(l - 1)^2 / gamma),  gamma = 0.45              (Thelen eq. 3)
//   passive force-length f_PE(l) = (exp(k_PE (l - 1) / e0) - 1) / (exp(k_PE) - 1),
//                        k_PE = 5, e0 = 0.6 (f_PE(1.6) = 1)                          (Thelen eq. 2)
//   force-velocity       Thelen eq. 6 at a f_L = 1 solved for the force, v in l_opt / s over
//                        v_max = 10 l_opt/s (lengthening positive):
//                        v <= 0: f_V = (1 + v/v_max) / (1 - v/(v_max A_f)), A_f = 0.25;
//                        v > 0:  f_V = (1 + c v/v_max F_len) / (1 + c v/v_max),
//                        c = (2 + 2/A_f) / (F_len - 1), F_len = 1.8
//   tendon force-strain  f_T(e) = F_toe (exp(k_toe e / e_toe) - 1) / (exp(k_toe) - 1) for e <= e_toe,
//                        k_lin (e - e_toe) + F_toe above; e0_T = 0.04 (f_T(e0_T) ~ 1), k_toe = 3,
//                        F_toe = 0.33, e_toe = 0.609 e0_T, k_lin = 1.712 / e0_T       (Thelen eq. 1)
//   force along the tendon F = F_max (a f_L f_V + f_PE) cos(phi).
// Tendon: rigid (l_m cos(phi) = L - l_ts; RigidTendonState) or elastic (Thelen's f_T in series with
// the fibre; ElasticTendonSeries). Against the elastic tendon in static equilibrium at activation 0.2
// over the angles of walking (tests/sim/musculotendon_test.cc TendonStretch...) the rigid one's force
// differs by up to 5 % for the vasti but 11-24 % for the long-tendon muscles (RF, hamstrings,
// gastrocnemius) at the ends of the range: the EMG form takes the elastic tendon.
#pragma once
#include <string>
#include <vector>

#include "sim/muscles.h"

namespace exotwin {

// Generic parameters of one gait2392 musculotendon actuator (Delp et al. 1990; the values of
// OpenSim's gait2392 as CEINMS-RT's LowerLimbModel lists them, subjectMTU.xml).
struct MusculotendonParams {
  std::string name;        // gait2392 actuator, e.g. "vas_lat_r"
  double f_max = 0;        // maximum isometric force, N
  double l_opt = 0;        // optimal fibre length, m
  double l_ts = 0;         // tendon slack length, m
  double pennation = 0;    // pennation angle at l_opt, rad
};

// The generic parameters of an EMG channel of OpenSim's gait models (vas_lat_r, vas_med_r, vas_int_r,
// rect_fem_r, semimem_r, semiten_r, bifemlh_r, med_gas_r, lat_gas_r, glut_max1..3_r and _l, Rajagopal's
// names too); false when the name is not one of them.
bool GenericMusculotendon(const std::string& channel, MusculotendonParams* p);
// The gait2392 actuator whose path twin muscle m takes (VM: vas_int, RF: rect_fem, ST: bifemlh, GAS:
// med_gas, GMAX: glut_max2). A channel's fibre and tendon lengths and pennation are its path's (the
// lengths belong to the path they share it with); its maximum isometric force is its own.
MusculotendonParams GenericMusculotendon(Muscle m);

// `generic` (a gait2392 actuator's values) with l_opt and l_ts scaled to twin muscle m's path: the
// ratio of this leg's path length to the generic gait2392 leg's at the anatomical pose (q = 0), as
// OpenSim's scale tool scales them (Delp et al. 2007).
MusculotendonParams ScaledMusculotendon(Muscle m, const MusculotendonParams& generic);

// Length and moment arms of twin muscle m's path at (q_hip, q_knee, q_ankle) (rad; q_ankle
// dorsiflexion positive, 0 where the recording has no ankle angle).
struct MtuKinematics {
  double length = 0;         // m
  double arm[2] = {0, 0};    // -dL/dq at the hip and the knee, m (0 where the path spans neither)
  double arm_ankle = 0;      // -dL/dq_ankle, m (the gastrocnemius: negative, a plantar flexor; else 0)
};
MtuKinematics MusculotendonKinematics(Muscle m, double q_hip, double q_knee, double q_ankle = 0);
// True when m's path crosses the ankle (GAS).
bool CrossesAnkle(Muscle m);
// "gait2392 rect_fem (Delp et al. 1990)", ...
std::string MusculotendonPathSource(Muscle m);

// Thelen 2003 curves (header).
double ActiveForceLength(double l_norm);
double PassiveForceLength(double l_norm);
double ForceVelocity(double v_norm);          // v in v_max units, lengthening positive
double TendonForceStrain(double strain);
constexpr double kMaxShorteningVelocity = 10.0;  // v_max, l_opt/s (Thelen 2003)

// State of a rigid-tendon Hill muscle at one instant.
struct HillState {
  double fibre_length = 0;     // normalized by l_opt
  double fibre_velocity = 0;   // normalized by v_max = 10 l_opt/s, lengthening positive
  double cos_pennation = 1;
  double active = 0;           // f_L f_V cos(phi): force per unit activation, per F_max
  double passive = 0;          // f_PE cos(phi), per F_max
};
// The rigid-tendon state at muscle-tendon length L (m) and lengthening velocity Ldot (m/s); the force is
// F_max (a active + passive).
HillState RigidTendonState(const MusculotendonParams& p, double L, double Ldot);

// States of an elastic-tendon Hill unit along a series (times t, s; path lengths L, m; activations a):
// Thelen 2003's fibre dynamics dl_m/dt = v_max l_opt f_V^-1(...) solved by backward Euler, i.e. at
// every sample the fibre length l_i at which the fibre's force at the velocity (l_i - l_{i-1}) / dt_i
// balances the tendon's:
//   (a f_L(l_i) f_V(v_i) + f_PE(l_i)) cos(phi_i) = f_T((L_i - l_m,i cos(phi_i) - l_ts) / l_ts)
// (per F_max on both sides: the state does not depend on F_max or a strength scaling it, CEINMS's
// convention). The first sample starts at the static equilibrium (ElasticEquilibriumFibreLength);
// a slack tendon (its force 0) leaves the fibre at the path's rigid length. Safeguarded Newton on a
// bracket, to 1e-10 l_opt.
struct TendonSeries {
  std::vector<double> fibre_length;    // normalized by l_opt
  std::vector<double> fibre_velocity;  // normalized by v_max, lengthening positive
  std::vector<double> force;           // tendon force per F_max (the unit's force is F_max force)
};
void ElasticTendonSeries(const MusculotendonParams& p, const std::vector<double>& t, const std::vector<double>& L,
                         const std::vector<double>& a, TendonSeries* out);

// The fibre length (normalized) of the elastic-tendon static equilibrium at activation a:
// F_max (a f_L + f_PE) cos(phi) = F_max f_T((L - l_m cos(phi) - l_ts) / l_ts), solved by bisection
// (the velocity factor 1, a slow movement). For measuring how far the rigid tendon is off.
double ElasticEquilibriumFibreLength(const MusculotendonParams& p, double L, double a);

}  // namespace exotwin
