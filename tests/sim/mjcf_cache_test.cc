// Kept MuJoCo models (sim/mjcf_cache.h): a copy of the kept model holds the same bytes as a fresh
// load; a file that does not load is not kept and still reports its error.
#include "sim/mjcf_cache.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "sim/plant.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

TEST(MjcfCache, KeptCopyEqualsAFreshLoad) {
  const std::string path = ShippedModelPath("leg_exowheel.xml");
  char err[1000] = "";
  mjModel* fresh = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  ASSERT_NE(fresh, nullptr) << err;
  ASSERT_TRUE(KeepMjcfModel(path));
  mjModel* copy = LoadMjcfModel(path, err, sizeof err);
  ASSERT_NE(copy, nullptr);
  EXPECT_STREQ(err, "");
  ASSERT_EQ(copy->nbuffer, fresh->nbuffer);
  EXPECT_EQ(std::memcmp(copy->buffer, fresh->buffer, static_cast<size_t>(fresh->nbuffer)), 0);
  EXPECT_EQ(std::memcmp(&copy->opt, &fresh->opt, sizeof(mjOption)), 0);
  mj_deleteModel(copy);
  mj_deleteModel(fresh);
}

TEST(MjcfCache, ABrokenFileIsNotKept) {
  const testing::ScopedTempDir tmp("mjcf_cache");
  const std::string path = tmp.path() + "/broken.xml";
  std::ofstream(path) << "<mujoco><worldbody><body></mujoco>";
  EXPECT_FALSE(KeepMjcfModel(path));
  char err[1000] = "";
  EXPECT_EQ(LoadMjcfModel(path, err, sizeof err), nullptr);
  EXPECT_STRNE(err, "");
}

}  // namespace
}  // namespace exotwin
