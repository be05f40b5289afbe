// MODEL.yaml (DESIGN.md "Model parameter file"): reading with strict validation, and writing.
#pragma once
#include <string>
#include <vector>

#include "core/yaml_fields.h"
#include "formats/measured_data.h"
#include "model/lumped_params.h"

namespace exotwin {

// Reads a model file. Throws InputError naming the file, the key (e.g. "human.J2" or
// "effects[1].joint") and what was expected, for: unreadable or malformed YAML, unknown or missing
// keys, wrong types, non-finite numbers, negative masses, values out of physical range
// (|J| <= 50 kg m^2, |X|, |Y| <= 50 kg m, L1 in (0.1, 1.0) m), unknown passive model or effect.
// Physical consistency (a realization exists) is checked when the twin is built (Plant::SetParams).
LegParams ReadModelFile(const std::string& path);

// Parses model YAML text; `source` names it in messages.
LegParams ParseModelYaml(const std::string& text, const std::string& source);

// Reads a model file: a two-joint MODEL.yaml or a one-joint one (top-level `joint:`, DESIGN.md
// "One-joint devices"), returned embedded in the two-link model (model/one_joint.h, params.one_joint
// set). ParseModelYaml dispatches the same way.

// A record for the model file at `params_path`: a one-joint record (data.one_joint) for a one-joint
// model, a record of both joints for a two-joint one. Throws InputError naming both files and what
// was expected otherwise.
void CheckRecordFitsModel(const LegParams& params, const std::string& params_path, const MeasuredData& data);

// A list of effects as a model file's `effects:` holds them (DESIGN.md "Effects"), read from the
// sequence n under `key` of the file c.source (a scenario's plant.effects): messages name
// "<key>[i].<field>" as ReadModelFile's name "effects[i].<field>".
std::vector<Effect> ReadEffectList(const YamlContext& c, const YAML::Node& n, const std::string& key);

// Serializes params as MODEL.yaml text. `extra_yaml` (already formatted top-level YAML, e.g. an
// `identification:` block) is appended verbatim; a one-joint model is written as a one-joint file; `header` lines become '# ' comments at the top.
std::string ModelToYaml(const LegParams& params, const std::string& header = "",
                        const std::string& extra_yaml = "");

}  // namespace exotwin
