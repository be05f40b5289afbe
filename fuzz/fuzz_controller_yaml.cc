// libFuzzer target: the controller file (ParseControllerFile) and what `serve` writes of one
// (ControllerFileYaml). Contract: fuzz/harness_controller.h.
#include <cstdint>
#include <string>

#include "fuzz/harness_controller.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  exotwin::fuzz::ControllerText(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
