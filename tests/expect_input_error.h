// Expects a call to throw exotwin::InputError whose message contains every given piece (the file,
// the line, what was expected): the bad-input tests' one check of a message.
#pragma once
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/error.h"

namespace exotwin::testing {

template <typename F>
void ExpectInputError(F f, const std::vector<std::string>& pieces) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    for (const auto& p : pieces) EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' not in: " << m;
  }
}

}  // namespace exotwin::testing
