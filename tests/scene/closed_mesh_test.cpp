// Closed collider meshes (clothsim/closed_mesh.hpp): closedness, signed volume, inside test,
// and the start-up warnings built from them (a collider whose faces point inwards, cloth
// masses that start inside a collider).
#include <clothsim/closed_mesh.hpp>
#include <clothsim/collision.hpp>

#include <gtest/gtest.h>

#include "floor_collider.hpp"

#include <memory>
#include <vector>

namespace clothsim {
namespace {

// The unit cube [0,1]^3: 8 vertices, 12 triangles, counter-clockwise seen from outside.
Eigen::Matrix3Xd cube_vertices(double size = 1.0, Eigen::Vector3d at = Eigen::Vector3d::Zero()) {
  Eigen::Matrix3Xd v(3, 8);
  for (int i = 0; i < 8; ++i) v.col(i) = at + size * Eigen::Vector3d((i & 1) ? 1 : 0, (i & 2) ? 1 : 0, (i & 4) ? 1 : 0);
  return v;
}
const std::vector<std::uint32_t> kCube = {
    0, 2, 3, 0, 3, 1,  // z = 0, normal -z
    4, 5, 7, 4, 7, 6,  // z = 1, +z
    0, 1, 5, 0, 5, 4,  // y = 0, -y
    2, 6, 7, 2, 7, 3,  // y = 1, +y
    0, 4, 6, 0, 6, 2,  // x = 0, -x
    1, 3, 7, 1, 7, 5}; // x = 1, +x

std::vector<std::uint32_t> flipped(std::vector<std::uint32_t> idx) {
  for (std::size_t t = 0; t < idx.size(); t += 3) std::swap(idx[t + 1], idx[t + 2]);
  return idx;
}

TriangleCorners corners(const Eigen::Matrix3Xd& v, const std::vector<std::uint32_t>& idx) {
  TriangleCorners c(3, static_cast<Eigen::Index>(idx.size()));
  for (std::size_t k = 0; k < idx.size(); ++k) c.col(static_cast<Eigen::Index>(k)) = v.col(idx[k]);
  return c;
}

TEST(ClosedMesh, UnitCubeIsClosedWithVolumePlusOne) {
  const SolidInfo s = analyse_solid(corners(cube_vertices(), kCube));
  EXPECT_TRUE(s.closed);
  EXPECT_NEAR(s.signed_volume, 1.0, 1e-12);
}

TEST(ClosedMesh, FlippedCubeHasVolumeMinusOne) {
  const SolidInfo s = analyse_solid(corners(cube_vertices(), flipped(kCube)));
  EXPECT_TRUE(s.closed);
  EXPECT_NEAR(s.signed_volume, -1.0, 1e-12);
}

TEST(ClosedMesh, VolumeDoesNotDependOnWhereTheCubeIs) {
  const SolidInfo s = analyse_solid(corners(cube_vertices(2.0, {5, -3, 7}), kCube));
  EXPECT_TRUE(s.closed);
  EXPECT_NEAR(s.signed_volume, 8.0, 1e-9);
}

TEST(ClosedMesh, OpenMeshesAreNotClosed) {
  std::vector<std::uint32_t> open(kCube.begin(), kCube.end() - 6);  // no x = 1 side
  EXPECT_FALSE(analyse_solid(corners(cube_vertices(), open)).closed);
  // one face flipped: its edges run the same way as their neighbours'
  std::vector<std::uint32_t> mixed = kCube;
  std::swap(mixed[1], mixed[2]);
  EXPECT_FALSE(analyse_solid(corners(cube_vertices(), mixed)).closed);
  // a plane (the dice's floor): open
  const std::vector<std::uint32_t> plane = {0, 1, 5, 0, 5, 4};
  EXPECT_FALSE(analyse_solid(corners(cube_vertices(), plane)).closed);
  // nothing
  EXPECT_FALSE(analyse_solid(TriangleCorners(3, 0)).closed);
  // a doubled face (an edge in four triangles)
  std::vector<std::uint32_t> doubled = kCube;
  doubled.insert(doubled.end(), kCube.begin(), kCube.begin() + 6);
  EXPECT_FALSE(analyse_solid(corners(cube_vertices(), doubled)).closed);
}

// An export that splits vertices (UV seams: the same position twice) is still closed.
TEST(ClosedMesh, SplitVerticesAreWeldedByPosition) {
  Eigen::Matrix3Xd v(3, 16);
  v << cube_vertices(), cube_vertices();
  std::vector<std::uint32_t> idx = kCube;
  for (std::size_t k = 18; k < idx.size(); ++k) idx[k] += 8;  // the last two sides use the copies
  EXPECT_TRUE(analyse_solid(corners(v, idx)).closed);
}

TEST(ClosedMesh, WindingNumberInsideOutsideAndFlipped) {
  const TriangleCorners c = corners(cube_vertices(), kCube), f = corners(cube_vertices(), flipped(kCube));
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(0.01, 0.99, 0.5),
                                  Eigen::Vector3d(0.999, 0.001, 0.999)}) {
    EXPECT_NEAR(winding_number(c, p), 1.0, 1e-9) << p.transpose();
    EXPECT_NEAR(winding_number(f, p), -1.0, 1e-9) << p.transpose();
  }
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(1.5, 0.5, 0.5), Eigen::Vector3d(-0.01, 0.5, 0.5),
                                  Eigen::Vector3d(10, -20, 30), Eigen::Vector3d(0.5, 1.0001, 0.5)}) {
    EXPECT_NEAR(winding_number(c, p), 0.0, 1e-9) << p.transpose();
    EXPECT_NEAR(winding_number(f, p), 0.0, 1e-9) << p.transpose();
  }
}

TEST(ClosedMesh, CountInsideAndTheWorkBudget) {
  Eigen::Matrix3Xd pts(3, 5);
  pts << 0.5, 0.2, 1.5, 0.5, -3,  //
      0.5, 0.9, 0.5, 0.5, 0,      //
      0.5, 0.1, 0.5, 1.2, 0;
  EXPECT_EQ(count_inside(corners(cube_vertices(), kCube), pts), 2);
  EXPECT_EQ(count_inside(corners(cube_vertices(), flipped(kCube)), pts), 2);
  // 2 points in the bounding box x 12 triangles = 24 tests: over a budget of 20, skipped (-1)
  EXPECT_EQ(count_inside(corners(cube_vertices(), kCube), pts, 20), -1);
  EXPECT_EQ(count_inside(corners(cube_vertices(), kCube), pts, 24), 2);
}

// A model: 4 masses, 3 of them inside a box collider; a floor plane (open: never warned about).
Model model_with(const std::vector<std::uint32_t>& box) {
  auto set = std::make_shared<ColliderSet>();
  Eigen::Matrix3Xd floor(3, 4);
  floor << -5, 5, 5, -5, -1, -1, -1, -1, -5, -5, 5, 5;
  set->add_object("Floor", floor, std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2});
  set->add_object("Box", cube_vertices(), box);
  set->build();
  Model m;
  m.x0.resize(3, 4);
  m.x0 << 0.5, 0.2, 0.8, 3, 0.5, 0.5, 0.5, 3, 0.5, 0.5, 0.5, 3;
  m.colliders = set;
  return m;
}

TEST(ColliderWarnings, MassesInsideAClosedCollider) {
  const std::vector<std::string> w = collider_warnings(model_with(kCube));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("warning: 3 of 4 masses start inside collider 'Box'"), std::string::npos) << w[0];
}

TEST(ColliderWarnings, InwardFacesAreNamedWithTheVolume) {
  const std::vector<std::string> w = collider_warnings(model_with(flipped(kCube)));
  ASSERT_EQ(w.size(), 2u);
  EXPECT_NE(w[0].find("collider 'Box' faces point inwards (signed volume -1 m^3)"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("Recalculate Outside"), std::string::npos) << w[0];
  EXPECT_NE(w[1].find("3 of 4 masses start inside collider 'Box'"), std::string::npos) << w[1];
}

// Part by part, as the bake: a small inside-out box beside a large outward one (the sum of the
// volumes is positive: a whole-mesh check misses it), not when it is inside the large one
// (a cavity: a hollow box's inner wall rightly faces into the hollow), and a box with one face
// flipped (not a consistent solid: a whole-mesh check calls it open and says nothing).
TEST(ColliderWarnings, PartsAreCheckedOneByOne) {
  auto set = std::make_shared<ColliderSet>();
  auto pair_of_boxes = [](Eigen::Vector3d small_at) {
    Eigen::Matrix3Xd v(3, 16);
    v << cube_vertices(4.0, {-2, -2, -2}), cube_vertices(1.0, small_at);
    std::vector<std::uint32_t> idx = kCube, small = flipped(kCube);
    for (std::uint32_t& k : small) k += 8;
    idx.insert(idx.end(), small.begin(), small.end());
    return std::make_pair(v, idx);
  };
  const auto [beside, beside_idx] = pair_of_boxes({5, 0, 0});
  set->add_object("Nested", beside, beside_idx);
  const auto [hollow, hollow_idx] = pair_of_boxes({-0.5, -0.5, -0.5});
  set->add_object("Hollow", hollow, hollow_idx);
  std::vector<std::uint32_t> mixed = kCube;
  std::swap(mixed[1], mixed[2]);
  set->add_object("Mixed", cube_vertices(1.0, {10, 0, 0}), mixed);
  // -0.0 and +0.0 are one position: a cube with a -0.0 copy of a corner is still closed
  Eigen::Matrix3Xd negzero(3, 9);
  negzero << cube_vertices(1.0, {20, 0, 0}), Eigen::Vector3d(20, 0, -0.0);
  negzero(2, 0) = 0.0;  // corner 0 is (20, 0, +0); corner 8 (20, 0, -0) replaces it in one face
  std::vector<std::uint32_t> nz = flipped(kCube);
  nz[0] = 8;
  set->add_object("Signed zero", negzero, nz);
  set->build();
  Model m;
  m.x0 = Eigen::Matrix3Xd::Constant(3, 2, 30.0);  // nothing inside
  m.colliders = set;
  const std::vector<std::string> w = collider_warnings(m);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_NE(w[0].find("collider 'Nested' faces point inwards (signed volume -1 m^3 in 1 of its 2 parts)"),
            std::string::npos) << w[0];
  EXPECT_NE(w[1].find("collider 'Mixed' is closed with faces pointing both ways (3 edges used twice the same way)"),
            std::string::npos) << w[1];
  EXPECT_NE(w[2].find("collider 'Signed zero' faces point inwards (signed volume -1 m^3)"), std::string::npos) << w[2];
}

// An open collider pushes only towards its front: masses that start behind a face (their foot
// on it) are named, within the band (shot out at once) and farther (pulled through on contact:
// a floor whose normals point down). Masses in front, or beside the plane's edge, are not.
TEST(ColliderWarnings, MassesBehindAnOpenColliderAreNamed) {
  auto floor_model = [](bool normals_up, const std::vector<Eigen::Vector3d>& masses) {
    auto set = std::make_shared<ColliderSet>();
    Eigen::Matrix3Xd v(3, 4);
    v << -1, 1, 1, -1, 0, 0, 0, 0, -1, -1, 1, 1;
    set->add_object("Floor", v, normals_up ? std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2}
                                           : std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3});
    set->build();
    Model m;
    m.x0.resize(3, static_cast<Eigen::Index>(masses.size()));
    for (std::size_t i = 0; i < masses.size(); ++i) m.x0.col(static_cast<Eigen::Index>(i)) = masses[i];
    m.options.material = Material::Seed;
    m.options.epsilon = 0.1;
    m.contact.distance = 0.1;  // (as the builder sets it from epsilon)
    m.colliders = set;
    return m;
  };
  // above an upward floor, and below its level but beside its edge: nothing
  EXPECT_TRUE(collider_warnings(floor_model(true, {{0, 0.5, 0}, {0.2, 0.05, 0.1}, {1.5, -0.05, 0}})).empty());
  // just under an upward floor: within the band
  std::vector<std::string> w = collider_warnings(floor_model(true, {{0, -0.05, 0}, {0.3, -0.15, 0}, {0, 0.5, 0}}));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("2 of 3 masses start behind collider 'Floor' within its contact band (0.2 m)"), std::string::npos)
      << w[0];
  // above a floor whose normals point down: behind it, farther than the band
  w = collider_warnings(floor_model(false, {{0, 0.6, 0}, {0.5, 0.6, 0.5}}));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("2 of 2 masses start behind collider 'Floor' (on the side its normals point away from)"),
            std::string::npos) << w[0];
  EXPECT_NE(w[0].find("Flip"), std::string::npos) << w[0];
}

// Masses that start deep in a collider's contact band are thrown off at once (the dice cloth
// at --epsilon 3 flies 100 m up): warned when the push k_rep (eps - d) is over 10x their
// weight. A mass at its resting depth (eps - m g / k_rep) or just inside the band is not.
TEST(ColliderWarnings, MassesThrownOutOfTheContactBandAreNamed) {
  const std::shared_ptr<ColliderSet> set = test::floor_collider();  // y = 0, normals up
  Model m;
  m.options.material = Material::Seed;
  m.options.epsilon = 0.1;
  m.options.k_rep = 600.0;
  m.contact.distance = 0.1, m.contact.k_rep = 600.0;  // (as the builder sets them)
  const double rest = 0.1 - 0.1 * 9.81 / 600.0;  // eps - m g / k_rep
  m.x0.resize(3, 5);
  m.x0 << 0, 0.1, 0.2, 0.3, 0.4,  //
      0.5, rest, 0.099, 0.05, 0.01,  //
      0, 0, 0, 0, 0;
  m.mass = Eigen::VectorXd::Constant(5, 0.1);
  m.colliders = set;
  const auto expect_one_warning = [](const Model& model, const std::string& part) {
    const std::vector<std::string> w = collider_warnings(model);
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find(part), std::string::npos) << w[0];
  };
  expect_one_warning(m, "warning: 2 of 5 masses start within the contact band of collider 'floor' (epsilon 0.1 m) "
                        "and get up to 55 times their weight at once");
  const LaunchCount l = count_launched(*set, 0, m.x0, m.mass, {}, 0.1, 600.0, 9.81, 10.0);
  EXPECT_EQ(l.count, 2u);
  EXPECT_NEAR(l.worst, 600.0 * 0.09 / 0.981, 1e-9);
  // a pinned mass is held, not thrown (a flag pinned at its pole); without gravity any push
  // throws, and the message gives it in newtons
  m.pinned = {0, 0, 0, 0, 1};
  EXPECT_EQ(count_launched(*set, 0, m.x0, m.mass, m.pinned, 0.1, 600.0, 9.81, 10.0).count, 1u);
  m.options.gravity_x = m.options.gravity_y = m.options.gravity_z = 0.0;
  expect_one_warning(m, "3 of 5 masses start within the contact band of collider 'floor' (epsilon 0.1 m) and get "
                        "up to 30 N at once, with no gravity to hold them");
}

TEST(ColliderWarnings, NoneForACleanSceneOrWithoutColliders) {
  Model m = model_with(kCube);
  m.x0.setConstant(3.0);  // every mass outside
  EXPECT_TRUE(collider_warnings(m).empty());
  EXPECT_TRUE(collider_warnings(Model{}).empty());
  // above the work budget: no count, no message
  EXPECT_TRUE(collider_warnings(model_with(kCube), 1.0).empty());
}

}  // namespace
}  // namespace clothsim
