// Reading a text file, whole or in chunks, with the errors a user can act on.
#pragma once
#include <cstddef>
#include <string>

namespace exotwin {

// The whole content of the file at `path` (bytes as stored, no newline conversion). `what` names the
// file's role in messages ("model", "column map"; "" for none) and `expected` its content ("a YAML
// text file"). Throws InputError:
//   "<path>: cannot open <what> file (<reason>)" if it is missing, a directory or unreadable;
//   "<path>: binary data (NUL byte), expected <expected>" if it holds a NUL byte.
std::string ReadTextFile(const std::string& path, const std::string& what, const std::string& expected);

// A text file read in chunks (for files too large to hold twice), with ReadTextFile's checks and
// messages: the constructor throws what ReadTextFile throws for a missing, directory or unreadable
// file; Read throws the NUL-byte error for a chunk holding one (and "read error" if read(2) fails).
class TextFileChunks {
 public:
  TextFileChunks(const std::string& path, const std::string& what, const std::string& expected);
  ~TextFileChunks();
  TextFileChunks(const TextFileChunks&) = delete;
  TextFileChunks& operator=(const TextFileChunks&) = delete;

  // Reads up to `n` bytes into `buf`; returns how many (0 only at the end of the file).
  size_t Read(char* buf, size_t n);
  // Size in bytes of a regular file (0 for a pipe or a device).
  size_t size() const { return size_; }
  // Reads the rest of the file (checking it for NUL bytes as Read does) and returns the number of
  // '\n' in it and whether it ends with one (`ends_with_newline` unchanged if the rest is empty).
  // For a caller that stops early on an error of its own: the file's NUL-byte error comes first.
  size_t DrainCountingNewlines(bool* ends_with_newline);

 private:
  [[noreturn]] void Fail(const std::string& reason) const;
  std::string path_, role_, expected_;
  int fd_ = -1;
  size_t size_ = 0;
};

}  // namespace exotwin
