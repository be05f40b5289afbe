// libFuzzer target: the scenario YAML parser (ParseScenarioYaml).
// Contract: any input either parses or throws InputError.
#include <cstdint>
#include <string>

#include "core/error.h"
#include "runner/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    exotwin::ParseScenarioYaml(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
  } catch (const exotwin::InputError&) {
  }
  return 0;
}
