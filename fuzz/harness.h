// The contract every fuzz target checks, shared with the corpus-replay tests (tests/analysis,
// tests/scenarios), so that the smoke run in the normal test suite checks exactly what the fuzzers do:
// any input either parses or throws exotwin::InputError. Anything else (another exception, a crash,
// a sanitizer report) is a bug.
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>

#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "core/error.h"

namespace exotwin::fuzz {

// Measured-data CSV file: parsed and validated (at least 2 rows, so the fuzzer reaches the
// validation quickly); when it has the 20 rows the CLI asks for, the kinematics are derived as
// `predict` does (filtering, resampling of non-uniform sampling). Returns true if it parsed.
inline bool MeasuredCsvFile(const std::string& path) {
  try {
    const MeasuredData d = ReadMeasuredCsv(path, 2);
    if (d.size() >= 20) {
      const Kinematics k = DeriveKinematics(d);
      // A derivation that "succeeds" with NaN or inf is a silent wrong result: a bug, not bad input.
      for (int j = 0; j < 2; ++j)
        for (const auto* v : {&k.q[j], &k.qd[j], &k.qdd[j]})
          for (double x : *v)
            if (!std::isfinite(x)) throw std::logic_error("DeriveKinematics: non-finite result");
    }
    return true;
  } catch (const InputError&) {
    return false;
  }
}

// MODEL.yaml text. A model that parses must also survive a round trip through ModelToYaml (what
// diagnose writes as extended.yaml must be loadable by every command).
inline bool ModelYamlText(const std::string& text) {
  LegParams p;
  try {
    p = ParseModelYaml(text, "fuzz.yaml");
  } catch (const InputError&) {
    return false;
  }
  ParseModelYaml(ModelToYaml(p), "roundtrip.yaml");  // must not throw at all
  return true;
}

}  // namespace exotwin::fuzz
