#include "runner/table5_protocol.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "diagnosis/diagnose.h"
#include "identification/identification.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "formats/number_text.h"
#include "formats/csv_table.h"
#include "core/output_path.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "core/rng.h"
#include "model/passive_torque.h"
#include "runner/runner.h"
#include "runner/scenario.h"
#include "sim/paper_tables.h"
#include "sim/plant_effects.h"
#include "sim/subjects.h"

namespace exotwin {

namespace {

namespace fs = std::filesystem;

constexpr double kGaitTail = 0.2;  // s recorded after the last stride (filter edge)

// The scenario file `rel` of the folder with the subject and the trial settings substituted.
Scenario LoadStep(const Table5Options& opt, const std::string& rel, const std::string& subject) {
  const std::string dir = opt.scenario_dir.empty() ? ShippedScenarioDir() : opt.scenario_dir;
  Scenario s = ReadScenario(dir + "/" + rel);
  s.subject.preset = subject;
  s.subject.random_seed.reset();
  s.subject.params_file.clear();
  return s;
}

// Runs the scenario into `dir`, appends its failed checks to `failed` (prefixed by `tag`).
RunResult RunInto(const Scenario& s, const std::string& dir, const std::string& tag,
                  std::vector<std::string>* failed) {
  fs::remove_all(dir);
  RunOptions ro;
  ro.out_dir = dir;
  RunResult r = RunScenario(s, ro);
  for (const CheckResult& c : r.checks)
    if (!c.passed) failed->push_back(tag + ": " + c.name + " = " + std::to_string(c.value) + " (limit " + c.op + " " +
                                     std::to_string(c.limit) + ")");
  return r;
}

// Every measured*.csv of a run folder, sorted by name.
std::vector<MeasuredData> ReadRun(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("measured", 0) == 0 && e.path().extension() == ".csv") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(dir + ": the run wrote no measured*.csv");
  std::vector<MeasuredData> out;
  for (const std::string& f : files) out.push_back(ReadMeasuredCsv(f));
  return out;
}

void Log(const Table5Options& opt, const std::string& line) {
  if (opt.log) opt.log(line);
}

// The scenario's plant with the protocol's effects added (Table5PlantEffects(opt, worn)); the source
// that messages name lists the files they came from.
void AddPlant(const std::vector<Effect>& fx, const Table5Options& opt, bool worn, Scenario* s) {
  if (fx.empty()) return;
  s->plant_effects.insert(s->plant_effects.end(), fx.begin(), fx.end());
  std::string src = opt.plant_file;
  if (worn && !opt.plant_worn_file.empty()) src += (src.empty() ? "" : " + ") + opt.plant_worn_file;
  s->plant_effects_source = s->plant_effects_source.empty() ? src : s->plant_effects_source + " + " + src;
}

Table5Diagnosis DiagnoseRecords(const std::string& what, const LegParams& model,
                                const std::vector<const MeasuredData*>& records, DiagnoseFit fit) {
  Table5Diagnosis out;
  out.records = what;
  out.fit = fit;
  try {
    DiagnoseOptions dopt;
    dopt.fit = fit;
    const Diagnosis d = Diagnose(model, records, dopt);
    out.done = true;
    for (const DiagnosedEffect& e : d.effects) {
      out.named.push_back(e.effect);
      out.ci.emplace_back(e.ci_lo, e.ci_hi);
    }
    out.not_identifiable = d.not_identifiable;
    out.cutoff_hz = d.cutoff.hz;
    for (int j = 0; j < 2; ++j) {
      out.rmse_before[j] = d.joints[j].rmse_before;
      out.rmse_after[j] = d.joints[j].rmse_after;
    }
  } catch (const InputError& err) {
    out.error = err.what();
  }
  return out;
}

}  // namespace

std::string ShippedScenarioDir() { return DataPath("scenarios"); }

std::vector<Effect> SubjectEffects(std::vector<Effect> fx, const std::string& subject, uint64_t seed) {
  for (Effect& e : fx) {
    const auto cv = e.fields.find("cv");
    if (cv == e.fields.end()) continue;
    uint64_t h = 1469598103934665603ull;  // FNV-1a, 64 bit
    for (char ch : subject + "/" + e.name + "/" + e.joint) h = (h ^ static_cast<unsigned char>(ch)) * 1099511628211ull;
    NormalRng<NormalPolar> z(MixSeed(seed ^ MixSeed(h)));
    const double sd = std::sqrt(std::log(1.0 + cv->second * cv->second));
    const double factor = (1.0 + e.value) * std::exp(sd * z.Normal() - 0.5 * sd * sd);
    e.value = std::min(factor, kMaxPassiveScale) - 1.0;
    e.fields.erase(cv);
  }
  return fx;
}

std::vector<Effect> Table5PlantEffects(const Table5Options& opt, bool worn) {
  std::vector<Effect> fx;
  for (const std::string* path : {&opt.plant_file, &opt.plant_worn_file}) {
    if (path->empty() || (!worn && path == &opt.plant_worn_file)) continue;
    const LegParams file = ReadModelFile(*path);
    ToPlantEffects(file, *path);  // an effect the plant cannot carry: InputError naming effects[i]
    fx.insert(fx.end(), file.effects.begin(), file.effects.end());
  }
  return fx;
}

Table5SubjectRun RunTable5Subject(const std::string& subject, const Table5Options& opt) {
  if (opt.trials < 1) throw InputError("table5: --trials: expected at least 1");
  if (!(opt.trial_duration >= 5.0)) throw InputError("table5: --trial-duration: expected at least 5 s");
  if (opt.strides < 1) throw InputError("table5: --strides: expected at least 1");
  const Subject preset = PresetSubject(subject);  // throws InputError listing the valid names
  const std::vector<Effect> device_fx = SubjectEffects(Table5PlantEffects(opt, false), subject, opt.seed),
                            worn_fx = SubjectEffects(Table5PlantEffects(opt, true), subject, opt.seed);
  const auto wall0 = std::chrono::steady_clock::now();
  Table5SubjectRun run;
  run.plant_worn = worn_fx;
  Table5Entry& e = run.entry;
  e.subject = subject;
  const std::string base = opt.out_dir + "/" + subject;
  CreateOutputFolder(base);

  const char* steps[4] = {"identification/step1_exo_knee.yaml", "identification/step2_exo_hip.yaml",
                          "identification/step3_knee.yaml", "identification/step4_hip.yaml"};
  std::vector<MeasuredData> exo_files, human_files;
  for (int k = 0; k < 4; ++k) {
    Scenario s = LoadStep(opt, steps[k], subject);
    s.protocol.trials = opt.trials;
    s.protocol.duration = opt.trial_duration;
    AddPlant(k < 2 ? device_fx : worn_fx, opt, k >= 2, &s);
    if (k == 2) e.truth = ResolveSubject(s);  // exo + human + passive as the twin holds them
    const std::string dir = base + "/step" + std::to_string(k + 1);
    const RunResult r = RunInto(s, dir, subject + " step " + std::to_string(k + 1), &run.failed_checks);
    char line[200];
    std::snprintf(line, sizeof(line), "%s: step %d (%s) %d x %.0f s in %.1f s wall", subject.c_str(), k + 1,
                  s.name.c_str(), opt.trials, opt.trial_duration, r.metrics.at("wall_time_s"));
    Log(opt, line);
    std::vector<MeasuredData> files = ReadRun(dir);
    auto& into = k < 2 ? exo_files : human_files;
    for (MeasuredData& f : files) into.push_back(std::move(f));
    if (!opt.keep_logs) fs::remove_all(dir);
  }

  IdentificationOptions iopt;
  const IdentificationResult exo = Identify(exo_files, nullptr, preset.L1, iopt);
  WriteFileAtomic(base + "/exo.yaml", ModelToYaml(exo.params, "exotwin table5: " + subject + " steps 1-2",
                                                  IdentificationYaml(exo, iopt)));
  LegParams known = exo.params;
  if (opt.knee_cuff) iopt.human_side.max_knee_compliance = kKneeCuffMaxCompliance;
  iopt.human_side.subject_passive = opt.subject_passive;
  const IdentificationResult human = Identify(human_files, &known, preset.L1, iopt);
  WriteFileAtomic(base + "/subject.yaml", ModelToYaml(human.params, "exotwin table5: " + subject + " steps 3-4",
                                                      IdentificationYaml(human, iopt)));
  e.identified = human.params;

  Scenario gait = LoadStep(opt, "gait_2kmh.yaml", subject);
  gait.subject.passive = PassiveModel::kRiener1999;
  gait.human.behaviour = "relaxed";
  gait.protocol.trials = 1;
  // strides x period after the ramp, plus a tail so that the derivative filter's edge stays outside.
  const double t_from = gait.protocol.ramp, t_to = t_from + opt.strides * gait.protocol.stride_period;
  gait.protocol.duration = t_to + kGaitTail;
  AddPlant(worn_fx, opt, true, &gait);
  // The twin the subject's gait record came from (its steps 3-4 records too: the same subject and
  // worn plant): the preset's exoskeleton and human, the passive model, the plant's effects with the
  // subject's draws. With it, diagnose and replay on those records tell what identification gets
  // wrong from what diagnosis does.
  LegParams truth = ResolveSubject(gait);
  truth.effects.insert(truth.effects.end(), gait.plant_effects.begin(), gait.plant_effects.end());
  WriteFileAtomic(base + "/truth.yaml", ModelToYaml(truth, "exotwin table5: " + subject +
                                                               ", the twin its worn records came from (seed " +
                                                               std::to_string(opt.seed) + ")"));
  const std::string gdir = base + "/gait";
  RunInto(gait, gdir, subject + " gait", &run.failed_checks);
  const MeasuredData g = ReadRun(gdir).front();
  ComputeTable5Rmse(g, t_from, t_to, preset.weight, preset.L2, &e);
  if (opt.diagnose) {
    // The identified model as subject.yaml has it: the rigid set, riener1999, and what steps 3-4
    // identified beyond the paper (--subject-passive: the subject's passive factor and damping).
    LegParams model = Table5ParameterSets(e.identified, preset.weight, preset.L2)[0];
    model.effects = e.identified.effects;
    run.diagnoses.push_back(DiagnoseRecords("gait", model, {&g}, opt.gait_fit));
    std::vector<const MeasuredData*> steps34;
    for (const MeasuredData& f : human_files) steps34.push_back(&f);
    run.diagnoses.push_back(DiagnoseRecords("steps 3-4", model, steps34, DiagnoseFit::kTorque));
  }
  if (!opt.keep_logs) fs::remove_all(gdir);
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  char line[120];
  std::snprintf(line, sizeof(line), "%s: done in %.1f s wall", subject.c_str(), run.wall_s);
  Log(opt, line);
  return run;
}

namespace {

// The set value of (name, joint) summed over `fx`, and whether any is set.
bool SetValue(const std::vector<Effect>& fx, const std::string& name, const std::string& joint, double* v) {
  bool any = false;
  *v = 0;
  for (const Effect& e : fx)
    if (e.name == name && e.joint == joint) {
      *v += e.value;
      any = true;
    }
  return any;
}

}  // namespace

std::string Table5DiagnosisMarkdown(const Table5Options& opt, const std::vector<Table5SubjectRun>& runs) {
  const std::vector<Effect> device = Table5PlantEffects(opt, false), worn = Table5PlantEffects(opt, true);
  std::string s = "\n## The plant's effects\n\n";
  if (worn.empty()) {
    s += "None: the rigid twin.\n";
  } else {
    s += "Device (every scenario): " + (opt.plant_file.empty() ? std::string("none") : opt.plant_file) +
         "; worn leg (steps 3-4 and gait): " +
         (opt.plant_worn_file.empty() ? std::string("none") : opt.plant_worn_file) + ".\n\n";
    s += "| effect | joint | value | unit | scenarios |\n| --- | --- | --- | --- | --- |\n";
    for (size_t i = 0; i < worn.size(); ++i)
      s += "| " + worn[i].name + " | " + worn[i].joint + " | " + FormatNumber("%g", worn[i].value) +
           (worn[i].fields.count("cv") ? ", cv " + FormatNumber("%g", worn[i].fields.at("cv")) + ": drawn per subject" : "") +
           " | " + worn[i].unit + " | " + (i < device.size() ? "steps 1-4, gait" : "steps 3-4, gait") + " |\n";
    // The per-subject draws (SubjectEffects), as each subject's plant carried them.
    for (size_t i = 0; i < worn.size(); ++i) {
      if (!worn[i].fields.count("cv")) continue;
      s += "\nDrawn " + worn[i].name + " (" + worn[i].joint + ", seed " + std::to_string(opt.seed) + "):";
      for (const Table5SubjectRun& r : runs)
        if (i < r.plant_worn.size()) s += " " + r.entry.subject + " " + FormatNumber("%+.3f", r.plant_worn[i].value);
      s += ".\n";
    }
  }
  bool any = false;
  for (const Table5SubjectRun& r : runs) any = any || !r.diagnoses.empty();
  if (!any) return s;
  s += "\n## diagnose on the twin's own records, with the identified model\n\n";
  s += "Per record set: the effects named (value [95 % interval], deviation from the plant's value of that "
       "effect at that joint), and the held-out RMS error (diagnose's last 30 %) of the identified twin -> the "
       "extended twin: of the filtered torque (N m) where the records are diagnosed by the torque fit, of the "
       "simulated angle (rad) where by the motion fit (--fit motion: the gait).\n\n";
  s += "| subject | records | named | hip held-out | knee held-out | paper's identified hip / knee (Table 5) |\n"
       "| --- | --- | --- | --- | --- | --- |\n";
  struct Acc { double sum = 0, abs_dev = 0; int n = 0; };  // abs_dev: sum of |named - that subject's set value|
  std::vector<std::pair<std::string, Acc>> named_gait;  // "name(joint)" -> gait values
  for (const Table5SubjectRun& r : runs)
    for (const Table5Diagnosis& d : r.diagnoses) {
      std::string paper = "-";
      for (const Table5Row& p : PaperTable5())
        if (r.entry.subject == p.subject)
          paper = FormatNumber("%.2f", p.hip_identified) + " / " + FormatNumber("%.2f", p.knee_identified);
      s += "| " + r.entry.subject + " | " + d.records + (d.fit == DiagnoseFit::kMotion ? " (motion fit)" : "") + " | ";
      if (!d.done) {
        s += "not run: " + d.error + " | - | - | " + paper + " |\n";
        continue;
      }
      if (d.named.empty()) s += "nothing";
      for (size_t i = 0; i < d.named.size(); ++i) {
        const Effect& e = d.named[i];
        s += (i ? "; " : "") + e.name + " (" + e.joint + ") " + FormatNumber("%.3g", e.value) + " [" +
             FormatNumber("%.3g", d.ci[i].first) + ", " + FormatNumber("%.3g", d.ci[i].second) + "]";
        // The model's own value of that effect (--subject-passive) adds to the named one.
        double set = 0, own = 0;
        const bool has_own = SetValue(r.entry.identified.effects, e.name, e.joint, &own);
        const double total = e.value + own;
        if (has_own) s += " (with the model's own " + FormatNumber("%.3g", own) + ": " + FormatNumber("%.3g", total) + ")";
        if (SetValue(r.plant_worn, e.name, e.joint, &set) && set != 0)
          s += " (" + FormatNumber("%+.0f", 100.0 * (total - set) / set) + " % of the plant's " + FormatNumber("%g", set) + ")";
        else
          s += " (not in the plant)";
        if (d.records == "gait") {
          const std::string key = e.name + " (" + e.joint + ")";
          auto it = std::find_if(named_gait.begin(), named_gait.end(), [&](const auto& p) { return p.first == key; });
          if (it == named_gait.end()) it = named_gait.insert(named_gait.end(), {key, Acc{}});
          it->second.sum += total;
          it->second.abs_dev += std::abs(total - set);
          ++it->second.n;
        }
      }
      s += " | " + FormatNumber("%.3f", d.rmse_before[0]) + " -> " + FormatNumber("%.3f", d.rmse_after[0]) + " | " +
           FormatNumber("%.3f", d.rmse_before[1]) + " -> " + FormatNumber("%.3f", d.rmse_after[1]) + " | " + paper +
           " |\n";
    }
  // The plant's link and sensor effects against what the gait records revealed, over the subjects.
  s += "\nThe plant's effects against diagnose on the gait records (" + std::to_string(runs.size()) +
       " subject(s)):\n\n| effect | set | named in | mean named | deviation |\n| --- | --- | --- | --- | --- |\n";
  std::vector<std::string> seen;
  for (const Effect& e : worn) {
    const std::string key = e.name + " (" + e.joint + ")";
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
    seen.push_back(key);
    double set = 0;
    SetValue(worn, e.name, e.joint, &set);
    // A value drawn per subject: its set value differs by subject; the deviation is then the mean
    // |named - that subject's value| over the subjects that named it.
    const bool drawn = e.fields.count("cv") > 0;
    const std::string set_text = drawn ? "drawn per subject" : FormatNumber("%g", set);
    auto it = std::find_if(named_gait.begin(), named_gait.end(), [&](const auto& p) { return p.first == key; });
    if (it == named_gait.end()) {
      s += "| " + key + " | " + set_text + " | 0 | - | not named |\n";
      continue;
    }
    const double mean = it->second.sum / it->second.n;
    std::string dev = "-";
    if (drawn) dev = "mean \\|named - set\\| " + FormatNumber("%.3g", it->second.abs_dev / it->second.n);
    else if (set != 0) dev = FormatNumber("%+.1f %%", 100.0 * (mean - set) / set);
    s += "| " + key + " | " + set_text + " | " + std::to_string(it->second.n) + " | " + FormatNumber("%.3g", mean) +
         " | " + dev + " |\n";
  }
  for (const auto& [key, acc] : named_gait)
    if (std::find(seen.begin(), seen.end(), key) == seen.end())
      s += "| " + key + " | not in the plant | " + std::to_string(acc.n) + " | " + FormatNumber("%.3g", acc.sum / acc.n) +
           " | - |\n";
  // Candidates the records cannot identify (said by diagnose, not fitted), once per record set.
  for (const char* what : {"gait", "steps 3-4"}) {
    std::vector<std::string> ni;
    for (const Table5SubjectRun& r : runs)
      for (const Table5Diagnosis& d : r.diagnoses)
        if (d.records == what)
          for (const std::string& c : d.not_identifiable)
            if (std::find(ni.begin(), ni.end(), c) == ni.end()) ni.push_back(c);
    s += std::string("\nNot identifiable from the ") + what + " records (diagnose, any subject): ";
    if (ni.empty()) s += "none.\n";
    for (size_t i = 0; i < ni.size(); ++i) s += (i ? "; " : "") + ni[i] + (i + 1 == ni.size() ? ".\n" : "");
  }
  return s;
}

std::string Table5DiagnosisJson(const std::vector<Table5SubjectRun>& runs) {
  using nlohmann::json;
  json subjects = json::array();
  for (const Table5SubjectRun& r : runs) {
    json ds = json::array();
    for (const Table5Diagnosis& d : r.diagnoses) {
      json fx = json::array();
      for (size_t i = 0; i < d.named.size(); ++i)
        fx.push_back({{"name", d.named[i].name}, {"joint", d.named[i].joint}, {"value", d.named[i].value},
                      {"unit", d.named[i].unit}, {"ci95", {d.ci[i].first, d.ci[i].second}}});
      json held = json::object();
      for (int j = 0; j < 2; ++j)
        held[j ? "knee" : "hip"] = {{"rmse_before", d.rmse_before[j]}, {"rmse_after", d.rmse_after[j]}};
      ds.push_back({{"records", d.records}, {"fit", DiagnoseFitName(d.fit)},
                    {"heldout_unit", d.fit == DiagnoseFit::kMotion ? "rad" : "N m"}, {"done", d.done}, {"error", d.error},
                    {"cutoff_hz", d.cutoff_hz},
                    {"effects", fx}, {"not_identifiable", d.not_identifiable}, {"heldout", held}});
    }
    subjects.push_back({{"subject", r.entry.subject}, {"diagnoses", ds}});
  }
  return json{{"subjects", subjects}}.dump(2) + "\n";
}

}  // namespace exotwin
