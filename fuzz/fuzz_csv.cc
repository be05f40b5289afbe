// libFuzzer target: the measured-data CSV reader (ReadMeasuredCsv + DeriveKinematics).
// Contract (fuzz/harness.h): any input either parses or throws InputError.
#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/harness.h"
#include "tests/temp_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The reader reads a file: one scratch file in a folder of this process, removed at exit (set
  // TMPDIR=/dev/shm for a tmpfs).
  static const exotwin::testing::ScopedTempDir tmp("fuzz_csv");
  static const std::string path = tmp.File("input.csv");
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  exotwin::fuzz::MeasuredCsvFile(path, tmp.path());
  return 0;
}
