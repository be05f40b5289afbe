// Reading a whole text file, with the errors a user can act on.
#pragma once
#include <string>

namespace exotwin {

// The whole content of the file at `path` (bytes as stored, no newline conversion). `what` names the
// file's role in messages ("model", "column map"; "" for none) and `expected` its content ("a YAML
// text file"). Throws InputError:
//   "<path>: cannot open <what> file (<reason>)" if it is missing, a directory or unreadable;
//   "<path>: binary data (NUL byte), expected <expected>" if it holds a NUL byte.
std::string ReadTextFile(const std::string& path, const std::string& what, const std::string& expected);

}  // namespace exotwin
