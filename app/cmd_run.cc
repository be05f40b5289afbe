#include <CLI/CLI.hpp>

#include <cstdio>

#include "app/commands.h"
#include "core/stop_signal.h"
#include "runner/out_folder_lock.h"
#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin {
namespace {

// Prints the checks as a table; returns 0 when all passed, 1 otherwise, 128 + N when signal N
// (SIGINT, SIGTERM) interrupted the run (result.json then says where: DESIGN.md "Interrupted runs").
int Report(const RunResult& r, const std::string& out_dir) {
  const auto samples = r.metrics.find("samples");
  std::printf("scenario %s (seed %llu): %zu samples, results in %s/result.json\n", r.scenario.c_str(),
              static_cast<unsigned long long>(r.seed),
              samples == r.metrics.end() ? size_t{0} : static_cast<size_t>(samples->second), out_dir.c_str());
  for (const CheckResult& c : r.checks)
    std::printf("  %-4s %-32s %12.5g %s %-10.5g (%s)\n", c.passed ? "ok" : "FAIL", c.name.c_str(), c.value,
                c.op.c_str(), c.limit, c.metric.c_str());
  if (r.interrupted) {
    std::fprintf(stderr, "exotwin: interrupted by %s at t = %.3f s (trial %d): checks not passed\n",
                 StopSignalName(r.interrupted->signal), r.interrupted->t, r.interrupted->trial);
    return 128 + r.interrupted->signal;
  }
  return r.all_passed() ? 0 : 1;
}

CommandRunner RegisterRun(CLI::App& app) {
  struct Opts {
    std::string scenario, out = "out", can_log, video;
    uint64_t seed = 0;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("run", "Run a scenario: plant + virtual hardware + the real controller");
  sub->add_option("scenario", o->scenario, "scenario YAML")->required();
  sub->add_option("--out", o->out, "output folder (result.json, measured.csv, truth.csv)");
  auto* seed = sub->add_option("--seed", o->seed, "seed (overrides the scenario's)");
  sub->add_option("--can-log", o->can_log, "candump log of every CAN frame");
  sub->add_option("--video", o->video, "render an MP4 video of the run");
  return [sub, o, seed]() -> int {
    if (!*sub) return -1;
    InstallStopSignalHandlers();
    const Scenario s = ReadScenario(o->scenario);
    const OutFolderLock lock(o->out);
    RunOptions opt;
    opt.out_dir = o->out;
    if (*seed) opt.seed = o->seed;
    opt.can_log = o->can_log;
    opt.progress = true;
    opt.video_path = o->video;
    return Report(RunScenario(s, opt), o->out);
  };
}

// `exotwin render SCENARIO.yaml -o FILE.mp4`: runs the scenario (logs under --out) and renders its
// first trial off-screen: side view, human and exoskeleton in distinct colours, overlays.
CommandRunner RegisterRender(CLI::App& app) {
  struct Opts {
    std::string scenario, video, out = "out/render";
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("render", "Run a scenario and render it to an MP4 (H.264, 30 fps, 1280x720)");
  sub->add_option("scenario", o->scenario, "scenario YAML")->required();
  sub->add_option("-o,--output", o->video, "output MP4")->required();
  sub->add_option("--out", o->out, "folder for the run's logs and result.json");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    InstallStopSignalHandlers();
    const Scenario s = ReadScenario(o->scenario);
    const OutFolderLock lock(o->out);
    RunOptions opt;
    opt.out_dir = o->out;
    opt.video_path = o->video;
    opt.progress = true;
    const int rc = Report(RunScenario(s, opt), o->out);
    std::printf("wrote %s\n", o->video.c_str());
    return rc > 1 ? rc : 0;  // a failed check does not fail the rendering; an interruption does
  };
}

const CommandRegistration kRun(RegisterRun);
const CommandRegistration kRender(RegisterRender);

}  // namespace
}  // namespace exotwin
