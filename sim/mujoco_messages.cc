// MuJoCo's warnings kept per thread: see mujoco_messages.h.
#include "sim/mujoco_messages.h"

#include <mutex>

#include <mujoco/mujoco.h>

namespace exotwin {
namespace {

thread_local std::string first_warning;

void KeepWarning(const char* msg) {
  if (first_warning.empty() && msg) first_warning = msg[0] ? msg : "(no text)";
}

}  // namespace

void KeepMujocoWarnings() {
  static std::once_flag once;
  std::call_once(once, [] { mju_user_warning = KeepWarning; });
}

void ClearMujocoWarning() { first_warning.clear(); }

std::string TakeMujocoWarning() {
  std::string w;
  w.swap(first_warning);
  return w;
}

}  // namespace exotwin
