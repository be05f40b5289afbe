// Compiled MuJoCo models kept per process by MJCF path, so that a process running many scenarios on
// the same model (a sweep's workers, forked after the parent kept the model) copies it instead of
// parsing and compiling the XML for every run. A copy (mj_copyModel) holds the same numbers as a
// fresh load. A kept model is never reloaded: keep only files that do not change during the process.
// Thread-safe.
#pragma once
#include <mujoco/mujoco.h>

#include <functional>
#include <string>

namespace exotwin {

// A new model of the MJCF file (the caller owns it: mj_deleteModel): a copy of the kept model when
// KeepMjcfModel(path) succeeded before, else mj_loadXML's result (nullptr with the message in err,
// or a model with a warning in err, as mj_loadXML).
mjModel* LoadMjcfModel(const std::string& path, char* err, int err_size);

// Loads path and keeps it for LoadMjcfModel; returns false (nothing kept) when it does not load
// cleanly, so that the Plant reports the problem as without keeping.
bool KeepMjcfModel(const std::string& path);

// A new model of a variant of the MJCF file (an edit of its text, named by `variant`; the caller
// owns it): a copy of the one kept for (path, variant) when there is one, else build()'s result
// (which may throw), kept for (path, variant) when path itself is kept (KeepMjcfModel), so that a
// process building the same edit many times compiles it once. build() runs under the cache's lock:
// it must not call this cache.
mjModel* LoadMjcfVariant(const std::string& path, const std::string& variant, const std::function<mjModel*()>& build);

}  // namespace exotwin
