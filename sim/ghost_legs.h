// A model for videos that compare legs: the MJCF's leg plus translucent "ghost" copies of it posed
// independently (e.g. the twin's simulated angles beside the measured ones in `render-replay`).
// Visual only: the copies have no actuators and the model is not meant to be simulated.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

struct mjModel_;
struct mjData_;

namespace exotwin {

struct GhostLegStyle {
  std::string suffix;                        // appended to every name of the copy, e.g. "_ghost1"
  std::array<double, 4> rgba{1, 0, 0, 0.4};  // colour of every geom of the copy
};

class GhostLegModel {
 public:
  // Loads `mjcf_path` (a leg as Plant loads it: body exo_thigh holding the hinge hip and, in body
  // exo_shank, the hinge knee) with one copy of the exo_thigh subtree per entry of `ghosts`,
  // inserted after exo_thigh in the same parent inside a body "ghost<suffix>" shifted by
  // (0, kGhostStepY * (k + 1), 0) (k = index in `ghosts`; +y is towards the side-view camera, so
  // ghost k is drawn in front of the measured leg and of ghost k - 1). In a copy every name="..."
  // gets the suffix and every geom the style's rgba (its material dropped). The thigh length L1 (m)
  // is written into every leg (SetThighLength). Comments are dropped; assets and includes are
  // resolved relative to the MJCF's folder as for the file itself. Throws InputError naming the file
  // if it cannot be read, has no body exo_thigh with children, or the result does not load.
  GhostLegModel(const std::string& mjcf_path, const std::vector<GhostLegStyle>& ghosts, double L1);
  ~GhostLegModel();
  GhostLegModel(const GhostLegModel&) = delete;
  GhostLegModel& operator=(const GhostLegModel&) = delete;

  static constexpr double kGhostStepY = 0.1;  // m

  // Poses leg `leg` (-1: the MJCF's own, k >= 0: ghost k) at hip and knee angles (rad) in data().
  void SetLeg(int leg, double q_hip, double q_knee);
  int ghosts() const { return static_cast<int>(hip_adr_.size()) - 1; }

  const mjModel_* model() const { return m_; }
  const mjData_* data() const { return d_; }  // qpos holds the poses set; the rest at qpos0

 private:
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  std::vector<int> hip_adr_, knee_adr_;  // qpos address per leg: [0] the MJCF's own, [k + 1] ghost k
};

// The MJCF text of `xml` (a file's content; `source` names it in errors) with the ghost copies that
// GhostLegModel describes (exposed for tests). Throws InputError as GhostLegModel does.
std::string AddGhostLegs(const std::string& xml, const std::string& source, const std::vector<GhostLegStyle>& ghosts);

}  // namespace exotwin
