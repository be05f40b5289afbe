// Kept MuJoCo models (sim/mjcf_cache.h): a copy of the kept model holds the same bytes as a fresh
// load; a file that does not load is not kept and still reports its error.
#include "sim/mjcf_cache.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "sim/internal_joints.h"
#include "sim/mjcf_text.h"
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

TEST(MjcfCache, AVariantOfAKeptFileIsCompiledOnceAndCopiedAsCompiled) {
  const std::string path = ShippedModelPath("exowheel_exo_only.xml");
  ASSERT_TRUE(KeepMjcfModel(path));
  InternalJoints s;
  s.kind[1] = InternalHinge::kRotor;
  s.backlash[1] = true;
  int builds = 0;
  auto build = [&] {
    ++builds;
    return LoadMjcfText(path, AddInternalJoints(ReadMjcfText(path), path, s), "test");
  };
  mjModel* fresh = build();
  mjModel* first = LoadMjcfVariant(path, "knee dead band", build);
  mjModel* second = LoadMjcfVariant(path, "knee dead band", build);
  EXPECT_EQ(builds, 2);  // the fresh one and the first: the second is a copy
  for (const mjModel* m : {first, second}) {
    ASSERT_EQ(m->nbuffer, fresh->nbuffer);
    EXPECT_EQ(std::memcmp(m->buffer, fresh->buffer, static_cast<size_t>(fresh->nbuffer)), 0);
    EXPECT_EQ(std::memcmp(&m->opt, &fresh->opt, sizeof(mjOption)), 0);
  }
  EXPECT_EQ(second->nv, 3);  // the internal hinge
  for (mjModel* m : {fresh, first, second}) mj_deleteModel(m);
}

TEST(MjcfCache, AVariantOfAFileNotKeptIsBuiltEachTime) {
  const testing::ScopedTempDir tmp("mjcf_cache");
  const std::string path = tmp.path() + "/pendulum.xml";
  std::ofstream(path) << "<mujoco><worldbody><body><joint type='hinge'/><geom size='0.1'/></body></worldbody></mujoco>";
  int builds = 0;
  auto build = [&] {
    ++builds;
    char err[1000] = "";
    return mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  };
  for (int i = 0; i < 2; ++i) mj_deleteModel(LoadMjcfVariant(path, "as is", build));
  EXPECT_EQ(builds, 2);
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
