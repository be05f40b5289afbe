// exotwin emg-fit (DESIGN.md): calibrates the EMG-driven hip and knee moment model from recordings
// (OpenSim storage files) and, with --report, writes the discrepancy loop's diagnosis.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>

#include "formats/csv_table.h"
#include "emg/emg_diagnose.h"
#include "emg/emg_recording.h"
#include "formats/number_text.h"
#include "app/commands.h"
#include "core/error.h"

namespace exotwin {
namespace {

CommandRunner RegisterEmgFit(CLI::App& app) {
  struct Opts {
    std::vector<std::string> emg, kin, mom;
    std::string map, out, report;
    bool linear = false;
    int blocks = 5;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "emg-fit", "Calibrate the EMG-driven hip and knee moment model (HJ15 eq. 26-27 and the causes the "
                 "discrepancy loop adds) from OpenSim storage files");
  sub->add_option("--emg", o->emg, "EMG envelopes (.sto); repeat for several recordings")->required();
  sub->add_option("--kinematics", o->kin, "inverse-kinematics angles (.sto/.mot), one per --emg")->required();
  sub->add_option("--moments", o->mom, "inverse-dynamics moments (.sto), one per --emg")->required();
  sub->add_option("--map", o->map, "muscle map YAML (EMG channel names per twin muscle); default: OpenSim names");
  sub->add_option("--out", o->out, "calibration output, EMGMODEL.yaml")->required();
  sub->add_option("--report", o->report, "folder for diagnosis.json and report.html of the discrepancy loop");
  sub->add_flag("--linear", o->linear,
                "fit the linear form of HJ15 eq. 26 only (alphas free of sign, no discrepancy loop)");
  sub->add_option("--blocks", o->blocks,
                  "one recording: contiguous cross-validation blocks, each left out in turn (default 5; several "
                  "recordings: each recording is left out instead)");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    const auto start = std::chrono::steady_clock::now();
    if (o->kin.size() != o->emg.size() || o->mom.size() != o->emg.size())
      throw InputError("emg-fit: " + std::to_string(o->emg.size()) + " --emg, " + std::to_string(o->kin.size()) +
                       " --kinematics and " + std::to_string(o->mom.size()) +
                       " --moments (expected one of each per recording, in step)");
    const MuscleMap map = o->map.empty() ? DefaultMuscleMap() : ReadMuscleMap(o->map);
    std::vector<EmgRecording> recs;
    for (size_t i = 0; i < o->emg.size(); ++i) recs.push_back(ReadEmgRecording(o->emg[i], o->kin[i], o->mom[i], map));
    for (const auto& r : recs)
      for (const auto& n : r.notes) std::fprintf(stderr, "emg-fit: %s: %s\n", r.source.c_str(), n.c_str());
    std::vector<const EmgRecording*> ptrs;
    for (const auto& r : recs) ptrs.push_back(&r);
    EmgDiagnoseOptions opt;
    opt.blocks = o->blocks;
    opt.strength_bounds = map.strength_bounds;
    opt.musculoskeletal = !o->linear;
    if (o->linear) opt.max_steps = 0, opt.robust_candidate = false, opt.signed_alphas = false, opt.musculoskeletal = false;
    const EmgDiagnosis d = DiagnoseEmg(ptrs, opt);
    std::vector<std::string> header = {"exotwin emg-fit: EMG-driven joint moment model (HJ15 eq. 26-27 + discrepancy loop)"};
    std::string files;
    for (size_t i = 0; i < o->emg.size(); ++i)
      files += (i ? "; " : "") + o->emg[i] + ", " + o->kin[i] + ", " + o->mom[i];
    header.push_back("recordings: " + files + "; map: " + map.source);
    for (const auto& s : d.selection) header.push_back(s);
    header.push_back("fit: the final structure on every sample; in 'fit', r2_cv / rms_cv are its cross-validation, the "
                     "heldout figures of the same structure fitted on the first 70 % of every recording");
    EmgTorqueModel out = d.calibration;
    for (int j = 0; j < 2; ++j) {
      const EmgJointFigures cv = out.figures[j];
      out.figures[j] = d.steps.back().model.figures[j];
      out.figures[j].r2_cv = cv.r2_cv, out.figures[j].rms_cv = cv.rms_cv;
    }
    WriteFileAtomic(o->out, EmgModelYaml(out, header));
    if (!o->report.empty()) WriteEmgDiagnosis(d, o->report);
    const char* jn[2] = {"hip", "knee"};
    std::printf("R^2 within 6 MAD: cv = %s left out in turn; last 30 %% = fit on the first 70 %%\n",
                d.folds_are_recordings ? (std::to_string(d.folds) + " recordings").c_str()
                                       : (std::to_string(d.folds) + " contiguous blocks").c_str());
    std::printf("%-44s %8s %8s %9s %9s %8s %8s\n", "step", "hip cv", "knee cv", "hip 30%", "knee 30%", "hip rms",
                "knee rms");
    for (const auto& s : d.steps)
      std::printf("%-44s %8.3f %8.3f %9.3f %9.3f %8.2f %8.2f\n", s.added.substr(0, 44).c_str(), s.model.figures[0].r2_cv,
                  s.model.figures[1].r2_cv, s.model.figures[0].r2_heldout_trim, s.model.figures[1].r2_heldout_trim,
                  s.model.figures[0].rms_heldout_trim, s.model.figures[1].rms_heldout_trim);
    for (int j = 0; j < 2; ++j)
      std::printf("%s: cross-validated R^2 %.3f (linear form %.3f); last 30 %% R^2 %.3f (all samples %.3f), linear "
                  "form %.3f (all samples %.3f)\n",
                  jn[j], d.steps.back().model.figures[j].r2_cv, d.steps.front().model.figures[j].r2_cv,
                  d.steps.back().model.figures[j].r2_heldout_trim, d.steps.back().model.figures[j].r2_heldout,
                  d.steps.front().model.figures[j].r2_heldout_trim, d.steps.front().model.figures[j].r2_heldout);
    const EmgMskModel& msk = d.calibration.msk;
    if (msk.present) {
      std::printf("%-44s %8.3f %8.3f %9s %9s %8.2f %8.2f\n", "musculoskeletal form (gait2392 + Hill)", msk.r2_cv[0],
                  msk.r2_cv[1], "-", "-", msk.rms_cv[0], msk.rms_cv[1]);
      for (int j = 0; j < 2; ++j)
        std::printf("%s: %s form chosen (cross-validated R^2 linear %.3f, musculoskeletal %.3f); the recorded muscles can "
                    "reach %.1f %% of the calibration moment at full activation, %.1f %% at their recorded activation "
                    "(largest strength %.1f F_max)\n",
                    jn[j], d.calibration.msk_form[j] ? "musculoskeletal" : "linear", d.calibration.figures[j].r2_cv,
                    msk.r2_cv[j], 100 * msk.reachable_share[j], 100 * msk.reachable_share_recorded[j],
                    kStrengthHi);  // the map may narrow it per channel
      std::map<std::string, std::string> terms;  // per synthesized muscle: its sources and weights
      for (const EmgMskMuscle& m : msk.muscles)
        if (m.synthesized) {
          std::string& t = terms[MuscleName(m.muscle)];
          t += (t.empty() ? "" : ", ") + m.channel + " " + NumberText(m.strength, 3);
        }
      for (const auto& [muscle, list] : terms)
        std::printf("the missing %s synthesized from the recorded excitations (strength x synergy weight: %s)\n",
                    muscle.c_str(), list.c_str());
      if (!terms.empty()) {
        std::printf("the synthesized activation x strength peaks at %.3f (a muscle's at most %.1f)\n",
                    msk.synthesized_peak, kStrengthHi);
        if (msk.synthesized_peak > kStrengthHi)
          std::fprintf(stderr, "emg-fit: warning: the synthesized muscle's activation x strength peaks at %.3f, above a "
                       "muscle's %.1f: the recorded excitations do not carry it\n", msk.synthesized_peak, kStrengthHi);
      }
    }
    for (int j = 0; j < 2; ++j)
      std::printf("%s: the estimate holds all but %g %% of its variance below %.1f Hz; the measured moment has %.1f %% of "
                  "its variance above (the estimate %.2f %%): R^2 cannot pass %.3f in that band\n",
                  jn[j], 100 * kBandResidue, d.ceiling[j].band_hz, 100 * d.ceiling[j].share_above,
                  100 * d.ceiling[j].estimate_share, d.ceiling[j].r2);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "emg-fit: wrote %s in %s s (the musculoskeletal form %s s of it)\n", o->out.c_str(),
                 NumberText(secs, 3).c_str(), NumberText(d.calibration.msk.seconds, 3).c_str());
    return 0;
  };
}

const CommandRegistration kEmgFit(RegisterEmgFit);

}  // namespace
}  // namespace exotwin
