// Sub-commands of the exotwin executable. Each registers its options on a CLI11 app and returns the
// process exit code when run (0 success, 1 a check failed or the run failed, 2 bad input).
#pragma once
#include <functional>
#include <string>

namespace CLI {
class App;
}

namespace exotwin {

using CommandRunner = std::function<int()>;

// Registers `predict` on `app`; the returned runner executes it after parsing.
CommandRunner RegisterPredict(CLI::App& app);

// Chooses the shipped MJCF for a parameter set: with a human the leg + exo, else the exo alone.
std::string DefaultModelFor(bool has_human);

}  // namespace exotwin
