// Measurements of `exotwin bench` (app/cmd_bench.cc), each returning a JSON object with its timings,
// its own in-run baseline and the ratio against it. Times are wall-clock seconds, best of `repeat`.
#pragma once
#include <nlohmann/json.hpp>
#include <sched.h>

#include <cstdio>
#include <string>
#include <vector>

#include "diagnosis/generate.h"

namespace exotwin {

// One row of the table `exotwin bench` prints (issue 16's table): a piece of work and its figure
// against a baseline measured in the same run, ratio first. Every probe returns its rows in its
// JSON object under "rows" (BenchRowsJson); the command gathers them into one table.
struct BenchRow {
  std::string work;      // what was timed, e.g. "exotwin run gait_2kmh (60 s, both CSV logs)"
  double ratio = 0;      // the figure the goal is about (a time ratio, a speed-up, a share)
  std::string unit;      // how ratio reads: "x" (times the baseline) or "%"
  std::string baseline;  // the in-run baseline the ratio is against, e.g. "bare mj_step loop"
  std::string goal;      // e.g. "<= 2.5x" ("" = none)
  std::string detail;    // the raw figures, e.g. "0.66 s vs 0.09 s"
};
nlohmann::ordered_json BenchRowsJson(const std::vector<BenchRow>& rows);
std::vector<BenchRow> BenchRowsFromJson(const nlohmann::ordered_json& probe);

// The machine the figures were measured on: cores (nproc) and load averages (1, 5, 15 min).
struct BenchMachine {
  unsigned cores = 0;
  double load[3] = {0, 0, 0};
};
BenchMachine MeasureMachine();
nlohmann::ordered_json MachineJson(const BenchMachine& m);

// The speed of one CPU: the seconds of a bare mj_step loop pinned to it. A machine's CPUs can differ
// (a virtual machine's vCPUs: on one 2-core machine the same loop took 1.53x longer on CPU 1 than on
// CPU 0, alone or not), so a ratio holds only with both of its halves on one CPU: the single-threaded
// probes run pinned to the fastest CPU (ScopedCpuPin), and a 2-job sweep's speed-up is bounded by
// SpeedupBoundOfCpus, not by 2.
struct BenchCpu {
  int cpu = 0;        // CPU number (sched_getaffinity)
  double step_s = 0;  // best of repeat: 20000 bare mj_step (quick: 2000)
};

// The table: a header with the machine's load at the start and at the end (and its CPUs' speeds),
// then one line per row (ratio, goal, work, baseline, detail), as Markdown.
void PrintBenchTable(std::FILE* out, const std::vector<BenchRow>& rows, const BenchMachine& start,
                     const BenchMachine& end, const std::vector<BenchCpu>& cpus = {});

struct BenchConfig {
  int repeat = 3;             // repetitions per timing (the minimum is kept)
  bool quick = false;         // small problem sizes (tests)
  std::string scratch = "/tmp";  // folder for temporary outputs
  std::vector<BenchCpu> cpus;    // MeasureCpus; empty: unknown (no pinning)
};

// Every CPU this process may run on, each measured pinned to it (the affinity is restored).
std::vector<BenchCpu> MeasureCpus(const BenchConfig& c);
// The fastest CPU's number; -1 if `cpus` is empty.
int FastestCpu(const std::vector<BenchCpu>& cpus);
// The speed-up that running on all of `cpus` gives at most over running on the fastest alone: the
// sum over CPUs of t_fastest / t_cpu (2 for two equal CPUs; 1 if empty).
double SpeedupBoundOfCpus(const std::vector<BenchCpu>& cpus);
nlohmann::ordered_json CpusJson(const std::vector<BenchCpu>& cpus);

// The CPUs this process may run on (sched_getaffinity), in increasing order; empty if unknown.
std::vector<int> AllowedCpus();

// Pins the calling thread, and the processes it starts from then on, to one CPU until destroyed,
// then restores the previous affinity. cpu < 0, or a mask the system refuses: no change.
class ScopedCpuPin {
 public:
  explicit ScopedCpuPin(int cpu);
  ~ScopedCpuPin();
  ScopedCpuPin(const ScopedCpuPin&) = delete;
  ScopedCpuPin& operator=(const ScopedCpuPin&) = delete;
  bool pinned() const { return pinned_; }

 private:
  cpu_set_t saved_;  // the previous affinity
  bool pinned_ = false;
};

// Closed loop (gait, plant + CAN + sensors + controller, no logs) vs bare mj_step, same model and
// The generated record of the diagnosis and long-record probes: S1 at 1 kHz for `duration_s` with one
// hidden Coulomb friction, seed 2024.
GenerateOptions BenchFrictionRecord(double duration_s);

// number of steps (10 s = 10000 steps; quick: 2 s). Rows: with EMG, without EMG.
nlohmann::ordered_json BenchClosedLoop(const BenchConfig& c);

// Start-up: wall time of `exotwin --help` (this executable, /proc/self/exe) against /bin/true, each
// spawned and waited for (best of 10 x repeat; quick: 5); ratio first. Goal: --help < 0.03 s.
nlohmann::ordered_json BenchStartup(const BenchConfig& c);

// `exotwin run scenarios/gait_2kmh.yaml` (60 s, both CSV logs) as a separate process, start-up
// included, vs a bare mj_step loop of the same model and number of steps in this process; and the
// same run with `--mcap` (its ROS 2 bag too) vs without (goal <= 1.3x), the two alternated.
nlohmann::ordered_json BenchRunCommand(const BenchConfig& c);

// Render + H.264 encode at 1280x720 with overlays (3 s of video; quick: 1 s) vs no overlays and vs
// real time (30 fps), ratio (x real time) first; cpu_ms_per_frame (all threads: llvmpipe, encoder,
// caller) bounds the fps of idle cores, fps <= cores * 1000 / cpu_ms_per_frame, so the row reads on
// a shared machine too; {"status": "unavailable", ...} without the renderer (plugin missing).
nlohmann::ordered_json BenchRender(const BenchConfig& c);

// Identification (steps 3-4, S1, 80 s of 1 kHz data; quick: 40 s): data seconds per wall second.
nlohmann::ordered_json BenchIdentification(const BenchConfig& c);

// replay (diagnosis/replay.h) of 600 s at 1 kHz (quick: 20 s) on the DFKI rig's model carrying
// friction and armature, 0.5 s windows, vs a bare mj_step loop of the same model over the same time.
nlohmann::ordered_json BenchReplay(const BenchConfig& c);

// The Python module (python/exotwin/bench.py, run by the interpreter it is built for, $EXOTWIN_PYTHON
// else /usr/bin/python3): exotwin.run vs `exotwin run` (<= 1.05x), a Python PD controller on Twin.step
// vs the UDP example (<= 0.25x), the binding's cost per step (no-op controller vs exotwin.run); gait_2kmh
// (quick: 6 s of it). The in-process pairs run on the fastest CPU (both halves), the UDP pair unpinned.
// {"status": "unavailable"} when the module is not built.
nlohmann::ordered_json BenchPython(const BenchConfig& c);
// diagnose --fit motion (diagnosis/motion_fit.h, 2 threads) of a 60 s closed-loop gait record (S1, knee
// backlash 0.02 rad in the plant; quick: 15 s) against one replay of the record (0.5 s windows, one
// thread): the number of replays' worth of wall time (goal <= 150).
nlohmann::ordered_json BenchMotionFit(const BenchConfig& c);

// Diagnosis of 60 s of 1 kHz data with one hidden effect (quick: 20 s): data seconds per wall second.
nlohmann::ordered_json BenchDiagnosis(const BenchConfig& c);

// Sweep speed-up (rows: speed-up, the parent's share): the same runs (gait 20 s x 8 subjects; quick: 2 s x 2) with 1 and 2 worker
// processes; ratio = t(1) / t(2) (target >= 1.85 on 2 idle cores); cores_used = children's CPU
// time / wall time (about 2 with 2 jobs on an idle machine: below it, other load took the cores);
// serial_fraction = the parent's CPU share, amdahl_speedup_2_idle_cores the bound it implies.
nlohmann::ordered_json BenchSweep(const BenchConfig& c);

// The controller across the process boundary (DESIGN.md "The CAN transport between processes").
// Rows: lockstep serve + exotwin-controller on gait_2kmh (60 s; quick: 5 s) over unix: and over shm:,
// each unpinned and with both processes pinned to one CPU, against the same run in this process, all
// measured in this call (goal <= 3x; logs_identical: measured.csv and truth.csv the same bytes); regress
// --controller-process of the shipped suite (over shm:) against regress (not quick; <= 3x); real time (60 s;
// quick: 2 s) with no added load and with one core kept busy by a spinning process, SCHED_FIFO 50 asked (the row
// says whether granted): tick-start jitter p99 (goal <= 100 us), p50, max (<= 1 ms), late, missed.
nlohmann::ordered_json BenchLink(const BenchConfig& c);

}  // namespace exotwin

namespace exotwin {

// predict / diagnose of a generated 1 kHz record (600 s, ~75 MB of CSV; quick: 20 s) run as child
// processes, against reading the same file once with strtod per field: ratio (wall time) first,
// then the times, the child's peak memory (ru_maxrss) and that of `exotwin --help` (start-up alone).
// diagnose_long adds the same row on the record `run` writes for the shipped gait scenario at that
// length (15 columns: cmd_*, ref_*, state and EMG besides the required ones; `run_record` in its JSON).
nlohmann::ordered_json BenchPredictLong(const BenchConfig& c);
nlohmann::ordered_json BenchDiagnoseLong(const BenchConfig& c);
// `diagnose` with stage 5c (completeness, ceilings, the search for terms) against --no-completeness, 60 s.
nlohmann::ordered_json BenchTermSearch(const BenchConfig& c);

}  // namespace exotwin
