// libFuzzer target: the column map (and the foreign CSV after "%%csv%%") as `convert --map` reads,
// applies and writes them. Contract: fuzz/harness.h ColumnMapText.
#include <cstdint>
#include <string>

#include "fuzz/harness.h"
#include "tests/temp_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const exotwin::testing::ScopedTempDir tmp("fuzz_column_map");
  exotwin::fuzz::ColumnMapText(std::string(reinterpret_cast<const char*>(data), size), tmp.path());
  return 0;
}
