#include "sim/plant.h"

#include <mujoco/mjxmacro.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <algorithm>
#include <type_traits>

#include "core/data_dir.h"
#include "core/error.h"
#include "sim/mjcf_cache.h"
#include "sim/mjcf_text.h"
#include "sim/mujoco_messages.h"
#include "model/leg_dynamics.h"
#include "model/passive_torque.h"
#include "sim/realizability.h"

namespace exotwin {

namespace {

// The rotor of a dead band or strap without a human: this share of the exoskeleton's J of its joint
// (Plant::CarryEffects).
constexpr double kRotorInertiaFraction = 0.05;
// A strap's damping, as a share of its mode's critical damping: its start-up and impact transients
// decay within a few of its periods.
constexpr double kStrapDampingRatio = 0.5;

// The first real number of the model (options and every mjtNum array) that is not finite or is
// huge (|x| > 1e9, beyond any physical value in SI units here), as "field[i] = value"; "" if none.
// MuJoCo loads such models (armature="inf", gear="1e300") without complaint, and the twin then
// computes inf or nonsense silently.
std::string FirstBadModelValue(const mjModel* m) {
  auto bad = [](double v) { return !std::isfinite(v) || std::abs(v) > 1e9; };
  auto say = [](const char* name, long i, double v) {
    std::ostringstream os;
    os << name << "[" << i << "] = " << v;
    return os.str();
  };
#define X(type, name)                                                \
  if (bad(m->opt.name)) return say("option." #name, 0, m->opt.name);
  MJOPTION_FLOATS
#undef X
#define X(name, n)                                                   \
  for (long i = 0; i < (n); ++i)                                     \
    if (bad(m->opt.name[i])) return say("option." #name, i, m->opt.name[i]);
  MJOPTION_VECTORS
#undef X
  MJMODEL_POINTERS_PREAMBLE(m)
#define X(type, name, nr, nc)                                        \
  if constexpr (std::is_same_v<type, mjtNum>) {                      \
    for (long i = 0; i < static_cast<long>(m->nr) * (nc); ++i)       \
      if (bad(m->name[i])) return say(#name, i, m->name[i]);         \
  }
  MJMODEL_POINTERS
#undef X
  (void)nuser_body, (void)nuser_jnt, (void)nuser_geom, (void)nuser_site, (void)nuser_cam;
  (void)nuser_tendon, (void)nuser_actuator, (void)nuser_sensor, (void)nq, (void)nv, (void)na, (void)nu;
  (void)nmocap;
  return "";
}

}  // namespace

std::string ShippedModelPath(const std::string& file) {
  return DataPath("mjcf/" + file);
}

std::string ExowheelMjcfPath(bool with_human) {
  return ShippedModelPath(with_human ? "leg_exowheel.xml" : "exowheel_exo_only.xml");
}

void SetThighLength(mjModel* m, double L1, const std::string& suffix) {
  const int shank = mj_name2id(m, mjOBJ_BODY, ("exo_shank" + suffix).c_str());
  if (shank < 0) throw InputError("model has no body 'exo_shank" + suffix + "'");
  const int rotor = mj_name2id(m, mjOBJ_BODY, (RotorBodyName(1) + suffix).c_str());
  m->body_pos[3 * (rotor >= 0 ? rotor : shank) + 2] = -L1;
  // Visual only: stretch the thigh geoms to the new L1 (centred at mid-thigh, half-length L1/2).
  for (const char* g : {"human_thigh_geom", "exo_thigh_bar"}) {
    const int id = mj_name2id(m, mjOBJ_GEOM, (g + suffix).c_str());
    if (id < 0) continue;
    m->geom_pos[3 * id + 2] = -0.5 * L1;
    const int axis = m->geom_type[id] == mjGEOM_BOX ? 2 : 1;  // box half-height / capsule half-length
    m->geom_size[3 * id + axis] = 0.5 * L1;
  }
}

Plant::Plant(const std::string& mjcf_path) : path_(mjcf_path) {
  char err[1000] = "";
  m_ = LoadMjcfModel(mjcf_path, err, sizeof(err));
  if (!m_) throw InputError(mjcf_path + ": cannot load MJCF model: " + err);
  const std::string bad_value = FirstBadModelValue(m_);
  if (!bad_value.empty()) {
    mj_deleteModel(m_);
    throw InputError(mjcf_path + ": MJCF model value " + bad_value +
                     ", expected a finite number of magnitude at most 1e9");
  }
  if (err[0]) {
    mj_deleteModel(m_);
    throw InputError(mjcf_path + ": MJCF model loaded with a warning (treated as an error): " + err);
  }
  d_ = mj_makeData(m_);
  d_inv_ = mj_makeData(m_);
  try {
    BindModel();
  } catch (...) {
    mj_deleteData(d_);
    mj_deleteData(d_inv_);
    mj_deleteModel(m_);
    throw;
  }
  params_.L1 = -m_->body_pos[3 * exo_shank_ + 2];
}

void Plant::BindModel() {
  const std::string& mjcf_path = path_;
  exo_thigh_ = Body("exo_thigh", true);
  exo_shank_ = Body("exo_shank", true);
  human_thigh_ = Body("human_thigh", false);
  human_shank_ = Body("human_shank", false);
  if ((human_thigh_ < 0) != (human_shank_ < 0))
    throw InputError(mjcf_path + ": needs both human_thigh and human_shank bodies or neither");
  const int hip = mj_name2id(m_, mjOBJ_JOINT, "hip");
  const int knee = mj_name2id(m_, mjOBJ_JOINT, "knee");
  const int internal = (structure_.kind[0] != InternalHinge::kNone) + (structure_.kind[1] != InternalHinge::kNone);
  if (hip < 0 || knee < 0 || m_->jnt_type[hip] != mjJNT_HINGE || m_->jnt_type[knee] != mjJNT_HINGE ||
      m_->nv != 2 + internal)
    throw InputError(mjcf_path + ": expected exactly two hinge joints named 'hip' and 'knee'");
  hip_dof_ = m_->jnt_dofadr[hip];
  knee_dof_ = m_->jnt_dofadr[knee];
  hip_jnt_ = hip;
  knee_jnt_ = knee;
  q_adr_[0] = m_->jnt_qposadr[hip];
  q_adr_[1] = m_->jnt_qposadr[knee];
  for (int j = 0; j < 2; ++j) {
    in_jnt_[j] = in_q_[j] = in_v_[j] = rotor_body_[j] = -1;
    if (structure_.kind[j] == InternalHinge::kNone) continue;
    in_jnt_[j] = mj_name2id(m_, mjOBJ_JOINT, InternalHingeName(j, structure_).c_str());
    if (in_jnt_[j] < 0) throw InputError(mjcf_path + ": the internal hinge did not compile");
    in_q_[j] = m_->jnt_qposadr[in_jnt_[j]];
    in_v_[j] = m_->jnt_dofadr[in_jnt_[j]];
    if (structure_.kind[j] == InternalHinge::kRotor) rotor_body_[j] = Body(RotorBodyName(j).c_str(), true);
  }
  for (int j = 0; j < 2; ++j) {
    const int dof = j == 0 ? hip_dof_ : knee_dof_, jnt = j == 0 ? hip : knee;
    base_frictionloss_[j] = m_->dof_frictionloss[dof];
    base_solref_[j] = m_->dof_solref[mjNREF * dof];
    base_damping_[j] = m_->dof_damping[dof];
    base_armature_[j] = m_->dof_armature[dof];
    base_stiffness_[j] = m_->jnt_stiffness[jnt];
    base_springref_[j] = m_->qpos_spring[m_->jnt_qposadr[jnt]];
  }
  if (m_->nu != 2)
    throw InputError(mjcf_path + ": expected two torque actuators (hip, knee), found " + std::to_string(m_->nu));
  // Step() writes the joint torques into ctrl[0] (hip) and ctrl[1] (knee): plain motors, gear 1.
  for (int i = 0; i < 2; ++i) {
    const int joint = i == 0 ? hip : knee;
    if (m_->actuator_trntype[i] != mjTRN_JOINT || m_->actuator_trnid[2 * i] != joint ||
        m_->actuator_gear[6 * i] != 1.0 || m_->actuator_gaintype[i] != mjGAIN_FIXED ||
        m_->actuator_gainprm[mjNGAIN * i] != 1.0 || m_->actuator_biastype[i] != mjBIAS_NONE) {
      const char* name = mj_id2name(m_, mjOBJ_ACTUATOR, i);
      throw InputError(mjcf_path + ": actuator " + std::to_string(i) + " ('" + (name ? name : "") +
                       "'): expected a <motor> on joint '" + (i == 0 ? "hip" : "knee") +
                       "' with gear 1 (ctrl is the joint torque in N m)");
    }
  }
}

void Plant::Rebuild(const InternalJoints& structure) {
  mjModel* m = nullptr;
  if (structure.any()) {
    std::string variant = "internal hinges";  // one per structure
    for (int j = 0; j < 2; ++j)
      variant += " " + std::to_string(static_cast<int>(structure.kind[j])) + (structure.backlash[j] ? "b" : "s");
    m = LoadMjcfVariant(path_, variant, [&] {
      return LoadMjcfText(path_, AddInternalJoints(ReadMjcfText(path_), path_, structure), "the model with internal hinges");
    });
  } else {
    char err[1000] = "";
    m = LoadMjcfModel(path_, err, sizeof(err));
    if (!m) throw InputError(path_ + ": cannot load MJCF model: " + err);
  }
  mj_deleteData(d_);
  mj_deleteData(d_inv_);
  mj_deleteModel(m_);
  m_ = m;
  d_ = mj_makeData(m_);
  d_inv_ = mj_makeData(m_);
  structure_ = structure;
  BindModel();
  ApplyFreedom();
}

Plant::~Plant() {
  mj_deleteData(d_);
  mj_deleteData(d_inv_);
  mj_deleteModel(m_);
}

int Plant::Body(const char* name, bool required) const {
  const int id = mj_name2id(m_, mjOBJ_BODY, name);
  if (id < 0 && required) throw InputError(path_ + ": MJCF model has no body named '" + name + "'");
  return id;
}

namespace {

// Writes one segment (in its joint frame: x forward at q = 0, z along the link upwards) into a body.
// Sagittal inertia about the hinge axis (y); the two others chosen so the triangle inequality holds.
void WriteBody(mjModel* m, int body, const SegmentInertial& s) {
  m->body_mass[body] = s.mass;
  m->body_ipos[3 * body + 0] = s.b;
  m->body_ipos[3 * body + 1] = 0.0;
  m->body_ipos[3 * body + 2] = -s.a;
  m->body_inertia[3 * body + 0] = s.Iz;        // about x (frontal axis)
  m->body_inertia[3 * body + 1] = s.Iz;        // about y (hinge axis): the sagittal Iz
  m->body_inertia[3 * body + 2] = 0.5 * s.Iz;  // about the long axis
  m->body_iquat[4 * body + 0] = 1.0;
  m->body_iquat[4 * body + 1] = m->body_iquat[4 * body + 2] = m->body_iquat[4 * body + 3] = 0.0;
}

// Realizes exo and human so that their sum is exactly params.Total(). When the human set alone has no
// physical realization but the combined system has one (Table 4's S3: its m2 window is empty by
// 0.1 kg), J1 is moved from the exoskeleton's thigh to the human's: just enough for a plausible human
// thigh (m2 = 1.1 x its lower bound, thigh CoM at L1/2 with the inertia of a uniform rod). Only J1
// moves and the sum is unchanged, so the joint torques are exactly those of the printed parameters.
// Throws InputError when no such split exists.
void SplitRealization(const LegParams& params, SystemRealization* exo, SystemRealization* human) {
  LumpedParams h = *params.human, e = params.exo;
  std::string why;
  if (!IsRealizable(h, params.L1, &why) && h.J2 > 0) {
    const double L1 = params.L1;
    const double m2 = 1.1 * (h.X2 * h.X2 + h.Y2 * h.Y2) / h.J2;
    const double mx = std::abs(h.X1 - m2 * L1);
    const double m1 = std::max(2.0 * mx / L1, 1.0);
    const double needed = h.J2 + m2 * L1 * L1 + (mx * mx + h.Y1 * h.Y1) / m1 + m1 * L1 * L1 / 12.0;
    const double shift = needed - h.J1;
    h.J1 += shift;
    h.m1 = m1;
    h.m2 = m2;
    e.J1 -= shift;
    if (!IsRealizable(e, L1, nullptr))
      throw InputError("human: lumped parameters have no physically consistent realization (" + why +
                       "), and the exoskeleton cannot lend the thigh inertia needed");
  }
  *human = RealizeLumped(h, params.L1, "human");
  *exo = RealizeLumped(e, params.L1, "exo");
}

}  // namespace

void Plant::SetParams(const LegParams& params) {
  if (!(params.L1 > 0.1 && params.L1 < 1.0))
    throw InputError("L1: expected a thigh length in (0.1, 1.0) m, got " + std::to_string(params.L1));
  if (params.human && human_thigh_ < 0)
    throw InputError(path_ + ": the parameter set has a human: block but the model has no human bodies");
  WriteRealization(params);
  params_ = params;
  has_params_ = true;
  mj_forward(m_, d_);
}

void Plant::WriteRealization(const LegParams& params) {
  // A rotor body (at its hinge's axis, mass kRotorMass, inertia J_r about the axis) turns with the
  // measured joint; the exoskeleton's lumped parameters give up what it adds (HJ15 eq. 4: J1, and for
  // the knee rotor, L1 below the hip, J2 and X1 as well), so that with the internal hinges held the
  // system is exactly the rigid one (M, gravity).
  constexpr double kRotorMass = 1e-6;  // kg: MuJoCo needs a mass for a body with a joint
  LegParams p = params;
  double rotor[2] = {0, 0};
  for (int j = 0; j < 2; ++j) {
    if (structure_.kind[j] != InternalHinge::kRotor) continue;
    rotor[j] = kRotorInertiaFraction * (j == 0 ? p.exo.J1 : p.exo.J2);
    if (!structure_.backlash[j]) rotor[j] = std::max(rotor[j], 4 * fx_.compliance[j] * timestep() * timestep());
  }
  p.exo.J1 -= rotor[0] + rotor[1] + kRotorMass * (rotor[1] > 0) * params.L1 * params.L1;
  p.exo.J2 -= rotor[1];
  p.exo.X1 -= kRotorMass * (rotor[1] > 0) * params.L1;
  SystemRealization exo, human;
  auto realize = [&] {
    if (!p.human) {
      exo = RealizeLumped(p.exo, p.L1, "exo");
    } else {
      SplitRealization(p, &exo, &human);
    }
  };
  try {
    try {
      realize();
    } catch (const InputError&) {
      // The dynamics depend on the lumped parameters alone: when the exoskeleton's given masses leave
      // no room for the rotor, its masses are chosen instead (m1 = m2 = 0, sim/realization.h).
      if ((rotor[0] == 0 && rotor[1] == 0) || (p.exo.m1 == 0 && p.exo.m2 == 0)) throw;
      p.exo.m1 = p.exo.m2 = 0;
      realize();
    }
  } catch (const InputError& e) {
    if (rotor[0] == 0 && rotor[1] == 0) throw;
    std::ostringstream os;
    os << e.what() << " once the rotor inertia " << rotor[0] << " / " << rotor[1]
       << " kg m^2 (hip / knee) of the backlash or compliance hinge is taken out of the exoskeleton's segments";
    throw InputError(os.str());
  }
  m_->opt.gravity[0] = m_->opt.gravity[1] = 0.0;
  m_->opt.gravity[2] = -params.g;
  SetThighLength(m_, params.L1);
  WriteBody(m_, exo_thigh_, exo.thigh);
  WriteBody(m_, exo_shank_, exo.lower_leg);
  if (human_thigh_ >= 0) {
    // Without a human the welded human bodies carry a negligible mass (MuJoCo needs mass > 0 only
    // for bodies with joints; these have none).
    SegmentInertial none{0.0, 0.0, 0.0, 0.0};
    WriteBody(m_, human_thigh_, params.human ? human.thigh : none);
    WriteBody(m_, human_shank_, params.human ? human.lower_leg : none);
  }
  for (int j = 0; j < 2; ++j) {
    rotor_inertia_[j] = rotor[j];
    if (rotor_body_[j] >= 0) WriteBody(m_, rotor_body_[j], {kRotorMass, 0.0, 0.0, rotor[j]});
  }
  mj_setConst(m_, d_);
}

Eigen::Vector2d Plant::InverseDynamics(const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                                       const Eigen::Vector2d& qdd) {
  mjData* d = d_inv_;
  // Internal hinges held at 0 (a dead band's centre, a strap unloaded): the rigid system.
  for (int j = 0; j < 2; ++j) {
    const int v = j == 0 ? hip_dof_ : knee_dof_;
    d->qpos[q_adr_[j]] = q[j];
    d->qvel[v] = qd[j];
    d->qacc[v] = qdd[j];
    if (in_jnt_[j] >= 0) d->qpos[in_q_[j]] = d->qvel[in_v_[j]] = d->qacc[in_v_[j]] = 0.0;
  }
  const int saved = m_->opt.disableflags;
  m_->opt.disableflags |= mjDSBL_CONSTRAINT;  // rigid-body inverse dynamics, no limit forces
  mj_inverse(m_, d);
  m_->opt.disableflags = saved;
  Eigen::Vector2d tau(d->qfrc_inverse[hip_dof_], d->qfrc_inverse[knee_dof_]);
  // The carried effects are not the rigid twin's: mj_inverse counted their armature (in M) and
  // their damping and spring (minus qfrc_passive).
  if (!fx_.link_empty())
    for (int j = 0; j < 2; ++j)
      tau[j] -= fx_.armature[j] * qdd[j] + fx_.damping[j] * qd[j] + fx_.stiffness[j] * (q[j] - fx_.springref[j]);
  if (hip_held_) tau[0] -= kHeldHipArmature * qdd[0];  // the rigid twin's hip (HoldHip's armature is no body's)
  if (params_.human) tau += PassiveElasticTorque(params_.passive, q);
  return tau;
}

void Plant::CarryEffects(const PlantEffects& fx) {
  const InternalJoints structure = InternalJointsOf(fx);
  if (structure.any() && !has_params_)
    throw std::logic_error("Plant::CarryEffects: backlash or series compliance before SetParams");
  const PlantEffects before = fx_;
  fx_ = fx;
  try {
    const bool rebuilt = !(structure == structure_);
    if (rebuilt) Rebuild(structure);
    if ((rebuilt || structure.any()) && has_params_) WriteRealization(params_);
    strap_omega_[0] = strap_omega_[1] = 0;
    for (int j = 0; j < 2; ++j) {
      if (in_jnt_[j] < 0) continue;
      const int jnt = in_jnt_[j], dof = in_v_[j];
      if (structure_.backlash[j]) {
        // The dead band's flanks: limit constraints with MuJoCo's solref time constant at its safe
        // minimum, 2 steps (as frictionloss), critically damped (MuJoCo XML reference, solref/solimp).
        m_->jnt_range[2 * jnt] = -0.5 * fx.backlash[j];
        m_->jnt_range[2 * jnt + 1] = 0.5 * fx.backlash[j];
        m_->jnt_solref[mjNREF * jnt] = 2 * m_->opt.timestep;
        m_->jnt_solref[mjNREF * jnt + 1] = 1.0;
        // A hard flank: impedance 0.99 .. 0.999 (MuJoCo's default 0.9 .. 0.95 lets the load press the
        // link 5x deeper past the flank, ~2.6e-4 rad on the development rig's knee at rest).
        m_->jnt_solimp[mjNIMP * jnt] = 0.99;
        m_->jnt_solimp[mjNIMP * jnt + 1] = 0.999;
        continue;
      }
      // The strap: stiffness k about springref 0, damped at kStrapDampingRatio of its mode's critical
      // damping 2 sqrt(k J), J the reduced inertia of the two sides (the rotor against the chain; the
      // exoskeleton's against the human's lower leg).
      const double k = fx.compliance[j];
      double J = rotor_inertia_[j];
      if (structure_.kind[j] == InternalHinge::kHuman) {
        const double Je = params_.exo.J2, Jh = params_.human->J2;
        J = Je * Jh / (Je + Jh);
      }
      const double omega = std::sqrt(k / J);
      if (omega * m_->opt.timestep > 0.5) {
        std::ostringstream os;
        os << path_ << ": a series compliance of " << k << " N m/rad at the " << (j == 0 ? "hip" : "knee")
           << " oscillates at " << omega << " rad/s against " << J << " kg m^2: too fast for the "
           << m_->opt.timestep << " s step (expected at most " << 0.5 / m_->opt.timestep << " rad/s)";
        throw InputError(os.str());
      }
      strap_omega_[j] = omega;
      m_->jnt_stiffness[jnt] = k;
      m_->qpos_spring[in_q_[j]] = 0.0;
      m_->dof_damping[dof] = 2 * kStrapDampingRatio * std::sqrt(k * J);
      if (structure_.kind[j] == InternalHinge::kHuman)  // the hinge at the knee: human_shank's origin
        for (int c = 0; c < 3; ++c) m_->jnt_pos[3 * jnt + c] = -m_->body_pos[3 * human_shank_ + c];
    }
  } catch (...) {
    fx_ = before;
    throw;
  }
  if (!before.link_empty() || !fx.link_empty()) {
    for (int j = 0; j < 2; ++j) {
      const int dof = j == 0 ? hip_dof_ : knee_dof_, jnt = j == 0 ? hip_jnt_ : knee_jnt_;
      m_->dof_frictionloss[dof] = base_frictionloss_[j] + fx.frictionloss[j];
      // The frictionloss constraint's time constant: the shortest MuJoCo integrates safely (2 steps),
      // so that its stiction zone around qd = 0 is as narrow as the step allows.
      m_->dof_solref[mjNREF * dof] =
          fx.frictionloss[j] > 0 || fx.has_friction_term(j) ? 2 * m_->opt.timestep : base_solref_[j];
      m_->dof_damping[dof] = base_damping_[j] + fx.damping[j];
      m_->dof_armature[dof] = base_armature_[j] + fx.armature[j] + (j == 0 && hip_held_ ? kHeldHipArmature : 0.0);
      if (fx.stiffness[j] != 0) {
        m_->jnt_stiffness[jnt] = base_stiffness_[j] + fx.stiffness[j];
        m_->qpos_spring[m_->jnt_qposadr[jnt]] = fx.springref[j];
      } else {
        m_->jnt_stiffness[jnt] = base_stiffness_[j];
        m_->qpos_spring[m_->jnt_qposadr[jnt]] = base_springref_[j];
      }
    }
  }
  if (structure_.any()) mj_setConst(m_, d_);
  mj_forward(m_, d_);
}

void Plant::FreeJointsAndTorque() {
  free_ = true;
  ApplyFreedom();
}

void Plant::ApplyFreedom() {
  if (!free_) return;
  m_->opt.disableflags |= mjDSBL_CLAMPCTRL;
  // The measured joints' limits off; a dead band's limits stay.
  m_->jnt_limited[hip_jnt_] = m_->jnt_limited[knee_jnt_] = 0;
}

Eigen::Vector2d Plant::internal_q() const {
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (int j = 0; j < 2; ++j)
    if (in_q_[j] >= 0) x[j] = d_->qpos[in_q_[j]];
  return x;
}

void Plant::HoldHip() {
  hip_held_ = true;
  m_->dof_armature[hip_dof_] = base_armature_[0] + fx_.armature[0] + kHeldHipArmature;
  d_->qpos[m_->jnt_qposadr[hip_jnt_]] = 0;
  d_->qvel[hip_dof_] = 0;
  mj_forward(m_, d_);
}

void Plant::Reset(const Eigen::Vector2d& q, const Eigen::Vector2d& qd, double t, const Eigen::Vector2d* qdd) {
  ClearMujocoWarning();
  mj_resetData(m_, d_);
  last_qdd_.setZero();
  for (int j = 0; j < 2; ++j) {
    d_->qpos[q_adr_[j]] = q[j];
    d_->qvel[j == 0 ? hip_dof_ : knee_dof_] = qd[j];
  }
  if (structure_.any()) {
    LegParams rigid = params_;
    rigid.effects.clear();
    const Eigen::Vector2d tau = ActuatorTorque(rigid, q, qd, qdd ? *qdd : Eigen::Vector2d::Zero());
    LegParams strapped = rigid;  // a strap carries the subject's passive moment too (CompliantPartTorque)
    for (const Effect& e : fx_.applied)
      if (FamilyOf(e).carrier == PlantCarrier::kSubjectForce) strapped.effects.push_back(e);
    for (int j = 0; j < 2; ++j) {
      if (in_q_[j] < 0) continue;
      d_->qpos[in_q_[j]] =
          structure_.backlash[j]
              ? -0.5 * fx_.backlash[j] * std::tanh(tau[j] / kBacklashTorqueWidth)
              : CompliantAngle(strapped, j, fx_.compliance[j], q, qd, qdd ? *qdd : Eigen::Vector2d::Zero())[j] - q[j];
    }
  }
  if (hip_held_) d_->qpos[m_->jnt_qposadr[hip_jnt_]] = 0, d_->qvel[hip_dof_] = 0;
  d_->time = t;
  mj_forward(m_, d_);
  CheckDivergence("reset");
}

double Plant::InternalSettlingTime() const {
  // A strap's mode decays as exp(-zeta omega t), zeta = kStrapDampingRatio: 5 / (zeta omega) leaves
  // e^-5 (< 1 %) of a start's error.
  double t = 0;
  for (int j = 0; j < 2; ++j)
    if (in_q_[j] >= 0 && !structure_.backlash[j] && strap_omega_[j] > 0)
      t = std::max(t, 5.0 / (kStrapDampingRatio * strap_omega_[j]));
  return t;
}

void Plant::Restate(const Eigen::Vector2d& q, const Eigen::Vector2d& qd, double t) {
  ClearMujocoWarning();
  for (int j = 0; j < 2; ++j) {
    const int dof = j == 0 ? hip_dof_ : knee_dof_;
    if (in_q_[j] >= 0 && structure_.backlash[j]) {
      // A dead band's link keeps its own angle and rate (the hinge's coordinates are relative to the
      // measured joint): moving the driven side does not carry the link along, except by the flank it
      // would pass, which pushes the link with it. (Carried along, the rotor's own acceleration within
      // each step, ~tau / J_r in the band, would be handed to the link as a velocity change.)
      double& iq = d_->qpos[in_q_[j]];
      double& iv = d_->qvel[in_v_[j]];
      iq -= q[j] - d_->qpos[q_adr_[j]];
      iv -= qd[j] - d_->qvel[dof];
      const double half = 0.5 * fx_.backlash[j];
      if (iq > half) iq = half, iv = std::min(iv, 0.0);
      if (iq < -half) iq = -half, iv = std::max(iv, 0.0);
    }  // a strap's follower keeps its deflection and deflection rate: it moves with the driven side
    d_->qpos[q_adr_[j]] = q[j];
    d_->qvel[dof] = qd[j];
  }
  if (hip_held_) d_->qpos[m_->jnt_qposadr[hip_jnt_]] = 0, d_->qvel[hip_dof_] = 0;
  d_->time = t;
  mj_forward(m_, d_);
  CheckDivergence("restate");
}

void Plant::Step(const Eigen::Vector2d& tau_R, const Eigen::Vector2d& tau_ext) {
  if (!std::isfinite(tau_R[0]) || !std::isfinite(tau_R[1]) || !std::isfinite(tau_ext[0]) ||
      !std::isfinite(tau_ext[1]))
    throw SimulationError(d_->time, "non-finite torque command");
  // On the part behind the internal hinges (at the followers' angles q + internal_q): tau_ext, P and the
  // subject's passive_moment.
  Eigen::Vector2d applied = tau_ext;
  const Eigen::Vector2d q_follower = structure_.any() ? q() + internal_q() : q();
  if (params_.human) applied -= PassiveElasticTorque(params_.passive, q_follower);
  if (!fx_.applied.empty()) applied += fx_.SubjectPassiveForce(q_follower);
  for (int j = 0; j < 2; ++j)
    if (in_v_[j] >= 0) d_->qfrc_applied[in_v_[j]] = applied[j];
  if (!fx_.applied.empty()) applied += fx_.AppliedForce(q(), qd(), last_qdd_, tau_R, d_->time - term_t0_);
  if (!fx_.friction_terms.empty()) {
    // Friction-like terms: this step's friction bound at the state and the applied actuator torque.
    EffectState s;
    s.q = q(), s.qd = qd(), s.qdd = last_qdd_, s.g = fx_.g, s.tau_R = tau_R, s.t = d_->time - term_t0_;
    double bound[2];
    Eigen::Vector2d force;
    fx_.FrictionTermBounds(s, bound, &force);
    m_->dof_frictionloss[hip_dof_] = base_frictionloss_[0] + fx_.frictionloss[0] + bound[0];
    m_->dof_frictionloss[knee_dof_] = base_frictionloss_[1] + fx_.frictionloss[1] + bound[1];
    applied += force;
  }
  d_->qfrc_applied[hip_dof_] = applied[0];
  d_->qfrc_applied[knee_dof_] = applied[1];
  // Actuators are plain motors with gear 1: ctrl is the joint torque (clamped by ctrlrange).
  d_->ctrl[0] = tau_R[0];
  d_->ctrl[1] = tau_R[1];
  ClearMujocoWarning();
  mj_step(m_, d_);
  if (hip_held_) d_->qpos[m_->jnt_qposadr[hip_jnt_]] = 0, d_->qvel[hip_dof_] = 0;
  last_qdd_ = qdd();
  CheckDivergence("step");
}

void Plant::CheckDivergence(const char* where) {
  // A warning MuJoCo counts (d_->warning) also raises its text; the text alone: a warning MuJoCo does
  // not count (the solver's "Linesearch objective is not convex").
  const std::string text = TakeMujocoWarning();
  for (int i = 0; i < mjNWARNING; ++i) {
    if (d_->warning[i].number > 0) {
      static const char* kNames[mjNWARNING] = {"inertia",  "contact full", "constraint full",
                                               "vgeom full", "bad qpos",   "bad qvel",
                                               "bad qacc",   "bad ctrl"};
      throw SimulationError(d_->time, std::string("MuJoCo warning '") + kNames[i] + "' in " + where);
    }
  }
  if (!text.empty()) throw SimulationError(d_->time, "MuJoCo warning '" + text + "' in " + where);
  for (int i = 0; i < m_->nq; ++i)
    if (!std::isfinite(d_->qpos[i]) || !std::isfinite(d_->qvel[i]))
      throw SimulationError(d_->time, std::string("non-finite state in ") + where);
}

Eigen::Vector2d Plant::q() const { return {d_->qpos[q_adr_[0]], d_->qpos[q_adr_[1]]}; }
Eigen::Vector2d Plant::qd() const { return {d_->qvel[hip_dof_], d_->qvel[knee_dof_]}; }
Eigen::Vector2d Plant::qdd() const { return {d_->qacc[hip_dof_], d_->qacc[knee_dof_]}; }
double Plant::time() const { return d_->time; }
double Plant::timestep() const { return m_->opt.timestep; }

}  // namespace exotwin
