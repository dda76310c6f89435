// run_app() on scenes filled by hand: a baked value the simulator refuses (PARAMS dt=-1: the
// message says the scene bakes it, and the command line can override it), a baked gravity, a
// scene without cloth, a cloth that starts through itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <clothsim/self_crossings.hpp>

#include "../viewer/hand_scene.hpp"
#include "app.hpp"

namespace {

int run(const b2o::Scene& scene, const std::vector<std::string>& options, std::string& err) {
  std::vector<std::string> args{"clothsim"};
  for (const std::string& o : options) args.push_back(o);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::testing::internal::CaptureStderr();
  const int code = clothsim::run_app(static_cast<int>(args.size()), argv.data(), scene);
  err = ::testing::internal::GetCapturedStderr();
  return code;
}

TEST(AppParams, ABakedValueOutOfRangeIsNamedAsTheScenes) {
  clothsim::testing::HandScene hand(6);
  const b2o::Param params[] = {{"dt", "-1"}};
  hand.scene.params = params;
  hand.scene.param_count = 1;
  std::string err;
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "2"}, err), 2);
  EXPECT_NE(err.find("dt must be a finite number > 0 (got -1), baked into scene"), std::string::npos) << err;
  // given on the command line, the user's value is the one refused, without the scene's note
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "2", "--dt", "-2"}, err), 2);
  EXPECT_NE(err.find("(got -2)"), std::string::npos) << err;
  EXPECT_EQ(err.find("baked into scene"), std::string::npos) << err;
  // and a good one overrides the scene's
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "2", "--dt", "0.001"}, err), 0) << err;
  // the user's own value, equal to the scene's bad one: the user's
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "2", "--dt", "-1"}, err), 2);
  EXPECT_EQ(err.find("baked into scene"), std::string::npos) << err;
}

TEST(AppParams, TheFailingValueIsTheOneNamed) {
  clothsim::testing::HandScene hand(6);
  const b2o::Param params[] = {{"dt", "-1"}, {"mass", "0"}};
  hand.scene.params = params;
  hand.scene.param_count = 2;
  std::string err;
  // dt given and good: the scene's mass is what fails, and it is named as the scene's
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "2", "--dt", "0.001"}, err), 2);
  EXPECT_NE(err.find("mass must be a finite number > 0 (got 0), baked into scene"), std::string::npos) << err;
}

// A baked gravity with a horizontal part: --help shows the scene's component, and --gravity,
// which sets (0, -G, 0), says that it replaces it.
TEST(AppParams, ABakedGravityVectorIsShownAndItsReplacementSaid) {
  clothsim::testing::HandScene hand(6);
  const b2o::Param params[] = {{"gravity_x", "3"}};
  hand.scene.params = params;
  hand.scene.param_count = 1;
  std::string err;
  ::testing::internal::CaptureStdout();
  std::string ignored;
  EXPECT_EQ(run(hand.scene, {"--help"}, ignored), 0);
  const std::string help = ::testing::internal::GetCapturedStdout();
  EXPECT_NE(help.find("--gravity-x       0 (scene 'hand': 3)"), std::string::npos) << help;
  EXPECT_EQ(run(hand.scene, {"--headless", "--steps", "2", "--gravity", "9.81"}, err), 0) << err;
  EXPECT_NE(err.find("--gravity 9.81 replaces the scene's gravity (3, -9.81, 0) by (0, -9.81, 0)"), std::string::npos)
      << err;
}

}  // namespace

namespace {

// A scene baked without CLOTH (every object a collider; blender2ogl_add_scene allows it):
// nothing moves, and a run (its start-up checks too) says so and ends cleanly.
TEST(AppParams, ASceneWithoutClothRunsAndSaysSo) {
  clothsim::testing::HandScene hand(6);
  hand.objects[0].cloth = b2o::kNone;
  hand.scene.cloth_count = 0;
  hand.scene.cloths = nullptr;
  const std::string report = ::testing::TempDir() + "no_cloth.json";
  std::string err;
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "5", "--report", report}, err), 0) << err;
  EXPECT_NE(err.find("no cloth"), std::string::npos) << err;
  std::ifstream in(report);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("\"masses\": 0"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("\"finite\": true"), std::string::npos) << text.str();
}

// A cloth that starts through itself: named at start-up with its count when self-contact is
// on (it cannot be undone), and the run goes on; with self-contact off, nothing to say.
TEST(AppParams, AClothThatStartsThroughItselfIsNamedAtStart) {
  clothsim::testing::HandScene hand(6);
  // a corner mass and its neighbour put on either side of the cloth's middle: their edge
  // passes through triangles it shares no mass with
  for (std::vector<float>* xyz : {&hand.positions, &hand.rest}) {
    const float moved[6] = {0.05f, 0.9f, 0.05f, 0.05f, 1.5f, 0.07f};
    std::copy(moved, moved + 6, xyz->begin());
  }
  Eigen::Matrix3Xd x(3, static_cast<Eigen::Index>(hand.rest.size() / 3));
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = hand.rest[static_cast<std::size_t>(i)];
  const std::size_t crossings = clothsim::count_self_crossings(x, hand.triangles).crossings;
  ASSERT_GT(crossings, 0u);
  std::string err;
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "3"}, err), 0) << err;
  EXPECT_NE(err.find("warning: the cloth starts with " + std::to_string(crossings) + " self-crossings"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("cannot undo these"), std::string::npos) << err;
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "3", "--self-collision", "off"}, err), 0) << err;
  EXPECT_EQ(err.find("self-crossings"), std::string::npos) << err;
}

// A cloth that starts touching itself without crossing (a corner mass put on a triangle of its
// middle, its neighbour lifted): no crossing to count, but the touches are named at start-up.
TEST(AppParams, AClothThatStartsTouchingItselfIsNamedAtStart) {
  clothsim::testing::HandScene hand(6);
  for (std::vector<float>* xyz : {&hand.positions, &hand.rest}) {
    for (std::size_t i = 1; i < xyz->size(); i += 3) (*xyz)[i] = 1.2f;  // level, in the plane y = 1.2
    const float moved[6] = {-0.06f, 1.2f, -0.11f, -0.48f, 1.5f, -0.8f};
    std::copy(moved, moved + 6, xyz->begin());
  }
  Eigen::Matrix3Xd x(3, static_cast<Eigen::Index>(hand.rest.size() / 3));
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = hand.rest[static_cast<std::size_t>(i)];
  const clothsim::CrossingCount c = clothsim::count_self_crossings(x, hand.triangles);
  ASSERT_EQ(c.crossings, 0u);
  ASSERT_GT(c.touches, 0u);
  std::string err;
  EXPECT_EQ(run(hand.scene, {"--headless", "--quiet", "--steps", "3"}, err), 0) << err;
  EXPECT_NE(err.find("warning: the cloth starts with " + std::to_string(c.touches) +
                     " places where an edge touches a triangle"),
            std::string::npos)
      << err;
}

}  // namespace
