// `exotwin identify --measured A.csv --measured B.csv [--known MODEL.yaml] [--map MAP.yaml] --out MODEL.yaml`
// (DESIGN.md): least-squares identification of the exoskeleton (steps 1-2) or, with --known, of the
// subject (steps 3-4), Hwang & Jeon 2015 sec. 3.2. --measured takes files or folders (every *.csv
// inside with the measured-data columns; others are skipped with a note), in any order.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "formats/column_map.h"
#include "diagnosis/derivative_cutoff.h"
#include "formats/csv_table.h"
#include "identification/identification.h"
#include "identification/one_joint_identification.h"
#include "model/one_joint.h"
#include "formats/mcap_reader.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "formats/number_text.h"
#include "app/commands.h"
#include "core/error.h"
#include "sim/realizability.h"

namespace exotwin {
namespace {

namespace fs = std::filesystem;

// Reads one --measured argument: a CSV file, a ROS 2 bag (an .mcap file or a rosbag2 folder), or a
// folder of CSVs (sorted by name), through the column map `map` when not empty.
void ReadMeasuredArg(const std::string& arg, const std::string& map, std::vector<MeasuredData>* out) {
  std::error_code ec;
  if (!fs::is_directory(arg, ec) || IsBagPath(arg)) {
    out->push_back(ReadMeasured(arg, map));
    return;
  }
  std::vector<std::string> csvs;
  for (const auto& e : fs::directory_iterator(arg, ec))
    if (e.is_regular_file() && e.path().extension() == ".csv") csvs.push_back(e.path().string());
  std::sort(csvs.begin(), csvs.end());
  size_t used = 0;
  for (const std::string& f : csvs) {
    try {
      out->push_back(ReadMeasured(f, map));
      ++used;
    } catch (const InputError& e) {
      if (std::string(e.what()).find("missing required column") == std::string::npos) throw;
      std::fprintf(stderr, "identify: note: skipping %s (not a measured-data CSV)\n", f.c_str());
    }
  }
  if (used == 0)
    throw InputError(arg + ": folder holds no measured-data CSV, expected *.csv files with columns "
                           "t, q_hip, q_knee, tau_hip, tau_knee");
}

// "--emg-threshold VM=0.2" or "--emg-threshold 0.2" (every channel).
void ParseThreshold(const std::string& s, std::map<std::string, double>* th) {
  const size_t eq = s.find('=');
  const std::string name = eq == std::string::npos ? "*" : s.substr(0, eq);
  const std::string val = eq == std::string::npos ? s : s.substr(eq + 1);
  char* end = nullptr;
  const double v = std::strtod(val.c_str(), &end);
  if (val.empty() || *end != '\0' || !(v > 0) || !std::isfinite(v))
    throw InputError("--emg-threshold '" + s + "': expected CHANNEL=VOLTS or VOLTS with a positive value");
  (*th)[name] = v;
}

struct IdentifyOpts {
    std::vector<std::string> measured, thresholds;
    std::string known, map, out, passive = "riener1999", cutoff = "20";
    double L1 = 0.0, emg_reference = 2.0, emg_envelope = 0.0, trim = 0.1;
    bool friction = false, knee_cuff = false, subject_passive = false;
};

// identify's one-joint case (DESIGN.md "One-joint devices"): I and mgl (with --friction R and C) from
// swings of the joint; --known and the two-joint options do not apply.
int IdentifyOneJointFiles(const std::vector<MeasuredData>& files, const IdentifyOpts& o, bool cutoff_given) {
  if (!o.known.empty())
    throw InputError("--known " + o.known + ": one-joint records (" + files.front().source +
                     ") are identified without a known part, expected no --known");
  if (o.L1 != 0.0) throw InputError("--L1: a one-joint record has no thigh, expected no --L1");
  std::vector<const MeasuredData*> recs;
  for (const MeasuredData& f : files) recs.push_back(&f);
  std::string why;
  const double cutoff = ResolveCutoffOption(o.cutoff, "--cutoff", recs, kOneJointL1, LegParams{}.g, &why);
  if (!cutoff_given) std::fprintf(stderr, "identify: assumed: derivative cutoff 20 Hz (--cutoff HZ|auto)\n");
  if (o.cutoff == "auto") std::fprintf(stderr, "identify: derivative cutoff %s\n", why.c_str());
  const OneJointEstimate e = IdentifyOneJoint(files, cutoff, o.trim, o.friction);
  for (size_t k = 0; k < e.names.size(); ++k)
    std::fprintf(stderr, "identify: %s = %.5g +- %.2g (standard error)\n", e.names[k].c_str(), e.value[k], e.se[k]);
  std::fprintf(stderr, "identify: one joint, %zu samples, condition number %.2f, residual RMS %.4f N m\n", e.samples,
               e.condition, e.rmse);
  WriteFileAtomic(o.out, ModelToYaml(OneJointParamsOf(e), "exotwin identify: one-joint device (HKS05 eq. 4)",
                                     OneJointIdentificationYaml(e, cutoff)));
  return 0;
}

CommandRunner RegisterIdentify(CLI::App& app) {
  using Opts = IdentifyOpts;
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "identify", "Least-squares identification of the lumped parameters (Hwang & Jeon 2015, steps 1-4)");
  sub->add_option("--measured", o->measured,
                  "measured-data CSV, folder of CSVs or ROS 2 bag (with --map): the knee-swing and hip-swing "
                  "recordings, any order")
      ->required();
  sub->add_option("--map", o->map, "column map (YAML) applied to every --measured file (foreign CSVs, ROS 2 bags)");
  sub->add_option("--known", o->known, "MODEL.yaml holding the exoskeleton (exo:); identifies the human");
  sub->add_option("--out", o->out, "MODEL.yaml to write")->required();
  sub->add_option("--L1", o->L1, "thigh length, m (default: from --known, else 0.41)");
  sub->add_option("--passive", o->passive, "passive elastic model subtracted in steps 3-4")
      ->check(CLI::IsMember({"none", "riener1999"}));
  sub->add_option("--emg-reference", o->emg_reference,
                  "s of relaxed EMG at the start of each file for the eq. (13) threshold (default 2)");
  sub->add_option("--emg-threshold", o->thresholds,
                  "eq. (13) threshold instead of the reference: CHANNEL=V (e.g. VM=0.3) or V for all");
  sub->add_option("--emg-envelope", o->emg_envelope,
                  "s, moving average of the rectified EMG before thresholding (default 0: per sample)");
  sub->add_option("--cutoff", o->cutoff,
                  "derivative filter cutoff in Hz, or 'auto' (chosen from the data by held-out "
                  "prediction error over every file); default 20 (Hwang & Jeon sec. 3.2)");
  sub->add_option("--trim", o->trim, "s dropped at both ends of every file (default 0.1)");
  sub->add_flag("--knee-cuff", o->knee_cuff,
                "steps 3-4: fit the knee cuff's compliance (a strap stiffer than 100 N m/rad) with the "
                "human's segments; default: a rigid cuff, as the paper");
  sub->add_flag("--subject-passive", o->subject_passive,
                "steps 3-4: fit the subject's factor on the passive model and the limb's damping per joint "
                "(the model carries them as passive_moment and viscous_friction); default: as the paper");
  sub->add_flag("--friction", o->friction,
                "one-joint records: identify the device's R and C too (HKS05 eq. 4), besides I and mgl");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    IdentificationOptions opt;
    opt.passive = o->passive == "none" ? PassiveModel::kNone : PassiveModel::kRiener1999;
    opt.trim_s = o->trim;
    if (o->knee_cuff) opt.human_side.max_knee_compliance = kKneeCuffMaxCompliance;
    opt.human_side.subject_passive = o->subject_passive;
    opt.selection.reference_s = o->emg_reference;
    opt.selection.envelope_s = o->emg_envelope;
    for (const std::string& t : o->thresholds) ParseThreshold(t, &opt.selection.thresholds);
    if (!(o->trim >= 0)) throw InputError("--trim: expected a time >= 0 s");
    if (o->knee_cuff && o->known.empty())
      throw InputError("--knee-cuff: the knee cuff is the human's (steps 3-4), expected --known MODEL.yaml");
    if (o->subject_passive && o->known.empty())
      throw InputError("--subject-passive: the passive moment is the human's (steps 3-4), expected --known MODEL.yaml");
    if (o->subject_passive && o->passive == "none")
      throw InputError("--subject-passive: fits the subject's factor on the passive model, expected --passive riener1999");
    if (!(o->emg_reference > 0)) throw InputError("--emg-reference: expected a time > 0 s");
    if (!(o->emg_envelope >= 0)) throw InputError("--emg-envelope: expected a time >= 0 s");
    if (o->L1 != 0.0 && !(o->L1 > 0.1 && o->L1 < 1.0))
      throw InputError("--L1: expected a thigh length in (0.1, 1.0) m, got " + std::to_string(o->L1));

    LegParams known;
    if (!o->known.empty()) {
      known = ReadModelFile(o->known);
      if (o->L1 != 0.0 && std::abs(o->L1 - known.L1) > 1e-12)
        throw InputError("--L1 " + std::to_string(o->L1) + " differs from L1 = " +
                         std::to_string(known.L1) + " in " + o->known + ", expected one thigh length");
      if (known.human)
        std::fprintf(stderr, "identify: note: the human: block of %s is replaced by the identified one\n",
                     o->known.c_str());
      if (!known.effects.empty())
        std::fprintf(stderr, "identify: note: the effects of %s are not used and not copied\n",
                     o->known.c_str());
    }
    std::vector<MeasuredData> files;
    for (const std::string& m : o->measured) ReadMeasuredArg(m, o->map, &files);
    if (files.front().one_joint) return IdentifyOneJointFiles(files, *o, sub->count("--cutoff") > 0);
    if (o->friction) throw InputError("--friction: for one-joint records (t, q_knee, tau_knee) only");
    for (const MeasuredData& f : files)
      if (f.one_joint)
        throw InputError(f.source + ": a one-joint record (no hip column) among the records of two joints of " +
                         files.front().source + ", expected t, q_hip, q_knee, tau_hip, tau_knee in every file");
    if (!o->known.empty())  // steps 3-4: the records are of a human wearing the device
      for (const MeasuredData& f : files) CheckHumanJointRange(f);
    const double L1 = o->L1 != 0.0 ? o->L1 : o->known.empty() ? 0.41 : known.L1;
    // Every default the identification rests on, L1 first (a wrong thigh length biases every step).
    std::string L1_source;
    if (o->L1 != 0.0)
      L1_source = "L1 = " + NumberText(L1, 4) + " m (--L1)";
    else if (o->known.empty())
      L1_source = "L1 = 0.41 m assumed (no --L1, no --known): give --L1 if this rig's thigh length differs";
    else
      L1_source = "L1 = " + NumberText(L1, 4) + " m from " + o->known;
    std::vector<std::string> assumed;
    if (o->L1 == 0.0) assumed.push_back(L1_source);
    if (!sub->count("--cutoff")) assumed.push_back("derivative cutoff 20 Hz (--cutoff HZ|auto)");
    if (!sub->count("--trim")) assumed.push_back("0.1 s trimmed at both ends of every file (--trim)");
    if (!o->known.empty() && !sub->count("--passive"))
      assumed.push_back("passive elastic torque riener1999 subtracted (--passive)");
    if (!o->known.empty() && o->thresholds.empty() && !sub->count("--emg-reference"))
      assumed.push_back("EMG activation threshold from the first 2 s of each file (--emg-reference, --emg-threshold)");
    for (const std::string& a : assumed) std::fprintf(stderr, "identify: assumed: %s\n", a.c_str());
    std::vector<const MeasuredData*> recs;
    for (const MeasuredData& f : files) recs.push_back(&f);
    std::string cutoff_why;
    opt.cutoff_hz = ResolveCutoffOption(o->cutoff, "--cutoff", recs, L1,
                                        o->known.empty() ? LegParams{}.g : known.g, &cutoff_why);
    if (o->cutoff == "auto") std::fprintf(stderr, "identify: derivative cutoff %s\n", cutoff_why.c_str());
    const IdentificationResult r = Identify(files, o->known.empty() ? nullptr : &known, L1, opt);

    std::string header = "exotwin identify: Hwang & Jeon 2015 ";
    header += o->known.empty() ? "steps 1-2 (exoskeleton alone)" : "steps 3-4 (subject; exo from " + o->known + ")";
    if (o->known.empty() && o->L1 == 0.0) header += "\n" + L1_source;
    std::string why;
    const LumpedParams& id = r.params.human ? *r.params.human : r.params.exo;
    if (!IsRealizable(id, r.params.L1, &why)) {
      std::fprintf(stderr, "identify: warning: identified %s parameters have no physically consistent "
                   "realization (%s); predict will refuse them. They rest on %s\n",
                   r.params.human ? "human" : "exo", why.c_str(), L1_source.c_str());
      header += "\nwarning: no physically consistent realization: " + why + "; " + L1_source;
    }
    for (const StepEstimate& s : r.steps)
      std::fprintf(stderr, "identify: step %d (%s): %zu of %zu samples, condition number %.2f, "
                   "residual RMS %.4f N m\n",
                   s.step, s.segment.c_str(), s.samples_used, s.samples_total, s.condition_number,
                   s.residual_rms);
    WriteFileAtomic(o->out, ModelToYaml(r.params, header, IdentificationYaml(r, opt)));
    return 0;
  };
}

const CommandRegistration kIdentify(RegisterIdentify);

}  // namespace
}  // namespace exotwin
