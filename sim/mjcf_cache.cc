// Kept MuJoCo models: see mjcf_cache.h.
#include "sim/mjcf_cache.h"

#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "sim/mujoco_messages.h"

namespace exotwin {
namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};

// The kept models of this process by path, and their variants by (path, variant) (freed at exit).
template <class Key>
using KeptModels = std::map<Key, std::unique_ptr<mjModel, ModelDeleter>>;
KeptModels<std::string>& Kept() {
  static KeptModels<std::string> kept;
  return kept;
}
KeptModels<std::pair<std::string, std::string>>& KeptVariants() {
  static KeptModels<std::pair<std::string, std::string>> kept;
  return kept;
}
std::mutex& KeptMutex() {
  static std::mutex m;
  return m;
}

}  // namespace

mjModel* LoadMjcfModel(const std::string& path, char* err, int err_size) {
  std::lock_guard<std::mutex> lock(KeptMutex());
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
  std::lock_guard<std::mutex> lock(KeptMutex());
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

mjModel* LoadMjcfVariant(const std::string& path, const std::string& variant, const std::function<mjModel*()>& build) {
  std::lock_guard<std::mutex> lock(KeptMutex());
  const auto key = std::make_pair(path, variant);
  const auto it = KeptVariants().find(key);
  if (it != KeptVariants().end()) return mj_copyModel(nullptr, it->second.get());
  mjModel* m = build();
  if (m && Kept().count(path)) KeptVariants()[key].reset(mj_copyModel(nullptr, m));
  return m;
}

}  // namespace exotwin
