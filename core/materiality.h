// The materiality scale shared by the model's discrepancy tests: a change below this share of a
// signal's RMS (about its mean, for an angle) is not material. The diagnosis's torque and angle
// floors (diagnosis/diagnose_select.h) and the identification's knee cuff (identification.h) use it.
#pragma once

namespace exotwin {

constexpr double kMaterialShare = 0.0025;

}  // namespace exotwin
