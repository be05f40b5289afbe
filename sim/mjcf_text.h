// MJCF text edits before compilation (MuJoCo 2.2 has no model-editing API): reading a file, finding a
// body element, and compiling edited text in place of the file through MuJoCo's virtual file system.
#pragma once
#include <cstddef>
#include <string>

struct mjModel_;

namespace exotwin {

// The MJCF file's text with its comments removed. Throws InputError naming the file if unreadable.
std::string ReadMjcfText(const std::string& mjcf_path);

// A <body name="NAME" ...> element in MJCF text: [begin, open_end) its opening tag, [begin, end) the
// whole element up to and including its matching </body>.
struct BodyElement {
  size_t begin = 0, open_end = 0, end = 0;
};

// Finds body `name` (comments already removed). Throws InputError naming `source` if there is no such
// body, it is self-closing (no joints or children) or it is not closed.
BodyElement FindBodyElement(const std::string& xml, const std::string& name, const std::string& source);

// Compiles `xml` as if it were the file mjcf_path (a virtual file of its name: assets and includes
// resolve relative to the file's folder). Returns the model (the caller owns it), or throws InputError
// naming mjcf_path and `what` with MuJoCo's message if it does not load or loads with a warning.
mjModel_* LoadMjcfText(const std::string& mjcf_path, const std::string& xml, const std::string& what);

}  // namespace exotwin
