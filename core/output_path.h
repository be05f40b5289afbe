// Where a command's output goes: every --out / -o path is created with its missing parent folders
// (DESIGN.md "Command line"), by the writer, when it writes (a refused input leaves nothing behind).
#pragma once
#include <string>

namespace exotwin {

// Creates the folder `dir` and its missing parents. Throws InputError
//   "<dir>: exists and is not a folder, expected an output folder (created when missing)", or
//   "<dir>: cannot create the output folder (<reason>)".
void CreateOutputFolder(const std::string& dir);

// Creates the missing parent folders of the file `path` (none for a name without a folder), with
// CreateOutputFolder's errors.
void CreateParentFolders(const std::string& path);

}  // namespace exotwin
