// The dice scene at real gravity: both dice land on the plane and stay on it, keeping their
// shape.
#include "scene_run.hpp"

#include <dice.h>
#include <gtest/gtest.h>

namespace clothsim {
namespace {

const b2o::Scene& scene() { return b2o::gen::dice::scene; }

TEST(DiceScene, BothDiceLandOnThePlaneAndStayOnIt) {
  const Model m = build_model(scene(), scene_options(scene()));
  ASSERT_EQ(m.cloths.size(), 2u);
  ASSERT_TRUE(m.colliders);
  const Options& o = m.options;
  const b2o::Object& plane = test::find_object(scene(), "Plane");
  const double plane_y = test::vertex(scene(), plane.first_vertex).y();
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  const int steps = static_cast<int>(std::lround(10.0 / o.dt));
  for (int i = 1; i <= steps; ++i) {
    ASSERT_TRUE(step(m, s, ws).finite) << "step " << i;
    ASSERT_GE(s.x.row(1).minCoeff(), plane_y - o.epsilon) << "a die went through the plane at step " << i;
  }
  const double rest = o.epsilon - o.mass * 9.81 / o.k_rep;  // penalty resting height
  for (const ClothRange& r : m.cloths) {
    const auto x = s.x.middleCols(r.first_mass, r.mass_count);
    const Eigen::Vector3d lo = x.rowwise().minCoeff(), hi = x.rowwise().maxCoeff();
    const Eigen::Vector3d lo0 = m.x0.middleCols(r.first_mass, r.mass_count).rowwise().minCoeff();
    EXPECT_LT(lo.y(), lo0.y() - 0.5) << "die " << r.scene_cloth << " did not fall";
    EXPECT_GT(lo.y(), plane_y + 0.5 * rest) << "die " << r.scene_cloth;
    EXPECT_LT(lo.y(), plane_y + o.epsilon) << "die " << r.scene_cloth << " is not on the plane";
    EXPECT_GT(hi.y() - lo.y(), 0.4) << "die " << r.scene_cloth << " collapsed";
    EXPECT_LT(hi.y() - lo.y(), 0.9) << "die " << r.scene_cloth << " is not resting";
    EXPECT_LT(hi.cwiseAbs().maxCoeff(), 3.0) << "die " << r.scene_cloth << " left the plane";
  }
  EXPECT_LT(kinetic_energy(m, s), 0.01);
  EXPECT_LE(s.max_penetration, o.epsilon);
}

}  // namespace
}  // namespace clothsim
