// can-utils candump log files ("candump -l" format), one frame per line:
//   (1700000000.123456) can0 123#DEADBEEF
// Time stamps are written as epoch_s + simulated time, to the microsecond. Error frames are written
// as candump writes SocketCAN error frames (CAN_ERR_FLAG | CAN_ERR_PROT): 20000080#0000000000000000.
#pragma once
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "core/file_text.h"
#include "protocol/can_frame.h"

namespace exotwin {

class CandumpWriter {
 public:
  // Opens (truncates) path; epoch_s (s) is added to every simulated time stamp. Throws InputError
  // when the file cannot be created.
  CandumpWriter(const std::string& path, std::string interface = "can0", int64_t epoch_s = 0);
  ~CandumpWriter();
  CandumpWriter(const CandumpWriter&) = delete;
  CandumpWriter& operator=(const CandumpWriter&) = delete;
  // Appends one line for f (time f.t, s >= -epoch_s) and flushes it to the OS, so an abort loses
  // nothing already written. Throws std::runtime_error on a write failure.
  void Write(const CanFrame& f);
  int64_t lines() const { return lines_; }

 private:
  std::string path_, interface_;
  int64_t epoch_s_;
  std::string line_;  // the line being written (sized once: Write does not allocate)
  std::FILE* file_ = nullptr;
  int64_t lines_ = 0;
};

// One line of a candump log.
struct CandumpRecord {
  CanFrame frame;         // frame.t = log time stamp - epoch_s (s)
  std::string interface;  // e.g. "can0"
};

// Formats one log line without the newline (the writer's format).
std::string FormatCandumpLine(const CanFrame& f, const std::string& interface, int64_t epoch_s);

class CandumpReader {
 public:
  // Opens path; epoch_s (s) is subtracted from every time stamp. Throws InputError if unreadable.
  explicit CandumpReader(const std::string& path, int64_t epoch_s = 0);
  // Reads the next frame into *out; false at end of file. Empty lines are skipped. Throws
  // InputError naming the file and line for a line that is not valid text (core/file_text.h), a malformed line, an extended (29-bit) ID, a remote or
  // a CAN FD frame (only classic 11-bit data and error frames are supported).
  bool Next(CandumpRecord* out);
  // Reads every frame of a log (throws like Next).
  static std::vector<CandumpRecord> ReadAll(const std::string& path, int64_t epoch_s = 0);

 private:
  std::string path_;
  std::ifstream in_;
  TextCheck text_;
  int64_t epoch_s_;
  int line_ = 0;
};

}  // namespace exotwin
