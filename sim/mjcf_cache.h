// Compiled MuJoCo models kept per process by MJCF path, so that a process running many scenarios on
// the same model (a sweep's workers, forked after the parent kept the model) copies it instead of
// parsing and compiling the XML for every run. A copy (mj_copyModel) holds the same numbers as a
// fresh load. A kept model is never reloaded: keep only files that do not change during the process.
#pragma once
#include <mujoco/mujoco.h>

#include <string>

namespace exotwin {

// A new model of the MJCF file (the caller owns it: mj_deleteModel): a copy of the kept model when
// KeepMjcfModel(path) succeeded before, else mj_loadXML's result (nullptr with the message in err,
// or a model with a warning in err, as mj_loadXML).
mjModel* LoadMjcfModel(const std::string& path, char* err, int err_size);

// Loads path and keeps it for LoadMjcfModel; returns false (nothing kept) when it does not load
// cleanly, so that the Plant reports the problem as without keeping.
bool KeepMjcfModel(const std::string& path);

}  // namespace exotwin
