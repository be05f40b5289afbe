// HAL-3 seated-knee plant: see hal3_plant.h.
#include "sim/hal3_plant.h"

#include <mujoco/mujoco.h>

#include <cmath>

#include "core/error.h"
#include "sim/mjcf_cache.h"
#include "sim/mujoco_messages.h"
#include "sim/subjects.h"

namespace exotwin {

Hal3PlantParams Hal3ParamsForSubject(const Subject& s) {
  Hal3PlantParams p;
  const double L2 = s.L2 > 0 ? s.L2 : 0.43;
  const double W = s.weight > 0 ? s.weight : 70.0;
  p.human.mass = 0.061 * W;  // Winter's Dempster "Foot leg" row (sim/anthropometry.cc)
  p.human.com = 0.606 * L2;
  const double rg = 0.416 * L2;
  p.human.Icm = p.human.mass * rg * rg;
  return p;
}

Hal3Plant::Hal3Plant(const std::string& mjcf_path) : path_(mjcf_path) {
  char err[1000] = "";
  m_ = LoadMjcfModel(mjcf_path, err, sizeof(err));
  if (!m_) throw InputError(mjcf_path + ": cannot load MJCF model: " + err);
  d_ = mj_makeData(m_);
  const int knee = mj_name2id(m_, mjOBJ_JOINT, "knee");
  hal_body_ = mj_name2id(m_, mjOBJ_BODY, "hal_shank");
  human_body_ = mj_name2id(m_, mjOBJ_BODY, "human_shank");
  std::string why;
  if (knee < 0 || m_->jnt_type[knee] != mjJNT_HINGE || m_->nv != 1)
    why = "expected exactly one hinge joint named 'knee'";
  else if (hal_body_ < 0 || human_body_ < 0)
    why = "expected bodies 'hal_shank' and 'human_shank'";
  else if (m_->nu != 1 || m_->actuator_trntype[0] != mjTRN_JOINT || m_->actuator_trnid[0] != knee ||
           m_->actuator_gear[0] != 1.0 || m_->actuator_biastype[0] != mjBIAS_NONE)
    why = "expected one <motor> with gear 1 on joint 'knee'";
  if (!why.empty()) {
    mj_deleteData(d_);
    mj_deleteModel(m_);
    throw InputError(mjcf_path + ": " + why);
  }
  dof_ = m_->jnt_dofadr[knee];
  SetParams(p_);
}

Hal3Plant::~Hal3Plant() {
  mj_deleteData(d_);
  mj_deleteModel(m_);
}

namespace {
// Link hanging along -z of its body frame; inertia about the hinge axis (y) is Icm.
void WriteLink(mjModel* m, int body, const HalLinkInertial& s) {
  m->body_mass[body] = s.mass;
  m->body_ipos[3 * body + 0] = 0.0;
  m->body_ipos[3 * body + 1] = 0.0;
  m->body_ipos[3 * body + 2] = -s.com;
  m->body_inertia[3 * body + 0] = s.Icm;
  m->body_inertia[3 * body + 1] = s.Icm;
  m->body_inertia[3 * body + 2] = 0.2 * s.Icm;  // long axis; irrelevant for the hinge
  m->body_iquat[4 * body + 0] = 1.0;
  m->body_iquat[4 * body + 1] = m->body_iquat[4 * body + 2] = m->body_iquat[4 * body + 3] = 0.0;
}
}  // namespace

void Hal3Plant::SetParams(const Hal3PlantParams& p) {
  for (const HalLinkInertial* l : {&p.human, &p.hal})
    if (!(l->mass > 0 && l->Icm > 0 && l->com >= 0 && l->com < 1.0))
      throw InputError(path_ + ": HAL-3 plant: link needs mass > 0, Icm > 0, 0 <= com < 1 m");
  if (!(p.armature >= 0 && p.R >= 0 && p.C >= 0 && p.coulomb_eps > 0 && p.g > 0))
    throw InputError(path_ + ": HAL-3 plant: expected armature, R, C >= 0, coulomb_eps, g > 0");
  WriteLink(m_, hal_body_, p.hal);
  WriteLink(m_, human_body_, p.human);
  m_->dof_armature[dof_] = p.armature;
  m_->dof_damping[dof_] = 0.0;  // R is applied explicitly so the strain gauge sees it exactly
  m_->opt.gravity[0] = m_->opt.gravity[1] = 0.0;
  m_->opt.gravity[2] = -p.g;
  mj_setConst(m_, d_);
  p_ = p;
  mj_forward(m_, d_);
}

void Hal3Plant::Reset(double th, double thd, double t) {
  ClearMujocoWarning();
  mj_resetData(m_, d_);
  d_->qpos[0] = th;
  d_->qvel[0] = thd;
  d_->time = t;
  mj_forward(m_, d_);
  thdd_ = tau_int_ = tau_applied_ = 0;
  CheckDivergence("reset");
}

void Hal3Plant::Step(double tau_motor, double tau_muscle) {
  if (!std::isfinite(tau_motor) || !std::isfinite(tau_muscle))
    throw SimulationError(d_->time, "non-finite torque (motor or muscle)");
  const double th0 = d_->qpos[0], thd0 = d_->qvel[0];
  const double friction = p_.R * thd0 + p_.C * std::tanh(thd0 / p_.coulomb_eps);
  d_->qfrc_applied[dof_] = tau_muscle - friction;
  d_->ctrl[0] = tau_motor;
  ClearMujocoWarning();
  mj_step(m_, d_);
  CheckDivergence("step");
  thdd_ = d_->qacc[dof_];
  tau_applied_ = d_->actuator_force[0];
  // HAL side of HKS05 eq. 15 solved for the torque it passes on to the leg (the limiter acts on HAL).
  tau_int_ = tau_applied_ + d_->qfrc_constraint[dof_] - friction - p_.hal_mgl() * std::sin(th0) -
             p_.hal_I() * thdd_;
}

void Hal3Plant::CheckDivergence(const char* where) {
  const std::string text = TakeMujocoWarning();  // as Plant::CheckDivergence
  for (int i = 0; i < mjNWARNING; ++i)
    if (d_->warning[i].number > 0)
      throw SimulationError(d_->time, std::string("MuJoCo warning ") + std::to_string(i) + " in " + where);
  if (!text.empty()) throw SimulationError(d_->time, "MuJoCo warning '" + text + "' in " + where);
  if (!std::isfinite(d_->qpos[0]) || !std::isfinite(d_->qvel[0]) || std::abs(d_->qvel[0]) > 100.0)
    throw SimulationError(d_->time, std::string("knee state diverged (|thd| > 100 rad/s or non-finite) in ") + where);
}

double Hal3Plant::th() const { return d_->qpos[0]; }
double Hal3Plant::thd() const { return d_->qvel[0]; }
double Hal3Plant::time() const { return d_->time; }
double Hal3Plant::timestep() const { return m_->opt.timestep; }

}  // namespace exotwin
