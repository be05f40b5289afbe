// The project's two exception types.
//   InputError: bad input (files, fields, command-line values). The CLI maps it to exit code 2.
//     Messages name the place (file, line or field) and what was expected.
//   SimulationError: the simulation diverged (non-finite state, MuJoCo warning, non-finite output);
//     carries the simulated time (s) and the cause.
#pragma once
#include <stdexcept>
#include <string>

namespace exotwin {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class SimulationError : public std::runtime_error {
 public:
  // what(): "simulation diverged at t = <t> s: <cause>".
  SimulationError(double t, const std::string& cause);
  double time() const { return time_; }

 private:
  double time_;
};

}  // namespace exotwin
