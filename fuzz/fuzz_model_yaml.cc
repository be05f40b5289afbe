// libFuzzer target: the MODEL.yaml parser (ParseModelYaml, plus the ModelToYaml round trip).
// Contract (fuzz/harness.h): any input either parses or throws InputError.
#include <cstdint>
#include <string>

#include "fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  exotwin::fuzz::ModelYamlText(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
