#include "core/error.h"

namespace exotwin {

SimulationError::SimulationError(double t, const std::string& cause)
    : std::runtime_error("simulation diverged at t = " + std::to_string(t) + " s: " + cause), time_(t) {}

}  // namespace exotwin
