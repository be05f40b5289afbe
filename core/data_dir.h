// Where the shipped data lives: the MJCF models (mjcf/), data tables (data/), scenarios with their
// baselines (scenarios/) and examples (examples/). One rule for the build tree and an installation:
//   1. the environment variable EXOTWIN_DATA_DIR, if set and not empty;
//   2. else <folder of the running executable>/../share/exotwin, the executable read from
//      /proc/self/exe (P/bin/exotwin -> P/share/exotwin; the build tree mirrors this layout:
//      build/share/exotwin links to the source folders, see cmake/install.cmake).
// The source path is never compiled into a program.
#pragma once
#include <string>

namespace exotwin {

// The data folder by the rule above, without a trailing slash. Throws InputError when that folder
// does not exist, naming the folder looked for and where the rule took it from
// (EXOTWIN_DATA_DIR or the executable's path), and how to set it.
std::string DataDir();

// The running executable's path (/proc/self/exe, resolved); empty when it cannot be read. The one
// place programs locate themselves: the data folder, the rendering plugin, exotwin-controller.
std::string ExecutablePath();

// DataDir() + "/" + rel (rel: a path relative to the data folder, e.g. "mjcf/leg_exowheel.xml").
// The file itself is not checked: its reader names it when it is missing.
std::string DataPath(const std::string& rel);

}  // namespace exotwin
