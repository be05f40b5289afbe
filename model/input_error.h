// The one exception type for bad input (files, fields, command-line values). The CLI maps it to exit
// code 2. Messages name the place (file, line or field) and what was expected.
#pragma once
#include <stdexcept>
#include <string>

namespace exotwin {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace exotwin
