// The closed loop allocates nothing per step in steady state (issue 16): the rig (runner/cosim_rig.h)
// with the EXOwheel and HAL-3 devices, the virtual CAN bus, the nodes, the controller and the log
// writers (measured.csv, truth.csv, candump). This binary replaces the global operator new with a
// counting one; a run's RunOptions::on_sample (called on every log instant) reads the count, and the
// count must not grow between two instants after the start-up (buffers and queues at their size).
// Not a timed assertion: the count is exact on every machine.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include "runner/runner.h"
#include "tests/temp_dir.h"

namespace {
std::atomic<long> g_allocations{0};

void* CountedAlloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* CountedAlignedAlloc(std::size_t n, std::align_val_t a) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t al = static_cast<std::size_t>(a);
  if (void* p = std::aligned_alloc(al, (n + al - 1) / al * al)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return CountedAlloc(n); }
void* operator new[](std::size_t n) { return CountedAlloc(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return CountedAlloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return CountedAlloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t a) { return CountedAlignedAlloc(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return CountedAlignedAlloc(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace exotwin {
namespace {

// Allocations between the log instants t0 and t1 (s) of a run of `file` (duration set to t1 + 0.5 s),
// with both CSV logs and a candump log.
long AllocationsBetween(const std::string& file, double t0, double t1) {
  Scenario s = ReadScenario(std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/" + file);
  s.protocol.duration = t1 + 0.5;
  s.protocol.trials = 1;
  s.log_measured_csv = true;
  const testing::ScopedTempDir tmp("cosim_alloc");
  RunOptions o;
  o.out_dir = tmp.path();
  o.can_log = tmp.path() + "/bus.log";
  long at0 = -1, at1 = -1;
  o.on_sample = [&](double t, const double*, const double*) {
    if (at0 < 0 && t >= t0) at0 = g_allocations.load();
    if (at1 < 0 && t >= t1) at1 = g_allocations.load();
  };
  RunScenario(s, o);
  EXPECT_GE(at0, 0);
  EXPECT_GE(at1, 0);
  return at1 - at0;
}

TEST(CosimRigAllocations, ExowheelGaitWithEmgAndLogsAllocatesNothingPerStep) {
  EXPECT_EQ(AllocationsBetween("gait_2kmh.yaml", 1.0, 4.0), 0);
}

TEST(CosimRigAllocations, Hal3AssistAllocatesNothingPerStep) {
  EXPECT_EQ(AllocationsBetween("hal3_exp2_assist.yaml", 1.0, 4.0), 0);
}

TEST(CosimRigAllocations, TheCounterSeesAllocations) {  // the replaced operator new is the one in use
  const long before = g_allocations.load();
  auto* p = new std::string(100, 'x');
  delete p;
  EXPECT_GT(g_allocations.load(), before);
}

}  // namespace
}  // namespace exotwin
