// MJCF text edits: see mjcf_text.h.
#include "sim/mjcf_text.h"

#include <mujoco/mujoco.h>

#include <cctype>
#include <cstring>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>

#include "core/error.h"
#include "sim/mujoco_messages.h"

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

}  // namespace

std::string ReadMjcfText(const std::string& mjcf_path) {
  std::ifstream in(mjcf_path, std::ios::binary);
  std::ostringstream text;
  if (!in || !(text << in.rdbuf())) throw InputError(mjcf_path + ": cannot read the MJCF file");
  static const std::regex kComment(R"(<!--[\s\S]*?-->)");
  return std::regex_replace(text.str(), kComment, "");
}

BodyElement FindBodyElement(const std::string& xml, const std::string& name, const std::string& source) {
  const std::regex open_tag(R"(<body\b[^>]*\sname\s*=\s*(["']))" + name + R"(\1[^>]*>)");
  std::smatch m;
  if (!std::regex_search(xml, m, open_tag)) throw InputError(source + ": no body named '" + name + "'");
  BodyElement b;
  b.begin = static_cast<size_t>(m.position(0));
  b.open_end = TagEnd(xml, b.begin);
  if (SelfClosing(xml, b.begin)) throw InputError(source + ": body '" + name + "' has no joints or children");
  // Matching </body>: count nested body elements (self-closing ones do not nest).
  size_t pos = b.open_end;
  int depth = 1;
  while (depth > 0) {
    const size_t open = xml.find("<body", pos), close = xml.find("</body", pos);
    if (close == std::string::npos) throw InputError(source + ": body '" + name + "' is not closed");
    if (open != std::string::npos && open < close) {
      const char next = open + 5 < xml.size() ? xml[open + 5] : '\0';
      if ((std::isspace(static_cast<unsigned char>(next)) || next == '>') && !SelfClosing(xml, open)) ++depth;
      pos = TagEnd(xml, open);
    } else {
      --depth;
      pos = TagEnd(xml, close);
    }
    if (pos == std::string::npos) throw InputError(source + ": body '" + name + "' is not closed");
  }
  b.end = pos;
  return b;
}

mjModel* LoadMjcfText(const std::string& mjcf_path, const std::string& xml, const std::string& what) {
  // MuJoCo strips the folder when it looks a file up in the VFS, and resolves everything else
  // relative to the original's folder.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const size_t slash = mjcf_path.find_last_of('/');
  const std::string base = slash == std::string::npos ? mjcf_path : mjcf_path.substr(slash + 1);
  if (mj_makeEmptyFileVFS(vfs.get(), base.c_str(), static_cast<int>(xml.size())) != 0)
    throw InputError(mjcf_path + ": cannot stage " + what + " in MuJoCo's virtual file system");
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), base.c_str())], xml.data(), xml.size());
  KeepMujocoWarnings();
  char err[1000] = "";
  mjModel* m = mj_loadXML(mjcf_path.c_str(), vfs.get(), err, sizeof err);
  TakeMujocoWarning();  // the loader's warnings are in err
  mj_deleteVFS(vfs.get());
  if (!m) throw InputError(mjcf_path + ": " + what + " does not load: " + err);
  if (err[0]) {
    mj_deleteModel(m);
    throw InputError(mjcf_path + ": " + what + " loaded with a warning (treated as an error): " + err);
  }
  return m;
}

}  // namespace exotwin
