// `exotwin diagnose`: name what the twin gets wrong on measured data, extend it, measure the gain.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>

#include "formats/column_map.h"
#include "diagnosis/diagnose.h"
#include "formats/number_text.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "app/commands.h"
#include "core/error.h"
#include "core/heap_policy.h"

namespace exotwin {
namespace {

CommandRunner RegisterDiagnose(CLI::App& app) {
  struct Opts {
    std::string params, out, mjcf, map, cutoff = "auto", fit = "torque";
    std::vector<std::string> measured;
    double holdout = 0.3;
    int max_effects = 6;
    bool no_completeness = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "diagnose", "Where twin and measured data disagree, the cause, the extended model and its gain");
  sub->add_option("--params", o->params, "MODEL.yaml of the twin")->required();
  sub->add_option("--measured", o->measured,
                  "measured-data CSV or ROS 2 bag (with --map); repeat for several records of one device (one set of effects, "
                  "validated on whole records left out)")->required();
  sub->add_option("--out", o->out, "output folder (diagnosis.json, extended.yaml, report.html)")->required();
  sub->add_option("--holdout", o->holdout, "held-out fraction at the end of the record (default 0.3)");
  sub->add_option("--mjcf", o->mjcf, "MJCF model to use instead of the shipped one");
  sub->add_option("--map", o->map, "column map (YAML) turning foreign --measured CSVs or ROS 2 bags into the schema");
  sub->add_option("--cutoff", o->cutoff,
                  "derivative filter cutoff in Hz, the torque filtered alike, or 'auto' (default: "
                  "chosen from the data by held-out prediction error)");
  sub->add_option("--max-effects", o->max_effects, "most effects named together (0..6, default 6)");
  sub->add_option("--fit", o->fit,
                  "torque (default: effects sized on the torque residual) or motion (effects fitted by simulating "
                  "the forward plant on the records, diagnosis/motion_fit.h)");
  sub->add_flag("--no-completeness", o->no_completeness,
                "skip the residual tests, the black-box ceilings and the search for terms beyond the table "
                "(diagnosis.json's completeness and ceiling not assessed)");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    KeepFreedMemoryForReuse();
    const DiagnoseFit fit = ParseDiagnoseFit(o->fit, "diagnose --fit");
    const LegParams params = ReadModelFile(o->params);
    DiagnoseOptions opt;
    opt.holdout_fraction = o->holdout;
    opt.mjcf = o->mjcf;
    opt.cutoff_hz = ParseCutoffOption(o->cutoff, "diagnose --cutoff");
    opt.max_effects = o->max_effects;
    opt.fit = fit;
    opt.assess = !o->no_completeness;
    std::vector<MeasuredData> data;
    std::string names;
    for (const std::string& m : o->measured) {
      MapReport report;
      data.push_back(ReadMeasured(m, o->map, 20, &report, [fit](const std::string& n) { return DiagnoseReadsColumn(n, fit); }));
      if (!o->map.empty()) std::fprintf(stderr, "diagnose: %s", report.Summary().c_str());
      CheckRecordFitsModel(params, o->params, data.back());
      if (params.human) CheckHumanJointRange(data.back());
      names += (names.empty() ? "" : ", ") + m;
    }
    const Diagnosis d = Diagnose(params, std::move(data), opt);
    WriteDiagnosis(d, o->out, o->params, names);
    std::printf("diagnose: derivative cutoff %s\n", d.cutoff.why.c_str());
    for (const auto& e : d.effects) {
      std::printf("diagnose: %s (%s) = %g %s [%g, %g]\n", e.effect.name.c_str(), e.effect.joint.c_str(),
                  e.effect.value, e.effect.unit.c_str(), e.ci_lo, e.ci_hi);
      for (const EffectAlias& a : e.aliases) std::printf("diagnose:   alias: %s\n", AliasText(a).c_str());
    }
    if (d.effects.empty()) std::printf("diagnose: no effect named\n");
    if (d.fit == DiagnoseFit::kMotion) {
      for (const TorqueOnlyEffect& t : d.torque_only)
        std::printf("diagnose: torque only: %s (%s) = %g %s%s\n", t.effect.name.c_str(), t.effect.joint.c_str(),
                    t.effect.value, t.effect.unit.c_str(),
                    t.simulated ? (": held-out simulated error " + NumberText(t.heldout_change_pct[0], 3) + " % hip, " +
                                   NumberText(t.heldout_change_pct[1], 3) + " % knee when added" +
                                   (std::isfinite(t.in_torque_twin_pct[0] + t.in_torque_twin_pct[1])
                                        ? ", " + NumberText(t.in_torque_twin_pct[0], 3) + " % hip, " +
                                              NumberText(t.in_torque_twin_pct[1], 3) + " % knee in the torque fit's twin"
                                        : std::string())).c_str()
                                : (" (" + t.why + ")").c_str());
      const int j0 = params.one_joint ? 1 : 0;
      for (int j = j0; j < 2; ++j)
        std::printf("diagnose: held-out simulated angle %s %.4f -> %.4f deg%s\n", j == 0 ? "hip" : "knee",
                    d.joints[j].rmse_before * 180 / M_PI, d.joints[j].rmse_after * 180 / M_PI,
                    d.leave_one_out ? (", whole records left out " + NumberText(d.left_out[j].rmse_before * 180 / M_PI, 4) +
                                       " -> " + NumberText(d.left_out[j].rmse_after * 180 / M_PI, 4) + " deg").c_str()
                                    : "");
      const SimulationScores& S = d.simulation;
      if (S.torque_fit_done) {
        std::string line = "diagnose: the torque fit's twin on the same rows: held-out";
        for (int j = j0; j < 2; ++j)
          line += std::string(j == j0 ? " " : ", ") + (j == 0 ? "hip " : "knee ") + NumberText(S.torque_fit_split[j].rmse_after * 180 / M_PI, 4);
        line += " deg";
        if (d.leave_one_out) {
          line += ", whole records left out";
          for (int j = j0; j < 2; ++j)
            line += std::string(j == j0 ? " " : ", ") + (j == 0 ? "hip " : "knee ") + NumberText(S.torque_fit_left_out[j].rmse_after * 180 / M_PI, 4);
          line += " deg";
        }
        for (size_t k = 0; k < S.torque_fit_not_carried.size(); ++k)
          line += (k == 0 ? " (not carried: " : ", ") + S.torque_fit_not_carried[k] + (k + 1 == S.torque_fit_not_carried.size() ? ")" : "");
        std::printf("%s\n", line.c_str());
        if (!S.torque_fit_why.empty()) std::printf("diagnose: %s\n", S.torque_fit_why.c_str());
      }
      std::printf("diagnose: report %s/report.html\n", o->out.c_str());
      return 0;
    }
    if (params.one_joint) {  // its one joint
      std::printf("diagnose: held-out rmse knee %.4f -> %.4f N m; report %s/report.html\n", d.joints[1].rmse_before,
                  d.joints[1].rmse_after, o->out.c_str());
      for (const RecordScore& r : d.records)
        std::printf("diagnose: %s: held-out %.4f -> %.4f N m (%.1f %%)%s, ceiling %.1f %% (null %.1f %%)\n", r.source.c_str(),
                    r.split[1].rmse_before, r.split[1].rmse_after, r.split[1].gain_pct,
                    d.leave_one_out ? (", left out " + NumberText(r.left_out[1].rmse_before) + " -> " +
                                       NumberText(r.left_out[1].rmse_after) + " N m (" +
                                       NumberText(r.left_out[1].gain_pct) + " %)").c_str()
                                    : "",
                    r.ceiling[1].gain_pct, r.ceiling_null[1].gain_pct);
      return 0;
    }
    std::printf("diagnose: held-out rmse hip %.4f -> %.4f N m, knee %.4f -> %.4f N m; report %s/report.html\n",
                d.joints[0].rmse_before, d.joints[0].rmse_after, d.joints[1].rmse_before,
                d.joints[1].rmse_after, o->out.c_str());
    if (d.leave_one_out)
      std::printf("diagnose: whole records left out: rmse hip %.4f -> %.4f N m, knee %.4f -> %.4f N m\n",
                  d.left_out[0].rmse_before, d.left_out[0].rmse_after, d.left_out[1].rmse_before,
                  d.left_out[1].rmse_after);
    return 0;
  };
}

const CommandRegistration kDiagnose(RegisterDiagnose);

}  // namespace
}  // namespace exotwin
