// Reading a text file, whole or in chunks, with the errors a user can act on, and the one check
// every text a user gives passes where it is read (files, YAML strings, command-line values).
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace exotwin {

// Valid text: UTF-8 (RFC 3629: no overlong form, no surrogate, nothing above U+10FFFF) holding no
// control character but tab, LF and CR (C0 controls, DEL and the C1 controls U+0080..U+009F are
// refused). Whatever passes can be written to JSON, CSV and HTML as it is. Applied by ReadTextFile and
// TextFileChunks (every file reader), by ParseYaml (core/yaml_fields.h: the text, then each string
// after its escapes, "\x85" or "\e" making a control character out of valid text), by the candump
// reader and by both executables to their command line (CheckCommandLine).
struct TextFault {
  size_t line = 1;   // 1-based; lines end at '\n'
  size_t byte = 1;   // 1-based byte of the offending byte (a sequence: its first byte) in that line
  std::string what;  // "invalid UTF-8 (byte 0xC1)", "control character 0x07", "binary data (NUL byte)", ...
  // "<what> at line L, byte B"
  std::string Where() const;
};

// The check of a text given in pieces (a file read in chunks): Feed each piece in order, then End.
// Both return false at the first fault (fault() then says which); after a fault the check stays failed.
class TextCheck {
 public:
  bool Feed(const char* p, size_t n);
  bool End();  // a UTF-8 sequence cut by the end of the text is a fault
  const std::optional<TextFault>& fault() const { return fault_; }

 private:
  bool Fail(size_t line, size_t byte, std::string what);
  size_t offset_ = 0;        // bytes fed so far
  size_t line_ = 1;          // line of the next byte
  size_t line_start_ = 0;    // offset of that line's first byte
  int need_ = 0;             // continuation bytes still expected by the sequence in progress
  unsigned char lo_ = 0x80, hi_ = 0xBF;  // range of the next continuation byte
  unsigned char lead_ = 0;   // the sequence's first byte
  size_t seq_line_ = 1, seq_byte_ = 1;  // where it started
  std::optional<TextFault> fault_;
};

// The first fault of a whole text (none: valid text).
std::optional<TextFault> FindTextFault(std::string_view text);

// `s` without the spaces, tabs and CRs at either end (a line of a text file, a field of it).
std::string Trim(const std::string& s);

// A string taken from a binary file (a topic, a name in a message) as a message may quote it: itself
// when it is valid text, else "<N bytes, not text>".
std::string ShownText(std::string_view s);

// Throws InputError("<source>: <fault.Where()>, expected <expected>") for a text that is not valid.
void CheckText(std::string_view text, const std::string& source, const std::string& expected);

// The command line's values (argv[1..argc-1]) as CheckText, before any is used: throws
// InputError("command line: argument N: <fault> at byte B, expected UTF-8 text").
void CheckCommandLine(int argc, const char* const* argv);

// The whole content of the file at `path` (bytes as stored, no newline conversion). `what` names the
// file's role in messages ("model", "column map"; "" for none) and `expected` its content ("a YAML
// text file"). Throws InputError:
//   "<path>: cannot open <what> file (<reason>)" if it is missing, a directory or unreadable;
//   "<path>: <fault> at line L, byte B, expected <expected>" if it is not valid text (TextFault:
//   "binary data (NUL byte)", "invalid UTF-8 (byte 0xC1)", "control character 0x1B", ...).
std::string ReadTextFile(const std::string& path, const std::string& what, const std::string& expected);

// The whole content of a binary file (an MCAP bag), unchecked; the open errors as ReadTextFile's.
std::string ReadBinaryFile(const std::string& path, const std::string& what);

// A text file read in chunks (for files too large to hold twice), with ReadTextFile's checks and
// messages: the constructor throws what ReadTextFile throws for a missing, directory or unreadable
// file; Read throws the text error for the first fault in the file so far (and "read error" if
// read(2) fails); a Read that reaches the end of the file also checks that no UTF-8 sequence is cut.
class TextFileChunks {
 public:
  TextFileChunks(const std::string& path, const std::string& what, const std::string& expected);
  // A binary file: the same reads and open errors, no text check.
  static TextFileChunks Binary(const std::string& path, const std::string& what);
  ~TextFileChunks();
  TextFileChunks(const TextFileChunks&) = delete;
  TextFileChunks(TextFileChunks&& o) noexcept;
  TextFileChunks& operator=(const TextFileChunks&) = delete;

  // Reads up to `n` bytes into `buf`; returns how many (0 only at the end of the file).
  size_t Read(char* buf, size_t n);
  // Size in bytes of a regular file (0 for a pipe or a device).
  size_t size() const { return size_; }
  // Reads the rest of the file (checking it as Read does) and returns the number of
  // '\n' in it and whether it ends with one (`ends_with_newline` unchanged if the rest is empty).
  // For a caller that stops early on an error of its own: the file's text error comes first.
  size_t DrainCountingNewlines(bool* ends_with_newline);

 private:
  [[noreturn]] void Fail(const std::string& reason) const;
  [[noreturn]] void FailText() const;
  std::string path_, role_, expected_;
  TextCheck check_;
  int fd_ = -1;
  size_t size_ = 0;
  bool text_ = true;  // the text check applies
};

}  // namespace exotwin
