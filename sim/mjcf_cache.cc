// Kept MuJoCo models: see mjcf_cache.h.
#include "sim/mjcf_cache.h"

#include <map>

namespace exotwin {
namespace {

// The kept models of this process by path (never freed: they live as long as the process).
std::map<std::string, mjModel*>& Kept() {
  static std::map<std::string, mjModel*> kept;
  return kept;
}

}  // namespace

mjModel* LoadMjcfModel(const std::string& path, char* err, int err_size) {
  const auto it = Kept().find(path);
  if (it != Kept().end()) {
    if (err_size > 0) err[0] = '\0';
    return mj_copyModel(nullptr, it->second);
  }
  return mj_loadXML(path.c_str(), nullptr, err, err_size);
}

bool KeepMjcfModel(const std::string& path) {
  if (Kept().count(path)) return true;
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof(err));
  if (!m || err[0]) {
    if (m) mj_deleteModel(m);
    return false;
  }
  Kept()[path] = m;
  return true;
}

}  // namespace exotwin
