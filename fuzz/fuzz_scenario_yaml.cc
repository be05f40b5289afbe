// libFuzzer target: the scenario reader (ParseScenarioYaml, a `plant:` block included) and the end of a
// run it feeds (FinishRun: checks, result.json). Contract: fuzz/harness_scenario.h.
#include <cstdint>
#include <string>

#include "formats/csv_table.h"
#include "fuzz/harness_scenario.h"
#include "tests/temp_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The scenario's folder: its result.json, and the plant file `plant: {effects_from: plant.yaml}`
  // names in the corpus (fuzz/corpus/fuzz_scenario_yaml/valid_plant_from.yaml).
  static const exotwin::testing::ScopedTempDir tmp("fuzz_scenario");
  static const bool plant = (exotwin::WriteFileAtomic(tmp.File("plant.yaml"), exotwin::fuzz::kPlantFile), true);
  (void)plant;
  exotwin::fuzz::ScenarioText(std::string(reinterpret_cast<const char*>(data), size), tmp.path());
  return 0;
}
