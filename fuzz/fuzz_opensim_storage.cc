// libFuzzer target: OpenSim storage text (.sto / .mot): parsed, written back, its kinematics written as
// a measured-data CSV. Contract: fuzz/harness.h StorageText.
#include <cstdint>
#include <string>

#include "fuzz/harness.h"
#include "tests/temp_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const exotwin::testing::ScopedTempDir tmp("fuzz_sto");
  exotwin::fuzz::StorageText(std::string(reinterpret_cast<const char*>(data), size), tmp.path());
  return 0;
}
