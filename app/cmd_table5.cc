// `exotwin table5 [--subjects S1,...] [--strides 10] [--out DIR] [--trials N] [--trial-duration S]
//  [--plant FILE] [--plant-worn FILE | --realistic] [--seed N] [--knee-cuff] [--subject-passive]
//  [--diagnose [--fit torque|motion]]`:
// Hwang & Jeon 2015 Tables 3-5 reproduced by the twin, side by side with the paper (identification
// steps 1-4 and relaxed gait through the closed loop, per subject; runner/table5_protocol.h), optionally
// through a plant with effects (the realistic EXOwheel of data/plants/) and with diagnose on the
// twin's own records. Writes DIR/table5.csv and DIR/table5.md (and DIR/table5_diagnosis.json with
// --diagnose) and prints the Markdown. Exit 1 if a scenario check failed, 2 on bad input.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <sstream>

#include "formats/csv_table.h"
#include "identification/table5.h"
#include "app/commands.h"
#include "core/error.h"
#include "core/data_dir.h"
#include "formats/model_file.h"
#include "runner/table5_protocol.h"
#include "sim/subjects.h"

namespace exotwin {
namespace {

std::vector<std::string> SplitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

CommandRunner RegisterTable5(CLI::App& app) {
  struct Opts {
    std::string subjects = "S1,S2,S3,S4,S5,S6,S7,S8,S9,S10", out = "out/table5", scenarios, plant, plant_worn;
    int strides = 10, trials = 5;
    uint64_t seed = 1;
    double trial_duration = 40.0;
    bool drop_logs = false, realistic = false, diagnose = false, knee_cuff = false, subject_passive = false;
    std::string fit = "torque";
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "table5", "Hwang & Jeon 2015 Tables 3-5 on the twin (identify steps 1-4, then relaxed gait), next to the paper");
  sub->add_option("--subjects", o->subjects, "comma-separated presets (default S1,...,S10)");
  sub->add_option("--strides", o->strides, "gait strides at 2 km/h (2 s each, default 10)");
  sub->add_option("--out", o->out, "output folder (default out/table5)");
  sub->add_option("--trials", o->trials, "trials per identification step (default 5, as the paper)");
  sub->add_option("--trial-duration", o->trial_duration, "s per identification trial (default 40)");
  sub->add_option("--scenarios", o->scenarios, "folder with identification/step*.yaml and gait_2kmh.yaml");
  sub->add_flag("--drop-logs", o->drop_logs, "delete the per-step CSV logs after use");
  sub->add_option("--plant", o->plant,
                  "model file whose effects the plant carries in every scenario (the device; its parameters unused)");
  sub->add_option("--plant-worn", o->plant_worn,
                  "model file whose effects are added where the subject wears the exoskeleton (steps 3-4, gait)");
  sub->add_flag("--realistic", o->realistic,
                "the shipped realistic EXOwheel: --plant data/plants/exowheel_realistic.yaml --plant-worn "
                "data/plants/relaxed_leg.yaml");
  sub->add_option("--seed", o->seed,
                  "seed of the per-subject draws of a plant effect with a cv field (passive_moment; default 1)");
  sub->add_flag("--knee-cuff", o->knee_cuff,
                "steps 3-4 fit the knee cuff's compliance with the human's segments (identify --knee-cuff)");
  sub->add_flag("--subject-passive", o->subject_passive,
                "steps 3-4 fit the subject's factor on the passive model and the limb's damping (identify "
                "--subject-passive)");
  sub->add_flag("--diagnose", o->diagnose,
                "diagnose the gait and the steps 3-4 records with the identified model (a section of the output)");
  sub->add_option("--fit", o->fit,
                  "with --diagnose, the gait records' fit: torque (default) or motion (the forward plant simulated on "
                  "the gait, diagnosis/motion_fit.h); the steps 3-4 records keep the torque fit");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    Table5Options opt;
    opt.subjects = SplitList(o->subjects);
    if (opt.subjects.empty()) throw InputError("--subjects: expected a comma-separated list such as S1,S2");
    for (const std::string& s : opt.subjects) PresetSubject(s);  // validates the names up front
    opt.strides = o->strides;
    opt.trials = o->trials;
    opt.trial_duration = o->trial_duration;
    opt.out_dir = o->out;
    opt.scenario_dir = o->scenarios;
    opt.keep_logs = !o->drop_logs;
    if (o->realistic && (!o->plant.empty() || !o->plant_worn.empty()))
      throw InputError("--realistic: names its own plant files; give it or --plant/--plant-worn, not both");
    opt.plant_file = o->realistic ? DataPath("data/plants/exowheel_realistic.yaml") : o->plant;
    opt.plant_worn_file = o->realistic ? DataPath("data/plants/relaxed_leg.yaml") : o->plant_worn;
    Table5PlantEffects(opt, true);  // reads both files up front: a bad file is exit 2 before any run
    opt.diagnose = o->diagnose;
    opt.knee_cuff = o->knee_cuff;
    opt.subject_passive = o->subject_passive;
    opt.gait_fit = ParseDiagnoseFit(o->fit, "table5 --fit");
    if (opt.gait_fit == DiagnoseFit::kMotion && !o->diagnose)
      throw InputError("table5 --fit motion: expected --diagnose with it");
    opt.seed = o->seed;
    opt.log = [](const std::string& line) { std::fprintf(stderr, "table5: %s\n", line.c_str()); };
    const auto wall0 = std::chrono::steady_clock::now();
    std::vector<Table5Entry> entries;
    std::vector<Table5SubjectRun> runs;
    std::vector<std::string> failed;
    for (const std::string& s : opt.subjects) {
      runs.push_back(RunTable5Subject(s, opt));
      entries.push_back(runs.back().entry);
      failed.insert(failed.end(), runs.back().failed_checks.begin(), runs.back().failed_checks.end());
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    char header[512];
    std::snprintf(header, sizeof(header),
                  "# Hwang & Jeon 2015 Tables 3-5 on exotwin\n\n%zu subject(s); identification %d trial(s) x "
                  "%.0f s per step; gait %d strides at 2 km/h after the ramp; %.0f s wall.",
                  entries.size(), opt.trials, opt.trial_duration, opt.strides, wall);
    std::string md = Table5Markdown(entries, header);
    if (!opt.plant_file.empty() || !opt.plant_worn_file.empty() || opt.diagnose)
      md += Table5DiagnosisMarkdown(opt, runs);
    if (opt.diagnose) WriteFileAtomic(opt.out_dir + "/table5_diagnosis.json", Table5DiagnosisJson(runs));
    WriteFileAtomic(opt.out_dir + "/table5.md", md);
    WriteFileAtomic(opt.out_dir + "/table5.csv", Table5Csv(entries));
    std::printf("%s", md.c_str());
    for (const std::string& f : failed) std::fprintf(stderr, "table5: check failed: %s\n", f.c_str());
    return failed.empty() ? 0 : 1;
  };
}

const CommandRegistration kTable5(RegisterTable5);

}  // namespace
}  // namespace exotwin
