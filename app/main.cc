// exotwin: a MuJoCo digital twin of a human leg in a lower-limb rehabilitation exoskeleton.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/error.h"
#include "core/file_text.h"
#include "sim/plant.h"

namespace {

// EXOTWIN_PEAK_FILE=PATH: at exit, the process's peak resident memory (VmHWM of /proc/self/status,
// kB) is written to PATH. `exotwin bench` reads it for its child processes: their ru_maxrss also
// counts the pages they shared with the parent between fork and exec.
std::string g_peak_file;

void WritePeak() {
  std::FILE* in = std::fopen("/proc/self/status", "r");
  if (!in) return;
  char line[256];
  long kb = -1;
  while (std::fgets(line, sizeof line, in))
    if (std::sscanf(line, "VmHWM: %ld kB", &kb) == 1) break;
  std::fclose(in);
  if (kb < 0) return;
  if (std::FILE* out = std::fopen(g_peak_file.c_str(), "w")) {
    std::fprintf(out, "%ld\n", kb);
    std::fclose(out);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (const char* f = std::getenv("EXOTWIN_PEAK_FILE"); f && *f) {
    g_peak_file = f;
    std::atexit(WritePeak);
  }
  try {  // every value is valid text before any is used (and later written to JSON, CSV or HTML)
    exotwin::CheckCommandLine(argc, argv);
  } catch (const exotwin::InputError& e) {
    std::fprintf(stderr, "exotwin: error: %s\n", e.what());
    return 2;
  }
  CLI::App app{"exotwin: digital twin of a leg in a rehabilitation exoskeleton"};
  app.require_subcommand(1);
  std::vector<exotwin::CommandRunner> runners;
  for (auto factory : exotwin::CommandFactories()) runners.push_back(factory(app));
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
  try {
    for (auto& run : runners) {
      const int rc = run();
      if (rc >= 0) return rc;
    }
    return 2;
  } catch (const exotwin::InputError& e) {
    std::fprintf(stderr, "exotwin: error: %s\n", e.what());
    return 2;
  } catch (const exotwin::SimulationError& e) {
    std::fprintf(stderr, "exotwin: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exotwin: internal error: %s\n", e.what());
    return 1;
  }
}
