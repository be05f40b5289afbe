// Tables 2-5 of Hwang & Jeon 2015 (Sensors 15) embedded as constants, so the binary needs no data
// directory. Same numbers as data/hwang2015_table{2,3,4,5}_*.csv (the tests compare them).
#pragma once
#include <array>

#include "model/lumped_params.h"

namespace exotwin {

constexpr int kPaperSubjects = 10;

// Table 2: subject characteristics. age (years), height (m), weight (kg), BMI (kg/m^2), thigh length
// L1 and lower-leg length L2 (m).
struct Table2Row {
  const char* subject;
  double age, height, weight, bmi, L1, L2;
};

// Table 3: identified exoskeleton lumped parameters (HJ15 eq. 4) per subject fitting.
struct Table3Row {
  const char* subject;
  LumpedParams exo;
};

// Table 4 anthropometric columns (the models give no Y): J (kg m^2), X (kg m).
struct AnthropometricColumns {
  double J1, J2, X1, X2;
};

// Table 4: identified human-limb lumped parameters and the De Leva / Dempster estimates.
struct Table4Row {
  const char* subject;
  LumpedParams identified;
  AnthropometricColumns deleva, dempster;
};

// Table 5: RMS error (N m) of estimated vs. measured torque in passive-mode gait training.
struct Table5Row {
  const char* subject;
  double hip_identified, hip_deleva, hip_dempster;
  double knee_identified, knee_deleva, knee_dempster;
};

// Rows S1..S10 in order.
const std::array<Table2Row, kPaperSubjects>& PaperTable2();
const std::array<Table3Row, kPaperSubjects>& PaperTable3();
const std::array<Table4Row, kPaperSubjects>& PaperTable4();
const std::array<Table5Row, kPaperSubjects>& PaperTable5();

// The Mean and SD rows printed under Table 3 (exo) and Table 4 (identified human), J/X/Y fields only.
LumpedParams PaperTable3Mean();
LumpedParams PaperTable3Sd();
LumpedParams PaperTable4IdentifiedMean();
LumpedParams PaperTable4IdentifiedSd();

}  // namespace exotwin
