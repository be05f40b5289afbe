// Internal hinges of the forward plant for backlash and series compliance (DESIGN.md "Effects in the
// forward plant"): MJCF text edits of the leg model (sim/mjcf_text.h), compiled by Plant::CarryEffects.
// The measured hinges hip and knee stay the driven, motor-side joints; an internal hinge sits between
// a joint's driven part and the part that follows it.
#pragma once
#include <string>

#include "sim/plant_effects.h"

namespace exotwin {

enum class InternalHinge {
  kNone,
  // body <joint>_rotor takes over the measured hinge and the body's placement; the joint's body
  // (exo_thigh, exo_shank) with its whole subtree turns inside it about the internal hinge.
  kRotor,
  // the human segment (human_shank) turns about the internal hinge inside the exoskeleton segment.
  kHuman,
};

struct InternalJoints {
  InternalHinge kind[2] = {InternalHinge::kNone, InternalHinge::kNone};
  bool backlash[2] = {false, false};  // the hinge is a dead band (limited), else a strap (a spring)
  bool any() const { return kind[0] != InternalHinge::kNone || kind[1] != InternalHinge::kNone; }
  bool operator==(const InternalJoints& o) const {
    return kind[0] == o.kind[0] && kind[1] == o.kind[1] && backlash[0] == o.backlash[0] &&
           backlash[1] == o.backlash[1];
  }
};

// The internal hinges of fx: a backlash behind a rotor (the whole chain is behind the dead band); a
// series compliance behind a rotor without a human, else at the human segment.
InternalJoints InternalJointsOf(const PlantEffects& fx);

// Names in the edited model: the internal hinge of joint j ("hip_backlash", "knee_compliance") and
// the rotor body ("hip_rotor", "knee_rotor").
std::string InternalHingeName(int j, const InternalJoints& s);
std::string RotorBodyName(int j);

// The MJCF text (comments removed) with the internal hinges of `s` added: for kRotor, the body of
// joint j (exo_thigh / exo_shank) becomes the child of a new body <joint>_rotor that carries the
// body's placement and its measured hinge, and gains the internal hinge (same axis; a dead band is
// limited, its range written by the Plant); for kHuman, human_shank gains the internal hinge. Masses,
// ranges, stiffness and the hinge position are written by the Plant after compilation. Throws
// InputError naming `source` when a body or hinge is missing.
std::string AddInternalJoints(const std::string& xml, const std::string& source, const InternalJoints& s);

}  // namespace exotwin
