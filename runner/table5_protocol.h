// The whole Table 5 protocol of Hwang & Jeon 2015 on the twin, per subject: identification steps 1-4
// (scenarios/identification/*.yaml through RunScenario: plant, virtual CAN, joint modules, the real
// controller), least squares in-process (identification/identification.h: exo, then human), then relaxed
// passive-mode gait at 2 km/h (scenarios/gait_2kmh.yaml) and the RMS errors of identification/table5.h.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "identification/table5.h"

namespace exotwin {

struct Table5Options {
  std::vector<std::string> subjects;  // presets "S1".."S10"
  int strides = 10;                   // gait strides (2 s each) after the ramp
  int trials = 5;                     // trials per identification step
  double trial_duration = 40.0;       // s per trial
  std::string out_dir = "out/table5"; // DIR/<subject>/step{1..4}, DIR/<subject>/gait, model files
  std::string scenario_dir;           // holds identification/step*.yaml and gait_2kmh.yaml ("" = shipped)
  bool keep_logs = true;              // false: the step and gait CSVs are deleted after use
  std::function<void(const std::string&)> log;  // progress lines (may be empty)
};

// Outcome of one subject: the entry of Table 5 and every scenario check that failed ("step: name").
struct Table5SubjectRun {
  Table5Entry entry;
  std::vector<std::string> failed_checks;
  double wall_s = 0;
};

// Runs steps 1-4, identification and gait for one preset subject. Writes DIR/<subject>/exo.yaml and
// subject.yaml (identified). Throws InputError on bad options, SimulationError on divergence.
Table5SubjectRun RunTable5Subject(const std::string& subject, const Table5Options& opt);

// The shipped scenarios folder: scenarios/ of the data folder (core/data_dir.h).
std::string ShippedScenarioDir();

}  // namespace exotwin
