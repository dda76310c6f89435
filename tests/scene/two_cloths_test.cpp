// The two_cloths scene: two 1 m squares, the upper turned 45 degrees and 0.3 m higher, fall onto
// a 0.5 m box on a floor; both end draped over the box, none fallen through it or the floor.
#include "scene_run.hpp"

#include <gtest/gtest.h>
#include <two_cloths.h>

#include <iostream>

namespace clothsim {
namespace {

TEST(TwoClothsScene, BothClothsEndDrapedOverTheBox) {
  const b2o::Scene& scene = b2o::gen::two_cloths::scene;
  const Model m = build_model(scene, scene_options(scene));
  ASSERT_EQ(m.cloths.size(), 2u);
  const b2o::Object& box = test::find_object(scene, "Box");
  double top = -1e300, half = 0.0;
  for (std::uint32_t v = 0; v < box.vertex_count; ++v) {
    const Eigen::Vector3d p = test::vertex(scene, box.first_vertex + v);
    top = std::max(top, p.y());
    half = std::max(half, std::abs(p.x()));
  }
  const State s = test::run_for(m, 5.0);
  ASSERT_TRUE(s.x.allFinite());
  const double band = m.contact.band;
  for (std::size_t c = 0; c < m.cloths.size(); ++c) {
    const ClothRange& r = m.cloths[c];
    const auto x = s.x.middleCols(r.first_mass, r.mass_count);
    const Eigen::Vector3d mean = x.rowwise().mean();
    int on_top = 0;
    for (Eigen::Index k = 0; k < x.cols(); ++k) {
      const Eigen::Vector3d p = x.col(k);
      EXPECT_GE(p.y(), -band) << "cloth " << c << " mass " << k << " fell through the floor";
      const bool over_box = std::abs(p.x()) < half - band && std::abs(p.z()) < half - band;
      if (!over_box) continue;
      EXPECT_GE(p.y(), top - band) << "cloth " << c << " mass " << k << " sank into the box";
      if (p.y() < top + 0.05) ++on_top;
    }
    std::cout << "two_cloths: cloth " << c << " mean (" << mean.transpose() << "), " << on_top
              << " masses on the box's top, lowest " << x.row(1).minCoeff() << " m\n";
    EXPECT_LT(std::hypot(mean.x(), mean.z()), 0.1) << "cloth " << c << " slid off the box";
    EXPECT_GT(on_top, x.cols() / 8) << "cloth " << c << " is not draped over the box";
    EXPECT_LT(x.row(1).minCoeff(), top - 0.1) << "cloth " << c << " does not hang over the box's sides";
  }
  EXPECT_LT(kinetic_energy(m, s), 0.01) << "still moving after 5 s";
}

}  // namespace
}  // namespace clothsim
