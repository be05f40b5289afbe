// RunScenario's dispatch to the device runners and the scenario's subject: see runner.h. The end of a
// run (checks, result.json) is in run_result.cc.
#include "runner/runner.h"

#include <filesystem>
#include <system_error>

#include "formats/model_file.h"
#include "core/error.h"
#include "core/output_path.h"
#include "runner/emg_calibration_protocol.h"
#include "runner/exowheel_runner.h"
#include "runner/exowheel_setup.h"
#include "runner/hal_runner.h"
#include "sim/mjcf_cache.h"
#include "sim/muscles.h"
#include "sim/plant.h"
#include "sim/plant_effects.h"
#include "sim/subjects.h"

namespace exotwin {

std::optional<Subject> ScenarioSubject(const Scenario& s) {
  if (!s.subject.preset.empty()) return PresetSubject(s.subject.preset);
  if (s.subject.random_seed) return DrawSubject(*s.subject.random_seed, 0);
  return std::nullopt;
}

ContractionProgramme IsometricProgrammeOf(const HumanSpec& h, uint64_t run_seed) {
  return IsometricProgramme(h.behaviour == "isometric_hip" ? 0 : 1, h.contractions, h.levels[0], h.levels[1],
                            h.cocontraction, h.programme_seed ? *h.programme_seed : run_seed);
}

LegParams ResolveSubject(const Scenario& s) {
  LegParams p;
  if (!s.subject.params_file.empty()) {
    p = ReadModelFile(s.subject.params_file);
  } else if (!s.subject.preset.empty()) {
    p = SubjectLegParams(PresetSubject(s.subject.preset));
  } else if (s.subject.random_seed) {
    p = SubjectLegParams(DrawSubject(*s.subject.random_seed, 0));
  } else {
    // Exo-only scenario without a subject: the mean exoskeleton of Table 3 at L1 = 0.41 m.
    p.L1 = 0.41;
    p.exo = {3.01, 0.74, 3.85, 1.73, 0.14, 0.18};
  }
  if (s.device == Device::kExowheelExoOnly) {
    p.human.reset();
    p.passive = PassiveModel::kNone;
  } else if (s.subject.params_file.empty()) {
    p.passive = s.subject.passive;
  }
  return p;
}

void KeepScenarioModel(const Scenario& s) {
  KeepMjcfModel(s.device == Device::kHal3 ? ShippedModelPath("hal3_knee.xml")
                                          : ExowheelMjcfPath(s.device != Device::kExowheelExoOnly));
}

void CheckScenarioRun(const Scenario& s, const RunOptions& opt) {
  const LegParams truth = ResolveSubject(s);
  if (!s.plant_effects.empty()) {  // as RunExowheelScenario hands them to the plant
    LegParams carried = truth;
    carried.effects = s.plant_effects;
    ToPlantEffects(carried, s.plant_effects_source);
  }
  if (s.device != Device::kHal3 && !s.emg_calibration && s.protocol.trajectory == TrajectoryKind::kFile)
    ReferenceOf(s);  // reads the motion file
  CreateOutputFolder(opt.out_dir);
  if (!opt.video_path.empty()) {
    std::error_code ec;
    if (std::filesystem::is_directory(opt.video_path, ec))
      throw InputError(opt.video_path + ": is a folder, expected the video file to write (.mp4)");
    CreateParentFolders(opt.video_path);
  }
  if (!opt.can_log.empty()) CreateParentFolders(opt.can_log);
  if (!opt.mcap.empty()) {
    std::error_code ec;
    if (std::filesystem::is_directory(opt.mcap, ec))
      throw InputError(opt.mcap + ": is a folder, expected the bag file to write (.mcap)");
    if (s.emg_calibration)
      throw InputError("--mcap: " + s.source + " is an emg_calibration protocol (its records are written per "
                       "trial in its folders); a bag is written of an EXOwheel or HAL-3 run");
    if (!s.log_measured_csv)
      throw InputError("--mcap: " + s.source + " logs no rows (logs: measured_csv: false); the bag holds the logs' rows");
    CreateParentFolders(opt.mcap);
  }
}

RunResult RunScenario(const Scenario& s, const RunOptions& opt) {
  CheckScenarioRun(s, opt);
  if (s.device == Device::kHal3) return RunHalScenario(s, opt);
  if (s.emg_calibration) return RunEmgCalibrationScenario(s, opt);
  return RunExowheelScenario(s, opt);
}

}  // namespace exotwin
