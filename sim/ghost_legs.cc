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
#include "sim/plant.h"

namespace exotwin {
namespace {

// End (one past '>') of the tag that starts at `open` ('<'); npos if unterminated.
size_t TagEnd(const std::string& s, size_t open) {
  const size_t gt = s.find('>', open);
  return gt == std::string::npos ? gt : gt + 1;
}

bool SelfClosing(const std::string& s, size_t open) {
  const size_t end = TagEnd(s, open);
  return end != std::string::npos && end >= 2 && s[end - 2] == '/';
}

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
  static const std::regex kThigh(R"(<body\b[^>]*\sname\s*=\s*(["'])exo_thigh\1[^>]*>)");
  std::smatch m;
  if (!std::regex_search(xml, m, kThigh)) throw InputError(source + ": no body named 'exo_thigh'");
  const size_t begin = m.position(0);
  if (SelfClosing(xml, begin)) throw InputError(source + ": body 'exo_thigh' has no joints or children");
  // Matching </body>: count nested body elements (self-closing ones do not nest).
  size_t pos = TagEnd(xml, begin);
  int depth = 1;
  while (depth > 0) {
    const size_t open = xml.find("<body", pos), close = xml.find("</body", pos);
    if (close == std::string::npos) throw InputError(source + ": body 'exo_thigh' is not closed");
    if (open != std::string::npos && open < close) {
      const char next = open + 5 < xml.size() ? xml[open + 5] : '\0';
      if ((std::isspace(static_cast<unsigned char>(next)) || next == '>') && !SelfClosing(xml, open)) ++depth;
      pos = TagEnd(xml, open);
    } else {
      --depth;
      pos = TagEnd(xml, close);
    }
    if (pos == std::string::npos) throw InputError(source + ": body 'exo_thigh' is not closed");
  }
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
  std::ifstream in(mjcf_path, std::ios::binary);
  std::ostringstream text;
  if (!in || !(text << in.rdbuf())) throw InputError(mjcf_path + ": cannot read the MJCF file");
  const std::string xml = AddGhostLegs(text.str(), mjcf_path, ghosts);

  // The text goes in a virtual file of the original's name: MuJoCo strips the folder when it looks a
  // file up in the VFS, and resolves everything else relative to the original's folder.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const size_t slash = mjcf_path.find_last_of('/');
  const std::string base = slash == std::string::npos ? mjcf_path : mjcf_path.substr(slash + 1);
  if (mj_makeEmptyFileVFS(vfs.get(), base.c_str(), static_cast<int>(xml.size())) != 0)
    throw InputError(mjcf_path + ": cannot stage the ghost-leg model in MuJoCo's virtual file system");
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), base.c_str())], xml.data(), xml.size());
  char err[1000] = "";
  m_ = mj_loadXML(mjcf_path.c_str(), vfs.get(), err, sizeof err);
  mj_deleteVFS(vfs.get());
  if (!m_) throw InputError(mjcf_path + ": the model with ghost legs does not load: " + err);
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
