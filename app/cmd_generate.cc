// `exotwin generate`: synthetic measured data with hidden effects drawn by a seed (diagnosis/generate.h).
#include <CLI/CLI.hpp>

#include <cstdio>

#include "formats/csv_table.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "core/error.h"
#include "app/commands.h"

namespace exotwin {
namespace {

CommandRunner RegisterGenerate(CLI::App& app) {
  struct Opts {
    std::string params, out, truth, joint;
    uint64_t seed = 1;
    int effects = 1;
    double duration = 60.0, rate = 1000.0;
    bool clean = false;
    std::vector<std::string> allowed, terms, stages;
    std::vector<double> values;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "generate", "Measured data from a truth twin carrying hidden effects drawn by a seed");
  sub->add_option("--params", o->params, "MODEL.yaml of the truth twin (before the hidden effects)")->required();
  sub->add_option("--seed", o->seed, "seed of every random draw (same seed = same file)")->required();
  sub->add_option("--out", o->out, "measured-data CSV to write")->required();
  sub->add_option("--effects", o->effects, "number of hidden effects, 0..3 (default 1)");
  sub->add_option("--effect", o->allowed, "restrict the draw to this effect name (repeatable)");
  sub->add_option("--joint", o->joint, "force the joint of the hidden effects (hip or knee)");
  sub->add_option("--duration", o->duration, "record length, s (default 60)");
  sub->add_option("--rate", o->rate, "sample rate, Hz (default 1000)");
  sub->add_option("--truth", o->truth, "write the truth (model + hidden effects) to this YAML");
  sub->add_flag("--clean", o->clean, "no hidden effect (same as --effects 0)");
  sub->add_option("--term", o->terms,
                  "hide a term beyond the table: value * EXPR at --joint (repeatable, one --value each; "
                  "alone, no drawn effect unless --effects is given)");
  sub->add_option("--value", o->values, "the value of each --term (N m), in their order");
  sub->add_option("--stage", o->stages, "link (default) or sensor, for each --term in their order");
  auto* effects_option = sub->get_option("--effects");
  return [sub, o, effects_option]() -> int {
    if (!*sub) return -1;
    const LegParams params = ReadModelFile(o->params);
    GenerateOptions g;
    g.seed = o->seed;
    g.effects = o->clean || (!o->terms.empty() && effects_option->count() == 0) ? 0 : o->effects;
    if (o->values.size() != o->terms.size())
      throw InputError("--term: " + std::to_string(o->terms.size()) + " terms and " + std::to_string(o->values.size()) +
                       " --value, expected one --value per --term");
    if (!o->stages.empty() && o->stages.size() != o->terms.size())
      throw InputError("--stage: " + std::to_string(o->stages.size()) + " for " + std::to_string(o->terms.size()) +
                       " terms, expected none or one per --term");
    if (!o->terms.empty() && o->joint.empty() && !params.one_joint)
      throw InputError("--term: expected --joint hip or knee (the terms' joint)");
    for (size_t k = 0; k < o->terms.size(); ++k) {
      Effect e;
      e.name = "term", e.unit = "N m", e.expr = o->terms[k], e.value = o->values[k];
      e.joint = o->joint.empty() ? "knee" : o->joint;
      e.stage = o->stages.empty() || o->stages[k] == "link" ? "" : o->stages[k];
      g.terms.push_back(e);
    }
    g.allowed = o->allowed;
    g.joint = o->joint;
    g.duration = o->duration;
    g.rate = o->rate;
    const GeneratedData data = GenerateMeasured(params, g);
    WriteGeneratedCsv(data, o->out, o->seed);
    if (!o->truth.empty())
      WriteFileAtomic(o->truth, ModelToYaml(data.truth,
                                            "exotwin generate --seed " + std::to_string(o->seed) +
                                                ": truth twin (hidden effects)\ntorque sensor noise " +
                                                std::to_string(data.torque_noise) + " N m"));
    return 0;
  };
}

const CommandRegistration kGenerate(RegisterGenerate);

}  // namespace
}  // namespace exotwin
