#include "batch/baseline.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

#include "formats/csv_table.h"
#include "core/output_path.h"
#include "core/error.h"
#include "core/file_text.h"

namespace exotwin {

Baseline ReadBaseline(const std::string& path) {
  const std::string text = ReadTextFile(path, "baseline", "a JSON text file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  }
  auto fail = [&](const std::string& what) { throw InputError(path + ": " + what); };
  if (!j.is_object()) fail("expected a JSON object");
  Baseline b;
  if (j.contains("scenario") && j["scenario"].is_string()) b.scenario = j["scenario"];
  if (j.contains("source") && j["source"].is_string()) b.source = j["source"];
  if (j.contains("seed") && j["seed"].is_number_unsigned()) b.seed = j["seed"];
  if (!j.contains("metrics") || !j["metrics"].is_object()) fail("metrics: expected an object of numbers");
  for (auto it = j["metrics"].begin(); it != j["metrics"].end(); ++it) {
    if (it.value().is_number()) b.metrics[it.key()] = it.value().get<double>();
    else if (it.value().is_null()) b.metrics[it.key()] = std::nan("");
    else fail("metrics." + it.key() + ": expected a number");
  }
  if (j.contains("tolerance")) {
    if (!j["tolerance"].is_object()) fail("tolerance: expected an object {metric: {abs, rel}}");
    for (auto it = j["tolerance"].begin(); it != j["tolerance"].end(); ++it) {
      const auto& t = it.value();
      if (!t.is_object()) fail("tolerance." + it.key() + ": expected {abs: N, rel: N}");
      Tolerance tol;
      for (auto kt = t.begin(); kt != t.end(); ++kt) {
        if (kt.key() != "abs" && kt.key() != "rel")
          fail("tolerance." + it.key() + "." + kt.key() + ": unknown key, expected abs or rel");
        if (!kt.value().is_number() || kt.value().get<double>() < 0)
          fail("tolerance." + it.key() + "." + kt.key() + ": expected a number >= 0");
        (kt.key() == "abs" ? tol.abs : tol.rel) = kt.value().get<double>();
      }
      b.tolerance[it.key()] = tol;
    }
  }
  return b;
}

void WriteBaseline(const Baseline& b, const std::string& path) {
  nlohmann::ordered_json j;
  j["scenario"] = b.scenario;
  j["source"] = b.source;
  j["seed"] = b.seed;
  nlohmann::ordered_json m = nlohmann::ordered_json::object();
  for (const auto& kv : b.metrics) m[kv.first] = kv.second;  // NaN is written as null
  j["metrics"] = m;
  if (!b.tolerance.empty()) {
    nlohmann::ordered_json t = nlohmann::ordered_json::object();
    for (const auto& kv : b.tolerance) t[kv.first] = {{"abs", kv.second.abs}, {"rel", kv.second.rel}};
    j["tolerance"] = t;
  }
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) CreateOutputFolder(parent);
  WriteFileAtomic(path, j.dump(2) + "\n");
}

}  // namespace exotwin
