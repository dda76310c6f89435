// Blender exports added with one line and no PARAMS (the default material, cotton) behave like
// cloth: finite, never stretched past 10 %, never deeper than the contact band in a collider;
// the tablecloth stays on its table with its sides hanging down, at two resolutions; the cloth
// over Suzanne (a non-convex model) rests on it.
#include "scene_run.hpp"

#include <gtest/gtest.h>
#include <drape.h>
#include <tablecloth.h>
#include <tablecloth_fine.h>

#include <cmath>
#include <iostream>

namespace clothsim {
namespace {

// Runs the scene's model for `seconds`, checking every tenth step of dt that the state is
// finite and no structural spring is stretched past 10 %, and every 0.05 s that no layer
// passes through another.
State run_checked(const Model& m, double seconds) {
  State s = make_state(m);
  Workspace ws = test::planned_workspace(m);
  const int steps = static_cast<int>(std::lround(seconds / m.options.dt));
  double worst = 0.0;
  for (int i = 1; i <= steps; ++i) {
    EXPECT_TRUE(test::step_dt(m, s, ws)) << "step " << i;
    if (test::crossing_frame(m, i) && test::expect_no_crossings(m, s) > 0) break;
    if (i % 10 == 0 || i == steps) worst = std::max(worst, max_strain(m, s.x));
  }
  std::cout << m.scene_name << ": max strain " << 100.0 * worst << " %, penetration " << s.max_penetration << " m\n";
  EXPECT_LE(worst, 0.10) << "stretched past 10 %";
  EXPECT_LE(s.max_penetration, m.contact.band);
  return s;
}

// The tablecloth: the masses on the table's top rest on it (none floats), they are a good part
// of the cloth, the cloth has not slid off (its centre over the table's centre), and its sides
// hang down past the table's edge.
void check_tablecloth(const b2o::Scene& scene) {
  const Model m = build_model(scene, scene_options(scene));
  EXPECT_EQ(m.options.material, Material::Cotton);
  const b2o::Object& top = test::find_object(scene, "TableTop");
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double top_y = -1e300, radius = 0.0;
  for (std::uint32_t v = 0; v < top.vertex_count; ++v) c += test::vertex(scene, top.first_vertex + v);
  c /= top.vertex_count;
  for (std::uint32_t v = 0; v < top.vertex_count; ++v) {
    const Eigen::Vector3d p = test::vertex(scene, top.first_vertex + v);
    top_y = std::max(top_y, p.y());
    radius = std::max(radius, std::hypot(p.x() - c.x(), p.z() - c.z()));
  }
  const State s = run_checked(m, 5.0);
  int over = 0;
  for (Eigen::Index k = 0; k < s.x.cols(); ++k) {
    const Eigen::Vector3d p = s.x.col(k);
    // (what hangs down may fold in under the table's top on the floor)
    if (std::hypot(p.x() - c.x(), p.z() - c.z()) > 0.9 * radius || p.y() < top_y - 0.1) continue;
    ++over;
    EXPECT_GE(p.y(), top_y - m.contact.band) << "mass " << k << " sank into the table";
    EXPECT_LE(p.y(), top_y + 0.05) << "mass " << k << " floats above the table";
  }
  EXPECT_GT(over, s.x.cols() / 5) << "little of the cloth is over the table";
  const Eigen::Vector3d mean = s.x.rowwise().mean();
  EXPECT_LT(std::hypot(mean.x() - c.x(), mean.z() - c.z()), 0.1 * radius) << "the cloth slid off the table";
  EXPECT_LT(s.x.row(1).minCoeff(), top_y - 0.3) << "the sides do not hang down";
  EXPECT_LT(kinetic_energy(m, s), 0.01) << "still moving after 5 s";
}

TEST(TableclothScene, StaysOnTheTableWithItsSidesHanging) { check_tablecloth(b2o::gen::tablecloth::scene); }

TEST(TableclothScene, StaysOnTheTableAtFourTimesTheMasses) { check_tablecloth(b2o::gen::tablecloth_fine::scene); }

// The cloth over Suzanne: it rests on her (its top a contact distance above hers, not slid
// off onto the floor) and hangs around her.
TEST(DrapeScene, RestsOnSuzanne) {
  const b2o::Scene& scene = b2o::gen::drape::scene;
  const Model m = build_model(scene, scene_options(scene));
  const b2o::Object& head = test::find_object(scene, "Suzanne");
  double head_top = -1e300;
  for (std::uint32_t v = 0; v < head.vertex_count; ++v)
    head_top = std::max(head_top, test::vertex(scene, head.first_vertex + v).y());
  const State s = run_checked(m, 5.0);
  const double cloth_top = s.x.row(1).maxCoeff();
  EXPECT_GT(cloth_top, head_top) << "the cloth fell past Suzanne";
  EXPECT_LT(cloth_top, head_top + 0.05) << "the cloth is not resting on Suzanne";
  EXPECT_LT(kinetic_energy(m, s), 0.01) << "still moving after 5 s";
}

}  // namespace
}  // namespace clothsim
