// Kept MuJoCo models: see mjcf_cache.h.
#include "sim/mjcf_cache.h"

#include <map>
#include <memory>

#include "sim/mujoco_messages.h"

namespace exotwin {
namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};

// The kept models of this process by path (freed at exit).
std::map<std::string, std::unique_ptr<mjModel, ModelDeleter>>& Kept() {
  static std::map<std::string, std::unique_ptr<mjModel, ModelDeleter>> kept;
  return kept;
}

}  // namespace

mjModel* LoadMjcfModel(const std::string& path, char* err, int err_size) {
  KeepMujocoWarnings();
  const auto it = Kept().find(path);
  if (it != Kept().end()) {
    if (err_size > 0) err[0] = '\0';
    return mj_copyModel(nullptr, it->second.get());
  }
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, err_size);
  TakeMujocoWarning();  // the loader's warnings are in err
  return m;
}

bool KeepMjcfModel(const std::string& path) {
  if (Kept().count(path)) return true;
  KeepMujocoWarnings();
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof(err));
  TakeMujocoWarning();  // in err
  if (!m || err[0]) {
    if (m) mj_deleteModel(m);
    return false;
  }
  Kept()[path].reset(m);
  return true;
}

}  // namespace exotwin
