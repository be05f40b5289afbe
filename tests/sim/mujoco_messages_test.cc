// MuJoCo's warnings are kept on the thread that raised them (sim/mujoco_messages.h): never printed in
// the program's output nor logged into the working folder, and a simulation step's warning is the
// plant's SimulationError.
#include "sim/mujoco_messages.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <filesystem>
#include <string>
#include <thread>

#include <unistd.h>

#include "core/error.h"
#include "sim/plant.h"
#include "sim/subjects.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

// Runs in a fresh working folder (MuJoCo's default handler appends to ./MUJOCO_LOG.TXT) with standard
// output captured; after the body, nothing was printed and no log file was written.
class MujocoMessages : public ::testing::Test {
 protected:
  void SetUp() override {
    old_ = std::filesystem::current_path();
    std::filesystem::current_path(dir_.path());
    ::testing::internal::CaptureStdout();
  }
  void TearDown() override {
    const std::string out = ::testing::internal::GetCapturedStdout();
    EXPECT_EQ(out, "");
    EXPECT_FALSE(std::filesystem::exists(dir_.path() + "/MUJOCO_LOG.TXT"));
    std::filesystem::current_path(old_);
    mjcb_control = nullptr;
  }
  std::unique_ptr<Plant> MakePlant() {
    auto p = std::make_unique<Plant>(ShippedModelPath("leg_exowheel.xml"));  // installs the handler
    p->SetParams(SubjectLegParams(PresetSubject("S1")));
    p->Reset({0.3, -0.5}, {0, 0}, 0.0);
    return p;
  }
  testing::ScopedTempDir dir_{"mujoco_messages"};
  std::filesystem::path old_;
};

TEST_F(MujocoMessages, AWarningIsKeptOnTheThreadThatRaisedIt) {
  KeepMujocoWarnings();
  mju_warning("first");
  mju_warning("second");
  std::string other;
  std::thread([&] {
    mju_warning("on another thread");
    other = TakeMujocoWarning();
  }).join();
  EXPECT_EQ(other, "on another thread");
  EXPECT_EQ(TakeMujocoWarning(), "first");  // the first since the last take
  EXPECT_EQ(TakeMujocoWarning(), "");
}

// A warning MuJoCo does not count in mjData::warning (the constraint solver's line search, raised
// here from the control callback inside mj_step) stops the step like a counted one.
TEST_F(MujocoMessages, AWarningInsideAStepIsTheStepsSimulationError) {
  auto p = MakePlant();
  p->Step({1, 1});
  mjcb_control = [](const mjModel*, mjData*) { mju_warning("Linesearch objective is not convex"); };
  try {
    p->Step({1, 1});
    ADD_FAILURE() << "the step did not stop";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("MuJoCo warning 'Linesearch objective is not convex' in step"),
              std::string::npos)
        << e.what();
  }
}

// A warning another model raised on this thread before the step is not this plant's.
TEST_F(MujocoMessages, AnEarlierWarningOnTheThreadIsNotTheNextStepsError) {
  auto p = MakePlant();
  mju_warning("raised before the step, elsewhere");
  EXPECT_NO_THROW(p->Step({1, 1}));
}

// A diverging state: MuJoCo's counted warning (with its text) is the error, and its text is neither
// printed nor logged.
TEST_F(MujocoMessages, ADivergingPlantPrintsNothing) {
  auto p = MakePlant();
  bool stopped = false;
  for (int i = 0; i < 100 && !stopped; ++i) {
    try {
      p->Step({0, 0}, {1e300, -1e300});
    } catch (const SimulationError&) {
      stopped = true;
    }
  }
  EXPECT_TRUE(stopped);
}

}  // namespace
}  // namespace exotwin
