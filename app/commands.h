// Sub-commands of the exotwin executable. Each registers its options on a CLI11 app and returns the
// process exit code when run (0 success, 1 a check failed or the run failed, 2 bad input).
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace exotwin {

using CommandRunner = std::function<int()>;  // returns -1 when its sub-command was not selected
using CommandFactory = CommandRunner (*)(CLI::App& app);

// Every app/cmd_*.cc registers its sub-command with a file-scope CommandRegistration; main() adds
// them all (app/ is an object library, so no registration is dropped by the linker).
std::vector<CommandFactory>& CommandFactories();
struct CommandRegistration {
  explicit CommandRegistration(CommandFactory f) { CommandFactories().push_back(f); }
};

}  // namespace exotwin
