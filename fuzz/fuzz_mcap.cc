// libFuzzer target: an MCAP file (a ROS 2 bag) as ReadMcapRecord reads it, its messages decoded by
// their channels, and read through a column map as `convert --map` reads it. Contract: fuzz/harness.h
// McapBytes.
#include <cstdint>
#include <string>

#include "fuzz/harness.h"
#include "tests/temp_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const exotwin::testing::ScopedTempDir tmp("fuzz_mcap");
  exotwin::fuzz::McapBytes(std::string(reinterpret_cast<const char*>(data), size), tmp.path());
  return 0;
}
