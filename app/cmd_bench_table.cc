// The table of `exotwin bench` (app/bench_probes.h): rows as JSON and back, the machine's load, the
// Markdown printer.
#include <unistd.h>

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

void PrintBenchTable(std::FILE* out, const std::vector<BenchRow>& rows, const BenchMachine& start,
                     const BenchMachine& end) {
  std::fprintf(out, "machine: %u cores (nproc); load average (1/5/15 min) %.2f/%.2f/%.2f at the start, %.2f/%.2f/%.2f at the end",
               start.cores, start.load[0], start.load[1], start.load[2], end.load[0], end.load[1], end.load[2]);
  std::fprintf(out, start.load[0] > 0.5 * start.cores ? " (busy: other load shares the cores, every figure is noisy)\n\n"
                                                       : "\n\n");
  std::fprintf(out, "| ratio | goal | work | against | figures |\n| --- | --- | --- | --- | --- |\n");
  for (const BenchRow& r : rows)
    std::fprintf(out, "| %.3g%s | %s | %s | %s | %s |\n", r.ratio, r.unit == "%" ? " %" : r.unit.c_str(),
                 r.goal.empty() ? "-" : r.goal.c_str(), r.work.c_str(), r.baseline.c_str(), r.detail.c_str());
}

}  // namespace exotwin
