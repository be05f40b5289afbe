// libFuzzer target: the measured-data CSV reader (ReadMeasuredCsv + DeriveKinematics).
// Contract (fuzz/harness.h): any input either parses or throws InputError.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // ReadMeasuredCsv reads a file: one scratch file per process (tmpfs when available).
  static const std::string path = [] {
    const char* dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return std::string(dir) + "/exotwin_fuzz_csv_" + std::to_string(getpid()) + ".csv";
  }();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  exotwin::fuzz::MeasuredCsvFile(path);
  return 0;
}
