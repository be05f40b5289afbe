// Helpers for tests that run the exotwin executable (path in EXOTWIN_BIN, set by CTest).
#pragma once
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "tests/temp_dir.h"

namespace exotwin::testing {

// A MODEL.yaml of the exoskeleton with a subject (Table 3/4 values, Riener passive torque), for the
// commands that take --params.
inline constexpr char kSubjectModelYaml[] =
    "L1: 0.41\n"
    "exo:   {J1: 3.02, J2: 0.74, X1: 3.85, X2: 1.74, Y1: 0.15, Y2: 0.16}\n"
    "human: {J1: 1.69, J2: 0.37, X1: 4.54, X2: 1.20, Y1: -0.16, Y2: 0.42}\n"
    "passive: riener1999\n"
    "effects: []\n";

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout + stderr
};

inline std::string ExotwinBin() {
  const char* b = std::getenv("EXOTWIN_BIN");
  return b ? b : std::string(EXOTWIN_SOURCE_DIR) + "/build/app/exotwin";
}

// Runs `exotwin <args>` through the shell, capturing stdout and stderr.
inline RunResult RunExotwin(const std::string& args) {
  RunResult r;
  const std::string cmd = ExotwinBin() + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) r.output.append(buf, n);
  const int st = pclose(p);
  r.exit_code = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

// Starts `bin <args>` in a child process (stdout and stderr to `log`) and returns its pid, -1 if fork
// fails; the caller waits for it (waitpid).
inline pid_t StartProgram(const std::string& bin, std::vector<std::string> args, const std::string& log = "/dev/null") {
  args.insert(args.begin(), bin);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    freopen(log.c_str(), "w", stdout);
    dup2(fileno(stdout), fileno(stderr));
    execv(bin.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

// Starts `exotwin <args>` in a child process (stdout and stderr to /dev/null): StartProgram.
inline pid_t StartExotwin(std::vector<std::string> args) { return StartProgram(ExotwinBin(), std::move(args)); }

// The deployable controller next to the exotwin executable (build/deploy/exotwin-controller).
inline std::string ControllerBin() {
  const std::string exotwin = ExotwinBin();
  const size_t slash = exotwin.rfind('/');
  const std::string build = exotwin.substr(0, exotwin.rfind('/', slash - 1));
  return build + "/deploy/exotwin-controller";
}

inline void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// The whole file (empty if it cannot be read).
inline std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace exotwin::testing
