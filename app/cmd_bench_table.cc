// The table of `exotwin bench` (app/bench_probes.h): rows as JSON and back, the machine's load, the
// Markdown printer.
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "app/bench_probes.h"

namespace exotwin {

nlohmann::ordered_json BenchRowsJson(const std::vector<BenchRow>& rows) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (const BenchRow& r : rows)
    a.push_back({{"work", r.work},
                 {"ratio", r.ratio},
                 {"unit", r.unit},
                 {"baseline", r.baseline},
                 {"goal", r.goal},
                 {"detail", r.detail}});
  return a;
}

std::vector<BenchRow> BenchRowsFromJson(const nlohmann::ordered_json& probe) {
  std::vector<BenchRow> rows;
  if (!probe.is_object() || !probe.contains("rows")) return rows;
  for (const auto& j : probe["rows"]) {
    BenchRow r;
    r.work = j.value("work", "");
    r.ratio = j.contains("ratio") && j["ratio"].is_number() ? j["ratio"].get<double>() : std::nan("");
    r.unit = j.value("unit", "");
    r.baseline = j.value("baseline", "");
    r.goal = j.value("goal", "");
    r.detail = j.value("detail", "");
    rows.push_back(r);
  }
  return rows;
}

BenchMachine MeasureMachine() {
  BenchMachine m;
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  m.cores = n > 0 ? static_cast<unsigned>(n) : 0;
  if (getloadavg(m.load, 3) < 3) m.load[0] = m.load[1] = m.load[2] = std::nan("");
  return m;
}

nlohmann::ordered_json MachineJson(const BenchMachine& m) {
  return {{"cores", m.cores}, {"load_avg_1min", m.load[0]}, {"load_avg_5min", m.load[1]}, {"load_avg_15min", m.load[2]}};
}

namespace {

// The fastest of non-empty `cpus`.
const BenchCpu& Fastest(const std::vector<BenchCpu>& cpus) {
  return *std::min_element(cpus.begin(), cpus.end(),
                           [](const BenchCpu& a, const BenchCpu& b) { return a.step_s < b.step_s; });
}

}  // namespace

int FastestCpu(const std::vector<BenchCpu>& cpus) { return cpus.empty() ? -1 : Fastest(cpus).cpu; }

double SpeedupBoundOfCpus(const std::vector<BenchCpu>& cpus) {
  if (cpus.empty()) return 1.0;
  double sum = 0;
  for (const BenchCpu& c : cpus) sum += Fastest(cpus).step_s / c.step_s;
  return sum;
}

nlohmann::ordered_json CpusJson(const std::vector<BenchCpu>& cpus) {
  nlohmann::ordered_json j = nlohmann::ordered_json::array();
  const int fastest = FastestCpu(cpus);
  for (const BenchCpu& c : cpus) j.push_back({{"cpu", c.cpu}, {"bare_mj_step_s", c.step_s}, {"fastest", c.cpu == fastest}});
  return j;
}

std::vector<int> AllowedCpus() {
  std::vector<int> cpus;
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &allowed)) cpus.push_back(cpu);
  return cpus;
}

ScopedCpuPin::ScopedCpuPin(int cpu) : saved_() {
  if (cpu < 0 || cpu >= CPU_SETSIZE) return;
  if (sched_getaffinity(0, sizeof saved_, &saved_) != 0) return;
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(cpu, &one);
  pinned_ = sched_setaffinity(0, sizeof one, &one) == 0;
}

ScopedCpuPin::~ScopedCpuPin() {
  if (pinned_) sched_setaffinity(0, sizeof saved_, &saved_);
}

void PrintBenchTable(std::FILE* out, const std::vector<BenchRow>& rows, const BenchMachine& start,
                     const BenchMachine& end, const std::vector<BenchCpu>& cpus) {
  std::fprintf(out, "machine: %u cores (nproc); load average (1/5/15 min) %.2f/%.2f/%.2f at the start, %.2f/%.2f/%.2f at the end",
               start.cores, start.load[0], start.load[1], start.load[2], end.load[0], end.load[1], end.load[2]);
  std::fprintf(out, start.load[0] > 0.5 * start.cores ? " (busy: other load shares the cores, every figure is noisy)\n\n"
                                                       : "\n\n");
  if (!cpus.empty()) {
    std::fprintf(out, "CPUs (a bare mj_step loop pinned to each, time against the fastest):");
    for (const BenchCpu& c : cpus) std::fprintf(out, " cpu%d %.2fx", c.cpu, c.step_s / Fastest(cpus).step_s);
    std::fprintf(out, "; single-threaded probes run on cpu%d; all CPUs together allow a %.2fx speed-up\n\n",
                 FastestCpu(cpus), SpeedupBoundOfCpus(cpus));
  }
  std::fprintf(out, "| ratio | goal | work | against | figures |\n| --- | --- | --- | --- | --- |\n");
  for (const BenchRow& r : rows)
    std::fprintf(out, "| %.3g%s | %s | %s | %s | %s |\n", r.ratio, r.unit == "%" ? " %" : r.unit.c_str(),
                 r.goal.empty() ? "-" : r.goal.c_str(), r.work.c_str(), r.baseline.c_str(), r.detail.c_str());
}

}  // namespace exotwin
