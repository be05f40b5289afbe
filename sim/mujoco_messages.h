// MuJoCo's text warnings kept on the thread that raised them. By default MuJoCo prints a warning
// (mju_warning: "Linesearch objective is not convex", "Inertia matrix is too close to singular ...")
// to standard output, in the middle of the program's own output, and appends it to MUJOCO_LOG.TXT in
// the user's working folder. Routed here, a warning is kept for its owner to turn into an error
// (Plant::CheckDivergence: a MuJoCo warning in a simulation is an error, DESIGN.md) or to drop where
// the caller reports it another way (mj_loadXML's err buffer). MuJoCo's errors (mju_error) keep
// MuJoCo's default handling.
#pragma once
#include <string>

namespace exotwin {

// Installs the handler (mju_user_warning) once per process; thread-safe, idempotent. Every function
// that loads a MuJoCo model calls it (sim/mjcf_cache.h, sim/mjcf_text.h), so any plant's data has it.
void KeepMujocoWarnings();

// The first warning MuJoCo raised on the calling thread since the last take or clear, "" if none;
// cleared.
std::string TakeMujocoWarning();
// Forgets the calling thread's warning: a simulation about to run its MuJoCo calls and check them
// (Plant::Step) answers for its own warnings only, not for another model's on the same thread.
void ClearMujocoWarning();

}  // namespace exotwin
