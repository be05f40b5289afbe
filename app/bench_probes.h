// Measurements of `exotwin bench` (app/cmd_bench.cc), each returning a JSON object with its timings,
// its own in-run baseline and the ratio against it. Times are wall-clock seconds, best of `repeat`.
#pragma once
#include <nlohmann/json.hpp>

#include <string>

namespace exotwin {

struct BenchConfig {
  int repeat = 3;             // repetitions per timing (the minimum is kept)
  bool quick = false;         // small problem sizes (tests)
  std::string scratch = "/tmp";  // folder for temporary outputs
};

// Closed loop (gait, plant + CAN + sensors + controller, no logs) vs bare mj_step, same model and
// number of steps (10 s = 10000 steps; quick: 2 s).
nlohmann::ordered_json BenchClosedLoop(const BenchConfig& c);

// Render + H.264 encode at 1280x720 with overlays (3 s of video; quick: 1 s) vs no overlays and vs
// real time (30 fps); {"status": "unavailable", ...} without the renderer.
nlohmann::ordered_json BenchRender(const BenchConfig& c);

// Identification (steps 3-4, S1, 80 s of 1 kHz data; quick: 40 s): data seconds per wall second.
nlohmann::ordered_json BenchIdentification(const BenchConfig& c);

// Diagnosis of 60 s of 1 kHz data with one hidden effect (quick: 20 s): data seconds per wall second.
nlohmann::ordered_json BenchDiagnosis(const BenchConfig& c);

// Sweep speed-up: the same runs (gait 20 s x 8 subjects; quick: 2 s x 2) with 1 and 2 worker
// processes; ratio = t(1) / t(2) (target >= 1.8 on 2 idle cores); cores_used = children's CPU
// time / wall time (about 2 with 2 jobs on an idle machine: below it, other load took the cores);
// serial_fraction = the parent's CPU share, amdahl_speedup_2_idle_cores the bound it implies.
nlohmann::ordered_json BenchSweep(const BenchConfig& c);

}  // namespace exotwin

namespace exotwin {

// predict / diagnose of a generated 1 kHz record (600 s, ~75 MB of CSV; quick: 20 s) run as child
// processes, against reading the same file once with strtod per field: ratio (wall time) first,
// then the times, the child's peak memory (ru_maxrss) and that of `exotwin --help` (start-up alone).
nlohmann::ordered_json BenchPredictLong(const BenchConfig& c);
nlohmann::ordered_json BenchDiagnoseLong(const BenchConfig& c);

}  // namespace exotwin
