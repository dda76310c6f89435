// clothsim_scene on a tiny b2o::Scene written by hand: cloth -> masses/springs/pins,
// other objects -> colliders, params -> Options, bad data -> an error naming the scene.
#include <clothsim/collision.hpp>
#include <clothsim/scene.hpp>

#include <blender2ogl/scene_types.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>

namespace clothsim {
namespace {

// Object 0: a floor quad (vertices 0-3); object 1: a cloth triangle pair (vertices 4-7).
const float kPositions[] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1,  // floor
                            0, 1, 0, 0.5f, 1, 0, 0.5f, 1, 0.5f, 0, 1, 0.5f};
const float kNormals[24] = {};
const float kTexcoords[16] = {};
std::uint32_t kIndices[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7};
const float kRest[] = {0, 1, 0, 0.5f, 1, 0, 0.5f, 1, 0.5f, 0, 1, 0.5f};
const b2o::Spring kSprings[] = {{0, 1, 0.5f, b2o::SpringKind::Structural}, {1, 2, 0.5f, b2o::SpringKind::Structural},
                                {2, 3, 0.5f, b2o::SpringKind::Structural}, {3, 0, 0.5f, b2o::SpringKind::Structural},
                                {0, 2, 0.7f, b2o::SpringKind::Structural}, {1, 3, 0.7f, b2o::SpringKind::Bend}};
const std::uint32_t kClothTris[] = {0, 1, 2, 0, 2, 3};
const std::uint32_t kPins[] = {3};
b2o::Object kObjects[] = {{"Floor", "Floor", 0, 4, 0, 6, 0, 0, b2o::kNone}, {"Cloth", "Cloth", 4, 4, 6, 6, 0, 0, 0}};
const b2o::Cloth kCloths[] = {{1, 4, kRest, nullptr, nullptr, nullptr, 6, kSprings, 5, 2, kClothTris, 1, kPins}};
const b2o::Param kParams[] = {{"k_rep", "321"}, {"dt", "0.004"}, {"camera_distance", "5"}};

b2o::Scene tiny() {
  b2o::Scene s{};
  s.format_version = b2o::kFormatVersion;
  s.name = "tiny";
  s.source = "tiny.obj";
  s.vertex_count = 8;
  s.positions = kPositions;
  s.normals = kNormals;
  s.texcoords = kTexcoords;
  s.index_count = 12;
  s.indices = kIndices;
  s.object_count = 2;
  s.objects = kObjects;
  s.cloth_count = 1;
  s.cloths = kCloths;
  s.param_count = 3;
  s.params = kParams;
  return s;
}

TEST(SceneAdapter, ParamsOverrideDefaultsAndUnknownKeysAreReported) {
  const BakedParams p = read_scene_params(tiny());
  EXPECT_EQ(p.options.k_rep, 321.0);
  EXPECT_EQ(p.options.dt, 0.004);
  EXPECT_EQ(p.options.mass, Options{}.mass);
  ASSERT_EQ(p.unknown.size(), 1u);
  EXPECT_EQ(p.unknown[0], "camera_distance");
  EXPECT_TRUE(p.refused.empty());
}

// Every option of the table is a PARAMS key: a scene baking it changes that option and no other.
TEST(SceneAdapter, EveryTableOptionCanBeBaked) {
  for (const OptionInfo& option : option_table()) {
    if (option.is_choice) continue;  // (the choices: ParamsNameAChoice)
    const std::string key(option.name);
    const b2o::Param p[] = {{key.c_str(), "12345"}};
    b2o::Scene s = tiny();
    s.param_count = 1;
    s.params = p;
    const BakedParams baked = read_scene_params(s);
    EXPECT_TRUE(baked.unknown.empty() && baked.refused.empty()) << key;
    for (const OptionInfo& other : option_table()) {
      if (other.is_choice) continue;
      EXPECT_EQ(other.value(baked.options) == 12345.0, other.name == option.name) << key;
    }
  }
}

// A choice is baked by its name.
TEST(SceneAdapter, ParamsNameAChoice) {
  const b2o::Param p[] = {{"integrator", "xpbd"}, {"dt", "1e-3"}};
  b2o::Scene s = tiny();
  s.param_count = 2;
  s.params = p;
  const Options o = scene_options(s);
  EXPECT_EQ(o.integrator, Integrator::XPBD);
  EXPECT_EQ(o.dt, 1e-3);
}

// A baked value the option refuses is named with its key and not applied; scene_options() throws.
TEST(SceneAdapter, ARefusedValueIsNamedNotApplied) {
  const b2o::Param p[] = {{"dt", "-1"}};
  b2o::Scene s = tiny();
  s.param_count = 1;
  s.params = p;
  const BakedParams baked = read_scene_params(s);
  ASSERT_EQ(baked.refused.size(), 1u);
  EXPECT_EQ(baked.refused[0].key, "dt");
  EXPECT_NE(baked.refused[0].why.find("must be a finite number > 0 (got -1)"), std::string::npos);
  EXPECT_EQ(baked.options.dt, Options{}.dt);
  EXPECT_THROW(scene_options(s), std::runtime_error);
}

TEST(SceneAdapter, ClothBecomesMassesSpringsPinsAndTheRestColliders) {
  Options o;
  o.k_struct = 111;
  o.k_bend = 22;
  const Model m = build_model(tiny(), o);
  EXPECT_EQ(m.scene_name, "tiny");
  ASSERT_EQ(m.mass_count(), 4u);
  ASSERT_EQ(m.spring_count(), 6u);
  EXPECT_EQ(m.x0(0, 1), 0.5);
  EXPECT_EQ(m.pinned[3], 1);
  EXPECT_EQ(m.inv_mass[3], 0.0);
  // the model turns and orders the springs (ModelBuilder::add_cloth): found by their ends
  const auto spring = [&m](std::uint32_t a, std::uint32_t b) {
    for (std::size_t s = 0; s < m.spring_count(); ++s)
      if (m.spring_a[s] == std::min(a, b) && m.spring_b[s] == std::max(a, b)) return s;
    ADD_FAILURE() << "no spring " << a << "-" << b;
    return std::size_t{0};
  };
  EXPECT_EQ(m.spring_kind[spring(0, 1)], 0);
  EXPECT_EQ(m.spring_stiffness(spring(0, 1)), 111);
  EXPECT_EQ(m.spring_stiffness(spring(1, 3)), 22);
  EXPECT_EQ(m.spring_kind[spring(1, 3)], 1);
  EXPECT_EQ(m.rest_length0[spring(0, 2)], static_cast<float>(std::sqrt(0.5)));  // from the rest positions
  ASSERT_EQ(m.cloths.size(), 1u);
  EXPECT_EQ(m.cloths[0].scene_cloth, 0);
  ASSERT_TRUE(m.colliders);
  EXPECT_EQ(m.colliders->object_count(), 1u);
  EXPECT_EQ(m.colliders->object_name(0), "Floor");
  EXPECT_EQ(collider_triangle_count(m), 2u);
}

TEST(SceneAdapter, BadDataNamesTheScene) {
  b2o::Scene s = tiny();
  s.format_version = b2o::kFormatVersion + 1;
  EXPECT_THROW(build_model(s, Options{}), std::runtime_error);
  try {
    build_model(s, Options{});
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("tiny"), std::string::npos);
  }
  s = tiny();
  kIndices[0] = 5;  // the floor names a cloth vertex
  EXPECT_THROW(build_model(s, Options{}), std::runtime_error);
  kIndices[0] = 0;
}

}  // namespace
}  // namespace clothsim
