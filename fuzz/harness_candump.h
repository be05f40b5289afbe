// Contract of the candump fuzz target, shared with tests/protocol/candump_corpus_replay_test.cc: a
// candump log either reads completely or throws InputError; frames that are read are classic CAN
// (id <= 0x7FF, dlc <= 8) or error frames, with a finite time stamp; each is written back as the
// CAN log writer writes it (FormatCandumpLine), which must be valid text.
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/file_text.h"
#include "protocol/candump.h"

namespace exotwin::fuzz {

// Returns true if the whole log was read.
inline bool CandumpFile(const std::string& path) {
  try {
    for (const CandumpRecord& r : CandumpReader::ReadAll(path)) {
      if (!r.frame.error && (r.frame.id > kCanMaxId || r.frame.dlc > kCanMaxDlc))
        throw std::logic_error("CandumpReader returned an invalid data frame");
      if (!std::isfinite(r.frame.t)) throw std::logic_error("CandumpReader returned a non-finite time");
      if (const auto f = FindTextFault(FormatCandumpLine(r.frame, r.interface, 0)))
        throw std::logic_error("FormatCandumpLine: written text not valid: " + f->Where());
    }
    return true;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace exotwin::fuzz
