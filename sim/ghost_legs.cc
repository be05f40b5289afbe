#include "sim/ghost_legs.h"

#include <mujoco/mujoco.h>

#include <cctype>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "core/error.h"
#include "sim/mjcf_text.h"
#include "sim/plant.h"

namespace exotwin {
namespace {

// The copy of a body element: names suffixed, geoms recoloured.
std::string GhostCopy(const std::string& element, const GhostLegStyle& g) {
  static const std::regex kName(R"((\s)name\s*=\s*(["'])(.*?)\2)");
  std::string out = std::regex_replace(element, kName, "$1name=$2$3" + g.suffix + "$2");
  static const std::regex kGeom(R"(<geom\b[^>]*>)");
  static const std::regex kColour(R"(\s(rgba|material)\s*=\s*(["']).*?\2)");
  char rgba[96];
  std::snprintf(rgba, sizeof rgba, " rgba=\"%g %g %g %g\"", g.rgba[0], g.rgba[1], g.rgba[2], g.rgba[3]);
  std::string result;
  auto last = out.cbegin();
  for (std::sregex_iterator it(out.begin(), out.end(), kGeom), end; it != end; ++it) {
    result.append(last, (*it)[0].first);
    const std::string tag = std::regex_replace((*it)[0].str(), kColour, "");
    result += "<geom" + std::string(rgba) + tag.substr(5);
    last = (*it)[0].second;
  }
  result.append(last, out.cend());
  return result;
}

}  // namespace

std::string AddGhostLegs(const std::string& xml_in, const std::string& source,
                         const std::vector<GhostLegStyle>& ghosts) {
  static const std::regex kComment(R"(<!--[\s\S]*?-->)");
  const std::string xml = std::regex_replace(xml_in, kComment, "");
  const BodyElement body = FindBodyElement(xml, "exo_thigh", source);
  const size_t begin = body.begin, pos = body.end;
  const std::string element = xml.substr(begin, pos - begin);
  std::string copies;
  for (size_t k = 0; k < ghosts.size(); ++k) {
    char wrapper[160];
    std::snprintf(wrapper, sizeof wrapper, "\n<body name=\"ghost%s\" pos=\"0 %g 0\">\n", ghosts[k].suffix.c_str(),
                  GhostLegModel::kGhostStepY * (k + 1));
    copies += wrapper + GhostCopy(element, ghosts[k]) + "\n</body>";
  }
  return xml.substr(0, pos) + copies + xml.substr(pos);
}

GhostLegModel::GhostLegModel(const std::string& mjcf_path, const std::vector<GhostLegStyle>& ghosts, double L1) {
  const std::string xml = AddGhostLegs(ReadMjcfText(mjcf_path), mjcf_path, ghosts);
  m_ = LoadMjcfText(mjcf_path, xml, "the model with ghost legs");
  d_ = mj_makeData(m_);

  auto hinge = [this, &mjcf_path](const std::string& name) {
    const int j = mj_name2id(m_, mjOBJ_JOINT, name.c_str());
    if (j < 0 || m_->jnt_type[j] != mjJNT_HINGE) {
      mj_deleteData(d_);
      mj_deleteModel(m_);
      throw InputError(mjcf_path + ": no hinge joint named '" + name + "'");
    }
    return m_->jnt_qposadr[j];
  };
  hip_adr_.push_back(hinge("hip"));
  knee_adr_.push_back(hinge("knee"));
  for (const GhostLegStyle& g : ghosts) {
    hip_adr_.push_back(hinge("hip" + g.suffix));
    knee_adr_.push_back(hinge("knee" + g.suffix));
  }
  try {
    SetThighLength(m_, L1);
    for (const GhostLegStyle& g : ghosts) SetThighLength(m_, L1, g.suffix);
  } catch (const InputError& e) {
    mj_deleteData(d_);
    mj_deleteModel(m_);
    throw InputError(mjcf_path + ": " + e.what());
  }
  mj_forward(m_, d_);
}

GhostLegModel::~GhostLegModel() {
  mj_deleteData(d_);
  mj_deleteModel(m_);
}

void GhostLegModel::SetLeg(int leg, double q_hip, double q_knee) {
  if (leg < -1 || leg >= ghosts()) throw std::out_of_range("GhostLegModel: no leg " + std::to_string(leg));
  d_->qpos[hip_adr_[leg + 1]] = q_hip;
  d_->qpos[knee_adr_[leg + 1]] = q_knee;
}

}  // namespace exotwin
