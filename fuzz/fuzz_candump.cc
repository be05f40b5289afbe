// libFuzzer target: the candump log reader (CandumpReader::ReadAll).
// Contract (fuzz/harness_candump.h): any input either reads or throws InputError.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/harness_candump.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The reader reads a file: one scratch file per process (tmpfs when available).
  static const std::string path = [] {
    const char* dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return std::string(dir) + "/exotwin_fuzz_candump_" + std::to_string(getpid()) + ".log";
  }();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  exotwin::fuzz::CandumpFile(path);
  return 0;
}
