// exotwin: a MuJoCo digital twin of a human leg in a lower-limb rehabilitation exoskeleton.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <vector>

#include "app/commands.h"
#include "core/error.h"
#include "sim/plant.h"

int main(int argc, char** argv) {
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
