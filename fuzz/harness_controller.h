// Contract of the controller-file fuzz target, shared with tests/controller/corpus_replay_test.cc: a
// controller file either parses or throws InputError; one that parses is written back as `serve`
// writes it (ControllerFileYaml), which must be valid text, parse again and give the same text.
#pragma once
#include <stdexcept>
#include <string>

#include "controller/controller_config.h"
#include "core/error.h"
#include "core/file_text.h"

namespace exotwin::fuzz {

// Returns true if the text parsed.
inline bool ControllerText(const std::string& text) {
  controller::ControllerFile f;
  try {
    f = controller::ParseControllerFile(text, "fuzz.yaml");
  } catch (const InputError&) {
    return false;
  }
  const std::string written = controller::ControllerFileYaml(f, "fuzz");
  if (const auto fault = FindTextFault(written))
    throw std::logic_error("ControllerFileYaml: written text not valid: " + fault->Where());
  const controller::ControllerFile back = controller::ParseControllerFile(written, "roundtrip.yaml");  // must not throw
  if (controller::ControllerFileYaml(back, "fuzz") != written)
    throw std::logic_error("ControllerFileYaml: the written file does not read back to itself");
  return true;
}

}  // namespace exotwin::fuzz
