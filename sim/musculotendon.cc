#include "sim/musculotendon.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace exotwin {
namespace {

using Vec3 = Eigen::Vector3d;

// Natural cubic spline through (x_i, y_i) (OpenSim's SimmSpline interpolates with cubic pieces of
// continuous second derivative); constant outside the knots is never reached here (the knots span
// -120..120 deg).
class NaturalSpline {
 public:
  NaturalSpline(std::vector<double> x, std::vector<double> y) : x_(std::move(x)), y_(std::move(y)) {
    const size_t n = x_.size();
    m_.assign(n, 0.0);
    if (n < 3) return;
    // Tridiagonal system for the second derivatives m_i (m_0 = m_{n-1} = 0).
    std::vector<double> a(n, 0), b(n, 1), c(n, 0), d(n, 0);
    for (size_t i = 1; i + 1 < n; ++i) {
      const double h0 = x_[i] - x_[i - 1], h1 = x_[i + 1] - x_[i];
      a[i] = h0, b[i] = 2 * (h0 + h1), c[i] = h1;
      d[i] = 6 * ((y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0);
    }
    for (size_t i = 1; i < n; ++i) {  // Thomas algorithm
      const double w = a[i] / b[i - 1];
      b[i] -= w * c[i - 1], d[i] -= w * d[i - 1];
    }
    m_[n - 1] = d[n - 1] / b[n - 1];
    for (size_t i = n - 1; i-- > 0;) m_[i] = (d[i] - c[i] * m_[i + 1]) / b[i];
  }
  double operator()(double t) const {
    const size_t n = x_.size();
    if (n == 1) return y_[0];
    size_t k = static_cast<size_t>(std::upper_bound(x_.begin(), x_.end(), t) - x_.begin());
    k = std::clamp<size_t>(k, 1, n - 1);
    const double h = x_[k] - x_[k - 1], A = (x_[k] - t) / h, B = (t - x_[k - 1]) / h;
    return A * y_[k - 1] + B * y_[k] + ((A * A * A - A) * m_[k - 1] + (B * B * B - B) * m_[k]) * h * h / 6;
  }

 private:
  std::vector<double> x_, y_, m_;
};

enum class Body { kPelvis, kFemur, kTibia, kCalcn };

// One path point: fixed on its body, or moving with the knee angle (x, y splines), or active only
// for knee angles within [lo, hi].
struct PathPoint {
  Body body;
  Vec3 p;
  const NaturalSpline* mx = nullptr;
  const NaturalSpline* my = nullptr;
  bool conditional = false;
  double lo = 0, hi = 0;
};

// ---- leg6dof9musc (a scaled gait2392 leg; Delp et al. 1990), m and rad ----
// Hip joint centre in the pelvis frame.
const Vec3 kHip(-0.0739512, -0.0691397, 0.0873398);
// Tibia origin in the femur frame: knee_angle_r translations (SimmSpline of the knee angle).
const NaturalSpline& KneeTx() {
  static const NaturalSpline s({-2.0944, -1.74533, -1.39626, -1.0472, -0.698132, -0.349066, -0.174533, 0.197344,
                                0.337395, 0.490178, 1.52146, 2.0944},
                               {-0.0037561, 0.00210107, 0.00482424, 0.00481249, 0.00248841, -0.00117378, -0.00363871,
                                -0.00613534, -0.00637949, -0.00654265, -0.00637949, -0.00616234});
  return s;
}
const NaturalSpline& KneeTy() {
  static const NaturalSpline s({-2.0944, -1.22173, -0.523599, -0.349066, -0.174533, 0.159149, 2.0944},
                               {-0.496039, -0.479137, -0.468338, -0.466695, -0.465521, -0.463953, -0.464817});
  return s;
}
// Calcaneus origin in the tibia frame (ankle and subtalar at 0): talus at (0, -0.483203, 0), calcn
// at (-0.0620508, -0.0531864, 0.0101307) in the talus.
const Vec3 kCalcnInTibia(-0.0620508, -0.483203 - 0.0531864, 0.0101307);
// gait2392's ankle_r (talocrural) axis, in the tibia frame (its joint frame at orientation 0): the
// talus turns about it by ankle_angle_r, dorsiflexion positive.
const Vec3 kAnkleAxis(-0.10501355, -0.17402245, 0.97912632);

const std::vector<double>& PatellaKnots() {
  static const std::vector<double> k = {-2.0944, -1.99997, -1.5708, -1.45752, -1.39626, -1.0472,
                                        -0.698132, -0.526391, -0.349066, -0.174533, 0, 0.00017453,
                                        0.00034907, 0.0279253, 0.0872665, 0.174533, 2.0944};
  return k;
}

const std::vector<PathPoint>& Path(Muscle m) {
  static const NaturalSpline rf_x(PatellaKnots(), {0.0175082, 0.0202202, 0.0309116, 0.0333257, 0.0345676, 0.0410942,
                                                   0.0474297, 0.0506691, 0.0543783, 0.0600407, 0.0693987, 0.0694092,
                                                   0.0694196, 0.0711413, 0.075283, 0.0823732, 0.0644437});
  static const NaturalSpline rf_y(PatellaKnots(), {0.0263083, 0.0267012, 0.0282215, 0.0284073, 0.0284468, 0.0280015,
                                                   0.0272362, 0.026795, 0.0263174, 0.025581, 0.0235803, 0.0235774,
                                                   0.0235745, 0.0230617, 0.0215479, 0.0179296, -0.0757138});
  static const NaturalSpline vi_x(PatellaKnots(), {0.00929694, 0.0120089, 0.022704, 0.0251187, 0.0263607, 0.0328932,
                                                   0.0392704, 0.0425567, 0.0463615, 0.0522856, 0.0623256, 0.0623371,
                                                   0.0623486, 0.0642454, 0.0688531, 0.0769044, 0.0729095});
  static const NaturalSpline vi_y(PatellaKnots(), {0.0287664, 0.0291593, 0.0306917, 0.0308797, 0.0309195, 0.0304938,
                                                   0.0298616, 0.0295622, 0.0293503, 0.0292314, 0.0284217, 0.0284203,
                                                   0.0284189, 0.0281523, 0.0272157, 0.0245296, -0.0770547});
  static const std::vector<PathPoint> rf = {
      {Body::kPelvis, Vec3(-0.0308566, -0.0325302, 0.101251)},
      {Body::kFemur, Vec3(0.0392043, -0.473033, 0.00223019), nullptr, nullptr, true, -2.61799, -1.45997},
      {Body::kTibia, Vec3(0, 0, 0.00157322), &rf_x, &rf_y}};
  static const std::vector<PathPoint> vm = {
      {Body::kFemur, Vec3(0.0340396, -0.225835, 0.0363872)},
      {Body::kFemur, Vec3(0.0393216, -0.244616, 0.0334527)},
      {Body::kFemur, Vec3(0.0402607, -0.473033, 0.00645579), nullptr, nullptr, true, -2.61799, -1.42},
      {Body::kTibia, Vec3(0, 0, 0.00202271), &vi_x, &vi_y}};
  static const std::vector<PathPoint> st = {{Body::kPelvis, Vec3(-0.131752, -0.107287, 0.0726333)},
                                            {Body::kTibia, Vec3(-0.0338242, -0.0404542, 0.0330713)},
                                            {Body::kTibia, Vec3(-0.0262952, -0.0632659, 0.0385439)}};
  static const std::vector<PathPoint> gas = {
      {Body::kFemur, Vec3(-0.0223018, -0.461178, -0.0275838)},
      {Body::kFemur, Vec3(-0.0352134, -0.472094, -0.0302835), nullptr, nullptr, true, -0.785398, 0.174533},
      {Body::kCalcn, Vec3(0, 0.0318348, -0.00544272)}};
  static const std::vector<PathPoint> gmax = {{Body::kPelvis, Vec3(-0.141103, 0.0184094, 0.058889)},
                                              {Body::kPelvis, Vec3(-0.143928, -0.0543913, 0.0956031)},
                                              {Body::kFemur, Vec3(-0.050003, -0.0622103, 0.0343917)},
                                              {Body::kFemur, Vec3(-0.018311, -0.119256, 0.0491814)}};
  switch (m) {
    case Muscle::kRF: return rf;
    case Muscle::kVM: return vm;
    case Muscle::kST: return st;
    case Muscle::kGAS: return gas;
    case Muscle::kGMAX: return gmax;
  }
  return rf;
}

Eigen::Matrix3d Rz(double a) {
  Eigen::Matrix3d R;
  R << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return R;
}

// Scale factors of leg6dof9musc's bodies against the generic gait2392 (its joint offsets over the
// generic ones: hip centre 0.0707/0.0661/0.0835 m, knee translation -0.4226 m at -120 deg, talus
// 0.43 m below the tibia, subtalar 0.04877 m): pelvis, femur, tibia, calcaneus.
constexpr double kBodyScale[4] = {1.04599, 1.17378, 1.12373, 1.27231};

// Path length at (qh, qk, qa) with the conditional points chosen at qk_active; `generic`: every point
// and joint offset divided by its body's scale (the generic gait2392 leg).
double PathLength(Muscle m, double qh, double qk, double qk_active, bool generic = false, double qa = 0) {
  const Eigen::Matrix3d Rh = Rz(qh), Rk = Rz(qk);
  const Eigen::Matrix3d Ra = Eigen::AngleAxisd(qa, kAnkleAxis.normalized()).toRotationMatrix();
  auto sc = [generic](Body b) { return generic ? 1 / kBodyScale[static_cast<int>(b)] : 1.0; };
  const Vec3 knee = Vec3(KneeTx()(qk), KneeTy()(qk), 0) * sc(Body::kFemur);
  const Vec3 hip = kHip * sc(Body::kPelvis);
  const Vec3 talus(0, -0.483203 * sc(Body::kTibia), 0);
  const Vec3 calcn_in_talus = (kCalcnInTibia - Vec3(0, -0.483203, 0)) * sc(Body::kCalcn);
  auto in_pelvis = [&](const PathPoint& pp) -> Vec3 {
    Vec3 p = pp.p;
    if (pp.mx) p.x() = (*pp.mx)(qk), p.y() = (*pp.my)(qk);
    p *= sc(pp.body);
    switch (pp.body) {
      case Body::kPelvis: return p;
      case Body::kFemur: return hip + Rh * p;
      case Body::kTibia: return hip + Rh * (knee + Rk * p);
      case Body::kCalcn: return hip + Rh * (knee + Rk * (talus + Ra * (calcn_in_talus + p)));
    }
    return p;
  };
  double L = 0;
  bool first = true;
  Vec3 prev;
  for (const PathPoint& pp : Path(m)) {
    if (pp.conditional && (qk_active < pp.lo || qk_active > pp.hi)) continue;
    const Vec3 x = in_pelvis(pp);
    if (!first) L += (x - prev).norm();
    prev = x, first = false;
  }
  return L;
}

struct Generic {
  const char* names[4];
  MusculotendonParams p;
};

// gait2392 (Delp et al. 1990) maximum isometric force, optimal fibre length, tendon slack length and
// pennation, as CEINMS-RT's LowerLimbModel (subjectMTU.xml) lists them; semiten, lat_gas and
// glut_max from OpenSim's gait2392 model file.
const std::vector<Generic>& GenericTable() {
  static const std::vector<Generic> t = {
      {{"vas_med", "vasmed", nullptr, nullptr}, {"vas_med_r", 1294, 0.089, 0.126, 0.087}},
      {{"vas_lat", "vaslat", nullptr, nullptr}, {"vas_lat_r", 1871, 0.084, 0.157, 0.087}},
      {{"vas_int", "vasint", nullptr, nullptr}, {"vas_int_r", 1365, 0.087, 0.136, 0.087}},
      {{"rect_fem", "recfem", nullptr, nullptr}, {"rect_fem_r", 1169, 0.114, 0.310, 0.087}},
      {{"semimem", nullptr, nullptr, nullptr}, {"semimem_r", 1288, 0.080, 0.359, 0.262}},
      {{"semiten", nullptr, nullptr, nullptr}, {"semiten_r", 410, 0.201, 0.262, 0.087}},
      {{"bifemlh", "bflh", nullptr, nullptr}, {"bifemlh_r", 896, 0.109, 0.326, 0.0}},
      {{"med_gas", "gasmed", nullptr, nullptr}, {"med_gas_r", 1558, 0.060, 0.390, 0.297}},
      {{"lat_gas", "gaslat", nullptr, nullptr}, {"lat_gas_r", 683, 0.064, 0.385, 0.140}},
      {{"glut_max1", "glmax1", nullptr, nullptr}, {"glut_max1_r", 573, 0.142, 0.125, 0.087}},
      {{"glut_max2", "glmax2", nullptr, nullptr}, {"glut_max2_r", 819, 0.147, 0.127, 0.0}},
      {{"glut_max3", "glmax3", nullptr, nullptr}, {"glut_max3_r", 552, 0.144, 0.145, 0.087}},
  };
  return t;
}

}  // namespace

bool GenericMusculotendon(const std::string& channel, MusculotendonParams* p) {
  // "<name>_r" / "<name>_l"
  if (channel.size() < 3 || channel[channel.size() - 2] != '_' ||
      (channel.back() != 'r' && channel.back() != 'l'))
    return false;
  const std::string base = channel.substr(0, channel.size() - 2);
  for (const Generic& g : GenericTable())
    for (const char* n : g.names)
      if (n && base == n) {
        *p = g.p;
        return true;
      }
  return false;
}

MusculotendonParams GenericMusculotendon(Muscle m) {
  const char* name = "vas_int_r";
  switch (m) {
    case Muscle::kVM: name = "vas_int_r"; break;
    case Muscle::kRF: name = "rect_fem_r"; break;
    case Muscle::kST: name = "bifemlh_r"; break;
    case Muscle::kGAS: name = "med_gas_r"; break;
    case Muscle::kGMAX: name = "glut_max2_r"; break;
  }
  MusculotendonParams p;
  GenericMusculotendon(name, &p);
  return p;
}

MusculotendonParams ScaledMusculotendon(Muscle m, const MusculotendonParams& generic) {
  // OpenSim's scale tool keeps l_opt and l_ts in proportion to the path length (Delp et al. 2007,
  // IEEE TBME 54:1940), here the ratio at the anatomical pose.
  const double s = PathLength(m, 0, 0, 0) / PathLength(m, 0, 0, 0, true);
  MusculotendonParams p = generic;
  p.l_opt *= s, p.l_ts *= s;
  return p;
}

std::string MusculotendonPathSource(Muscle m) {
  switch (m) {
    case Muscle::kRF: return "gait2392 rect_fem (Delp et al. 1990)";
    case Muscle::kVM: return "gait2392 vas_int (Delp et al. 1990; Visser et al. 1990)";
    case Muscle::kST: return "gait2392 bifemlh (Delp et al. 1990)";
    case Muscle::kGAS: return "gait2392 med_gas (Delp et al. 1990)";
    case Muscle::kGMAX: return "gait2392 glut_max2 (Delp et al. 1990)";
  }
  return "";
}

bool CrossesAnkle(Muscle m) { return m == Muscle::kGAS; }

MtuKinematics MusculotendonKinematics(Muscle m, double q_hip, double q_knee, double q_ankle) {
  MtuKinematics k;
  const bool ankle = CrossesAnkle(m);
  const double qa = ankle ? q_ankle : 0;
  k.length = PathLength(m, q_hip, q_knee, q_knee, false, qa);
  constexpr double h = 1e-5;  // rad: central differences of a smooth path (via points fixed at q)
  for (int j = 0; j < 2; ++j) {
    if (ActionSign(m, j) == 0) continue;
    const double dh = j == 0 ? h : 0, dk = j == 1 ? h : 0;
    k.arm[j] = -(PathLength(m, q_hip + dh, q_knee + dk, q_knee, false, qa) -
                 PathLength(m, q_hip - dh, q_knee - dk, q_knee, false, qa)) /
               (2 * h);
  }
  if (ankle)
    k.arm_ankle = -(PathLength(m, q_hip, q_knee, q_knee, false, qa + h) - PathLength(m, q_hip, q_knee, q_knee, false, qa - h)) /
                  (2 * h);
  return k;
}

double ActiveForceLength(double l) { return std::exp(-(l - 1) * (l - 1) / 0.45); }

double PassiveForceLength(double l) {
  constexpr double kPE = 5.0, e0 = 0.6;
  if (l <= 1) return 0;
  return std::expm1(kPE * (l - 1) / e0) / std::expm1(kPE);
}

double ForceVelocity(double v) {
  constexpr double Af = 0.25, Flen = 1.8, c = (2 + 2 / Af) / (Flen - 1);
  if (v <= -1) return 0;
  if (v <= 0) return (1 + v) / (1 - v / Af);
  return (1 + c * v * Flen) / (1 + c * v);
}

double TendonForceStrain(double e) {
  constexpr double e0 = 0.04, k_toe = 3, F_toe = 0.33, e_toe = 0.609 * e0, k_lin = 1.712 / e0;
  if (e <= 0) return 0;
  if (e <= e_toe) return F_toe * std::expm1(k_toe * e / e_toe) / std::expm1(k_toe);
  return k_lin * (e - e_toe) + F_toe;
}

HillState RigidTendonState(const MusculotendonParams& p, double L, double Ldot) {
  HillState s;
  const double h = p.l_opt * std::sin(p.pennation);         // constant fibre thickness
  const double along = std::max(L - p.l_ts, 1e-6);          // fibre length along the tendon
  const double lm = std::sqrt(along * along + h * h);
  s.cos_pennation = along / lm;
  s.fibre_length = lm / p.l_opt;
  s.fibre_velocity = Ldot * s.cos_pennation / (kMaxShorteningVelocity * p.l_opt);  // dl_m/dt = cos(phi) dL/dt
  s.active = ActiveForceLength(s.fibre_length) * ForceVelocity(s.fibre_velocity) * s.cos_pennation;
  s.passive = PassiveForceLength(s.fibre_length) * s.cos_pennation;
  return s;
}

namespace {

// The elastic unit's balance at normalized fibre length l (ElasticTendonSeries): g(l) = fibre force -
// tendon force (per F_max) and dg/dl, the fibre velocity (l - l_prev) rate (normalized: rate = 1 /
// (v_max dt), 0 for the static equilibrium).
struct Balance {
  const MusculotendonParams& p;
  double h, L, a, l_prev, rate;
  double v(double l) const { return (l - l_prev) * rate; }
  double Along(double l) const {
    const double lm = l * p.l_opt;
    return std::sqrt(std::max(lm * lm - h * h, 1e-30));
  }
  double Strain(double l) const { return (L - Along(l) - p.l_ts) / p.l_ts; }
  // g and its derivative (Thelen 2003's curves, as ActiveForceLength, PassiveForceLength,
  // ForceVelocity and TendonForceStrain compute them, and their closed-form slopes).
  double operator()(double l, double* dg) const {
    constexpr double kPE = 5.0, e0 = 0.6, Af = 0.25, Flen = 1.8, c = (2 + 2 / Af) / (Flen - 1);
    constexpr double e0T = 0.04, k_toe = 3, F_toe = 0.33, e_toe = 0.609 * e0T, k_lin = 1.712 / e0T;
    static const double kExpPE = std::expm1(kPE), kExpToe = std::expm1(k_toe);
    const double lm = l * p.l_opt, along = Along(l), cp = along / lm;
    const double fL = std::exp(-(l - 1) * (l - 1) / 0.45), dfL = fL * (-2 * (l - 1) / 0.45);
    double fPE = 0, dfPE = 0;
    if (l > 1) {
      const double E = std::exp(kPE * (l - 1) / e0);
      fPE = (E - 1) / kExpPE, dfPE = kPE / e0 * E / kExpPE;
    }
    const double vel = v(l), fV = ForceVelocity(vel);
    const double dfV = vel <= -1 ? 0 : vel <= 0 ? (1 + 1 / Af) / ((1 - vel / Af) * (1 - vel / Af))
                                                : c * (Flen - 1) / ((1 + c * vel) * (1 + c * vel));
    const double e = (L - along - p.l_ts) / p.l_ts;
    double fT = 0, dfT = 0;
    if (e > e_toe) {
      fT = k_lin * (e - e_toe) + F_toe, dfT = k_lin;
    } else if (e > 0) {
      const double E = std::exp(k_toe * e / e_toe);
      fT = F_toe * (E - 1) / kExpToe, dfT = F_toe * k_toe / e_toe * E / kExpToe;
    }
    const double dcp = h * h / (along * lm * lm) * p.l_opt;  // d cos(phi) / dl
    const double de = -(lm / along) * p.l_opt / p.l_ts;      // d strain / dl
    const double fm = a * fL * fV + fPE;
    *dg = (a * (dfL * fV + fL * dfV * rate) + dfPE) * cp + fm * dcp - dfT * de;
    return fm * cp - fT;
  }
};

// The root of Balance b on [lo, hi], lo the shortest fibre the pennation allows (or 0.05 l_opt), hi
// the fibre at the tendon's slack length: Newton from `start`, kept inside the bracket its own
// evaluations narrow, bisection where it would leave it; an end is evaluated only when a step would
// pass it (hi with g <= 0: the tendon slack, the fibre there; lo with g >= 0: the fibre at lo).
double SolveBalance(const Balance& b, double start) {
  const double h_norm = b.h / b.p.l_opt;
  const double lo_end = std::max(h_norm * (1 + 1e-9), 0.05);
  const double hi_end = std::sqrt(std::pow(std::max(b.L - b.p.l_ts, 1e-6), 2) + b.h * b.h) / b.p.l_opt;
  if (hi_end <= lo_end) return hi_end;
  double lo = lo_end, hi = hi_end, d;
  bool lo_known = false, hi_known = false;  // g(lo) < 0, g(hi) > 0 established
  double x = std::clamp(start, lo, hi);
  for (int it = 0; it < 100; ++it) {
    const double g = b(x, &d);
    if (g == 0) return x;
    if (g < 0) lo = x, lo_known = true;
    else hi = x, hi_known = true;
    double nx = d > 0 ? x - g / d : (g < 0 ? hi : lo);
    if (!(nx > lo && nx < hi)) {
      if (!hi_known && nx >= hi) {
        if (b(hi_end, &d) <= 0) return hi_end;  // no fibre force at the tendon's slack length: slack
        hi_known = true;
      }
      if (!lo_known && nx <= lo) {
        if (b(lo_end, &d) >= 0) return lo_end;
        lo_known = true;
      }
      nx = 0.5 * (lo + hi);
    }
    if (std::abs(nx - x) < 1e-10 || hi - lo < 1e-10) return nx;
    x = nx;
  }
  return x;
}

}  // namespace

void ElasticTendonSeries(const MusculotendonParams& p, const std::vector<double>& t, const std::vector<double>& L,
                         const std::vector<double>& a, TendonSeries* out) {
  const size_t n = t.size();
  out->fibre_length.assign(n, 0.0), out->fibre_velocity.assign(n, 0.0), out->force.assign(n, 0.0);
  const double h = p.l_opt * std::sin(p.pennation);
  double l_prev = 1;
  for (size_t i = 0; i < n; ++i) {
    const double rate = i == 0 ? 0.0 : 1 / (kMaxShorteningVelocity * (t[i] - t[i - 1]));
    const Balance b{p, h, L[i], a[i], l_prev, rate};
    const double l = SolveBalance(b, i == 0 ? std::sqrt(std::pow(std::max(L[i] - p.l_ts, 1e-6), 2) + h * h) / p.l_opt : l_prev);
    out->fibre_length[i] = l;
    out->fibre_velocity[i] = b.v(l);
    out->force[i] = TendonForceStrain(b.Strain(l));
    l_prev = l;
  }
}

double ElasticEquilibriumFibreLength(const MusculotendonParams& p, double L, double a) {
  const double h = p.l_opt * std::sin(p.pennation);
  // g(l) = muscle force - tendon force along the tendon, over the fibre lengths the path allows;
  // increasing the fibre length shortens the tendon (its force falls) and raises the passive force.
  auto g = [&](double l_norm) {
    const double lm = l_norm * p.l_opt;
    const double along = std::sqrt(std::max(lm * lm - h * h, 0.0));
    const double cp = lm > 0 ? along / lm : 1;
    const double fm = (a * ActiveForceLength(l_norm) + PassiveForceLength(l_norm)) * cp;
    const double ft = TendonForceStrain((L - along - p.l_ts) / p.l_ts);
    return fm - ft;
  };
  const double hi_len = std::sqrt(std::pow(std::max(L - p.l_ts, 0.0), 2) + h * h) / p.l_opt;  // tendon slack
  double lo = std::max(h / p.l_opt + 1e-6, 0.3), hi = std::max(hi_len, lo);
  if (g(hi) <= 0) return hi;  // slack tendon: the rigid length
  if (g(lo) > 0) return lo;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace exotwin
