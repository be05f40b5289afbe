// The whole Table 5 protocol of Hwang & Jeon 2015 on the twin, per subject: identification steps 1-4
// (scenarios/identification/*.yaml through RunScenario: plant, virtual CAN, joint modules, the real
// controller), least squares in-process (identification/identification.h: exo, then human), then relaxed
// passive-mode gait at 2 km/h (scenarios/gait_2kmh.yaml) and the RMS errors of identification/table5.h.
// Optionally with plant effects in every scenario (a realistic EXOwheel, data/plants/) and the
// discrepancy analysis (diagnosis/diagnose.h) of the twin's own records with the identified model.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "diagnosis/diagnose.h"
#include "identification/table5.h"
#include "model/lumped_params.h"

namespace exotwin {

struct Table5Options {
  std::vector<std::string> subjects;  // presets "S1".."S10"
  int strides = 10;                   // gait strides (2 s each) after the ramp
  int trials = 5;                     // trials per identification step
  double trial_duration = 40.0;       // s per trial
  std::string out_dir = "out/table5"; // DIR/<subject>/step{1..4}, DIR/<subject>/gait, model files
  std::string scenario_dir;           // holds identification/step*.yaml and gait_2kmh.yaml ("" = shipped)
  bool keep_logs = true;              // false: the step and gait CSVs are deleted after use
  // Plant effects (DESIGN.md "Effects in the forward plant"), each from a model file's effect list
  // (its parameters are not used), added to those of the scenarios themselves:
  std::string plant_file;       // the device's: every scenario (steps 1-4 and gait); "" = none
  std::string plant_worn_file;  // the worn leg's: where the subject wears the exoskeleton (steps 3-4, gait)
  bool diagnose = false;        // diagnose the gait and the steps 3-4 records with the identified model
  bool knee_cuff = false;        // steps 3-4 fit the knee cuff's compliance (identification.h HumanSideFit)
  bool subject_passive = false;  // steps 3-4 fit the subject's factor on P^ and the limb's damping
  // The gait records' fit (diagnosis/diagnose.h DiagnoseFit): kMotion sizes the effects by simulating the
  // forward plant on the gait (diagnosis/motion_fit.h; a strap or a dead band shows in the motion). The
  // steps 3-4 records (quasi-static identification trials, trials x trial_duration s each) keep the
  // torque fit either way.
  DiagnoseFit gait_fit = DiagnoseFit::kTorque;
  // Seed of the per-subject draws: an effect with a `cv` field (passive_moment) takes, for each subject,
  // a value drawn from (seed, subject name) (SubjectEffects).
  uint64_t seed = 1;
  std::function<void(const std::string&)> log;  // progress lines (may be empty)
};

// `diagnose` (diagnosis/diagnose.h, default options) on one set of a subject's records, with the
// identified model (Table5Entry::identified, passive riener1999, and the effects steps 3-4 identified:
// with subject_passive, the subject's passive factor and damping; else none).
struct Table5Diagnosis {
  std::string records;                  // "gait" or "steps 3-4"
  DiagnoseFit fit = DiagnoseFit::kTorque;
  bool done = false;
  std::string error;                    // why not done (the InputError's message)
  std::vector<Effect> named;            // the effects named, with their 95 % intervals in `ci`
  std::vector<std::pair<double, double>> ci;
  std::vector<std::string> not_identifiable;  // candidates these records cannot identify
  double cutoff_hz = 0;
  // Held-out, identified vs extended twin: the torque's RMS error (N m) for the torque fit, the simulated
  // angle's (rad) for the motion fit.
  double rmse_before[2] = {0, 0}, rmse_after[2] = {0, 0};
};

// Outcome of one subject: the entry of Table 5 and every scenario check that failed ("step: name").
struct Table5SubjectRun {
  Table5Entry entry;
  std::vector<std::string> failed_checks;
  std::vector<Table5Diagnosis> diagnoses;  // opt.diagnose: gait, then steps 3-4
  std::vector<Effect> plant_worn;          // the effects this subject's worn scenarios carried (drawn)
  double wall_s = 0;
};

// Runs steps 1-4, identification and gait for one preset subject. Writes DIR/<subject>/exo.yaml and
// subject.yaml (identified), and truth.yaml: the twin its worn records (steps 3-4, gait) came from, the
// preset with its passive model and the plant's effects, the subject's draws resolved. Throws
// InputError on bad options, SimulationError on divergence.
Table5SubjectRun RunTable5Subject(const std::string& subject, const Table5Options& opt);

// The effects of the plant a scenario of the protocol carries on top of its own: the device's in every
// scenario, plus the worn leg's where `worn` (steps 3-4, gait). Reads the files (InputError naming a
// missing or bad file, or an effect the plant cannot carry: sim/plant_effects.h).
std::vector<Effect> Table5PlantEffects(const Table5Options& opt, bool worn);

// `fx` with every effect that has a `cv` field (the inter-subject coefficient of variation of a
// passive_moment) drawn for `subject`: the subject's factor on Riener & Edrich's curves,
// 1 + value' = (1 + value) exp(s z - s^2 / 2), s = sqrt(ln(1 + cv^2)), z standard normal (Marsaglia
// polar, core/rng.h) from MixSeed(seed ^ MixSeed(FNV-1a of "subject/name/joint")): a log-normal
// factor of mean 1 + value and that coefficient of variation, positive; capped at kMaxPassiveScale
// (model/passive_torque.h). The `cv` field is dropped from the drawn effect. Same seed, same bits.
std::vector<Effect> SubjectEffects(std::vector<Effect> fx, const std::string& subject, uint64_t seed);

// Markdown of the plant's effects against what diagnose named per subject (value, % of the value that
// subject's plant carried at that joint and name; the drawn values per subject where a file has a cv), the held-out errors of the identified and the extended twin beside the
// paper's Table 5, and the candidates said not identifiable.
std::string Table5DiagnosisMarkdown(const Table5Options& opt, const std::vector<Table5SubjectRun>& runs);

// JSON of the diagnoses: {"subjects": [{"subject", "diagnoses": [{"records", "done", "error",
// "cutoff_hz", "effects": [{"name", "joint", "value", "unit", "ci95"}], "not_identifiable",
// "heldout": {"hip": {"rmse_before", "rmse_after"}, "knee": {...}}}]}]}.
std::string Table5DiagnosisJson(const std::vector<Table5SubjectRun>& runs);

// The shipped scenarios folder: scenarios/ of the data folder (core/data_dir.h).
std::string ShippedScenarioDir();

}  // namespace exotwin
