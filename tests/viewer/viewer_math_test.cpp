// The viewer's GL-free parts: camera, real-time pacing, cloth normals, framing, picking.
#include "hand_scene.hpp"

#include <clothsim/scene.hpp>
#include <clothsim/sim.hpp>
#include <clothsim/view/camera.hpp>
#include <clothsim/view/cloth_mesh.hpp>
#include <clothsim/view/pacing.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace cv = clothsim::view;

namespace {

Eigen::Vector3d project(const cv::OrbitCamera& cam, double aspect, const Eigen::Vector3d& p) {
  const Eigen::Vector4f c = cam.projection(aspect) * cam.view() * Eigen::Vector4f(
      static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), 1.0f);
  return Eigen::Vector3d(c.x() / c.w(), c.y() / c.w(), c.z() / c.w());
}

clothsim::Model hand_model(const clothsim::testing::HandScene& h) {
  return clothsim::build_model(h.scene, clothsim::scene_options(h.scene));
}

}  // namespace

TEST(Camera, FrameKeepsEveryCornerOfTheBoxInView) {
  for (double aspect : {16.0 / 9.0, 1.0, 0.5}) {
    cv::OrbitCamera cam;
    const Eigen::Vector3d lo(-1.5, -2.3, -1.4), hi(1.5, 1.1, 1.6);
    cam.frame(lo, hi, aspect);
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                              (corner & 4) ? hi.z() : lo.z());
      const Eigen::Vector3d ndc = project(cam, aspect, p);
      EXPECT_LE(std::abs(ndc.x()), 1.0) << "aspect " << aspect << " corner " << corner;
      EXPECT_LE(std::abs(ndc.y()), 1.0) << "aspect " << aspect << " corner " << corner;
      EXPECT_LT(std::abs(ndc.z()), 1.0) << "depth range clips corner " << corner;
    }
    // ... and fills a fair part of the picture (not a dot in the middle).
    const Eigen::Vector3d a = project(cam, aspect, lo), b = project(cam, aspect, hi);
    EXPECT_GT((a - b).head<2>().norm(), 0.5);
  }
}

TEST(Camera, RayThroughAPixelHitsWhatProjectsThere) {
  cv::OrbitCamera cam;
  cam.frame(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 1.5);
  cam.orbit(123.0, -40.0);
  const double w = 900, h = 600;
  const Eigen::Vector3d p(0.3, -0.4, 0.7);
  const Eigen::Vector3d ndc = project(cam, w / h, p);
  const double px = (ndc.x() + 1.0) * 0.5 * w, py = (1.0 - ndc.y()) * 0.5 * h;
  const cv::Ray ray = cam.ray(px, py, w, h);
  EXPECT_NEAR(ray.dir.norm(), 1.0, 1e-12);
  const Eigen::Vector3d q = p - ray.origin;
  EXPECT_LT((q - q.dot(ray.dir) * ray.dir).norm(), 1e-5);  // p lies on the ray
  // The centre pixel looks at the target.
  const cv::Ray c = cam.ray(w / 2, h / 2, w, h);
  EXPECT_LT((c.origin + cam.distance * c.dir - cam.target).norm(), 1e-9);
}

TEST(Camera, OrbitPanZoom) {
  cv::OrbitCamera cam;
  cam.target = Eigen::Vector3d(1, 2, 3);
  cam.distance = 4.0;
  cam.orbit(500.0, 10000.0);  // far past straight down
  EXPECT_NEAR((cam.eye() - cam.target).norm(), 4.0, 1e-12);
  EXPECT_LT(cam.pitch, 1.5708);  // clamped: the view never flips over the pole
  EXPECT_TRUE(cam.view().allFinite());
  const Eigen::Vector3d before = cam.target;
  cam.pan(30.0, -20.0, 600);
  EXPECT_GT((cam.target - before).norm(), 0.0);
  EXPECT_NEAR((cam.target - before).dot(cam.forward()), 0.0, 1e-12);  // in the view plane
  cam.zoom(2.0);
  EXPECT_LT(cam.distance, 4.0);
  cam.zoom(-2.0);
  EXPECT_NEAR(cam.distance, 4.0, 1e-12);
}

TEST(Camera, ZoomedFarOutTheSceneStaysBeforeTheFarPlane) {
  cv::OrbitCamera cam;
  cam.frame(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 1.0);
  const double beyond = cam.far_plane - cam.distance;  // depth kept behind the target
  cam.zoom(-40.0);  // 40 wheel steps out: distance x 166
  EXPECT_GT(cam.distance, 100.0);
  EXPECT_NEAR(cam.far_plane - cam.distance, beyond, 1e-9 * cam.far_plane);
  cam.zoom(40.0);
  EXPECT_NEAR(cam.far_plane - cam.distance, beyond, 1e-9 * cam.far_plane);
  EXPECT_GT(cam.far_plane, cam.near_plane);
}

TEST(Camera, DragTargetStaysAtTheGrabbedDepthUnderTheCursor) {
  cv::OrbitCamera cam;
  cam.frame(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1), 1.0);
  const double w = 400, h = 400;
  // Grab a point, move the cursor: the target is under the new cursor, at the same depth.
  const Eigen::Vector3d grabbed(0.2, 0.1, -0.3);
  const double depth = (grabbed - cam.eye()).dot(cam.forward());
  const cv::Ray moved = cam.ray(300, 120, w, h);
  Eigen::Vector3d target;
  ASSERT_TRUE(cv::point_at_depth(moved, cam.eye(), cam.forward(), depth, target));
  EXPECT_NEAR((target - cam.eye()).dot(cam.forward()), depth, 1e-9);
  const Eigen::Vector3d ndc = project(cam, 1.0, target);
  EXPECT_NEAR((ndc.x() + 1.0) * 0.5 * w, 300.0, 1e-3);
  EXPECT_NEAR((1.0 - ndc.y()) * 0.5 * h, 120.0, 1e-3);
  // The unmoved cursor gives back the grabbed point.
  const Eigen::Vector3d g = project(cam, 1.0, grabbed);
  ASSERT_TRUE(cv::point_at_depth(cam.ray((g.x() + 1) * 0.5 * w, (1 - g.y()) * 0.5 * h, w, h), cam.eye(),
                                 cam.forward(), depth, target));
  EXPECT_LT((target - grabbed).norm(), 1e-5);
  // A ray along the plane has no such point.
  const cv::Ray sideways{cam.eye(), cam.forward().cross(Eigen::Vector3d::UnitY()).normalized()};
  EXPECT_FALSE(cv::point_at_depth(sideways, cam.eye(), cam.forward(), depth, target));
}

TEST(StepClock, CarriesTheRemainderSoRealTimeIsKept) {
  cv::StepClock clock(0.01, 0.1);
  long steps = 0;
  for (int frame = 0; frame < 600; ++frame) steps += clock.steps_due(1.0 / 60.0, 1e-4);
  // 10 s of wall time at dt 0.01: 1000 steps, give or take the carried remainder.
  EXPECT_GE(steps, 999);
  EXPECT_LE(steps, 1000);
  EXPECT_FALSE(clock.behind());
  EXPECT_LT(clock.carried(), 0.01);
  EXPECT_EQ(clock.dropped(), 0.0);  // kept up: the closing line says so
}

TEST(StepClock, CapsWorkPerFrameAndDropsTheBacklog) {
  cv::StepClock clock(0.001, 0.1);
  // Each step costs 2 ms: at most 50 steps fit in 100 ms, though a 0.2 s frame asks for 200.
  const long n = clock.steps_due(0.2, 0.002);
  EXPECT_EQ(n, 50);
  EXPECT_TRUE(clock.behind());
  EXPECT_LT(clock.carried(), 0.001);  // nothing owed: no spiral
  // What was given up is counted: 0.2 s due, 50 steps of 1 ms taken, the rest dropped.
  EXPECT_NEAR(clock.dropped() + clock.carried(), 0.15, 1e-12);
  EXPECT_GT(clock.dropped(), 0.149);
  // A machine so slow that one step exceeds the cap still moves one step per frame.
  cv::StepClock slow(0.01, 0.1);
  EXPECT_EQ(slow.steps_due(0.5, 0.3), 1);
  EXPECT_TRUE(slow.behind());
  // Fast enough again: behind() clears, and nothing more is dropped.
  const double before = clock.dropped();
  EXPECT_EQ(clock.steps_due(0.0101, 1e-5), 10);
  EXPECT_FALSE(clock.behind());
  EXPECT_EQ(clock.dropped(), before);
  // A stalled frame (the window dragged, the process stopped): beyond 0.25 s is dropped.
  cv::StepClock stalled(0.01, 0.1);
  stalled.steps_due(1.0, 1e-6);
  EXPECT_NEAR(stalled.dropped(), 0.75, 1e-12);
}

TEST(StepClock, TakesOneStepWhileTheCostIsUnknownAndOwesTheRest) {
  // 0.2 s of backlog at dt 1 ms: 200 steps are due, but an unmeasured step could take seconds.
  cv::StepClock clock(0.001, 0.1);
  EXPECT_EQ(clock.steps_due(0.2, 0.0), 1);
  EXPECT_FALSE(clock.behind());
  EXPECT_NEAR(clock.carried(), 0.199, 1e-9);  // the first frame's time is still owed
  EXPECT_EQ(clock.dropped(), 0.0);             // owed, not dropped
  // Measured and cheap: the next frame takes the backlog too, and real time is kept.
  EXPECT_EQ(clock.steps_due(0.001, 1e-6), 200);
  EXPECT_FALSE(clock.behind());
  // Measured and dear (2 ms a step): the backlog is taken within the cap, the rest dropped.
  cv::StepClock dear(0.001, 0.1);
  EXPECT_EQ(dear.steps_due(0.2, 0.0), 1);
  EXPECT_EQ(dear.steps_due(0.001, 0.002), 50);
  EXPECT_TRUE(dear.behind());
  EXPECT_LT(dear.carried(), 0.001);
  // Nothing due and the cost unknown: no step, nothing owed.
  cv::StepClock idle(0.01, 0.1);
  EXPECT_EQ(idle.steps_due(0.001, 0.0), 0);
  EXPECT_NEAR(idle.carried(), 0.001, 1e-12);
}

TEST(StepClock, CostEstimateRisesSmoothlyAndFallsAtOnce) {
  EXPECT_EQ(cv::next_step_cost(0.0, 0.004), 0.004);          // the first measurement
  EXPECT_DOUBLE_EQ(cv::next_step_cost(0.001, 0.002), 0.0012);  // a dearer frame: smoothed
  EXPECT_EQ(cv::next_step_cost(0.004, 0.0005), 0.0005);       // a cheaper one: taken at once
  // The cold first step (4 ms) then steps of 0.5 ms: the cap is back to 200 steps of 0.5 ms
  // in the next frame, not after ten.
  cv::StepClock clock(0.001, 0.1);
  const double cost = cv::next_step_cost(cv::next_step_cost(0.0, 0.004), 0.0005);
  EXPECT_EQ(clock.steps_due(0.25, cost), 200);
}

TEST(StepClock, IgnoresBadElapsedTimes) {
  cv::StepClock clock(0.01, 0.1);
  EXPECT_EQ(clock.steps_due(-1.0, 0.0), 0);
  EXPECT_EQ(clock.steps_due(std::numeric_limits<double>::quiet_NaN(), 0.0), 0);
  EXPECT_LE(clock.steps_due(1e9, 1e-6), 25);  // a stall is not caught up
}

TEST(StepsOfDt, CountsStepsOfTheUsersDtNotSubsteps) {
  const cv::StepsOfDt four{4};
  EXPECT_EQ(four.completed(40), 10u);
  EXPECT_EQ(four.completed(43), 10u);  // a step of dt half done is not done
  // A failure in any substep of step 11 of dt is step 11's, and 10 steps were completed.
  for (std::uint64_t model_step : {41u, 43u, 44u}) {
    EXPECT_EQ(four.containing(model_step), 11u) << model_step;
    EXPECT_EQ(four.completed_before_failure(model_step), 10u) << model_step;
  }
  EXPECT_EQ(four.step_label(43), "step 11, substep 3 of 4");
  const cv::StepsOfDt one{1};
  EXPECT_EQ(one.completed(40), 40u);
  EXPECT_EQ(one.containing(40), 40u);
  EXPECT_EQ(one.completed_before_failure(40), 39u);
  EXPECT_EQ(one.step_label(40), "step 40");
  EXPECT_EQ(cv::StepsOfDt{0}.completed(40), 40u);  // no substeps given: each step is one
}

TEST(StepsOfDt, TitleRatesArePerStepOfTheUsersDt) {
  // 40 model steps of dt / 4 in 1 s of wall time, 8 ms of stepping, 0.04 s simulated: 10 steps
  // of dt per second at 0.8 ms each (4 substeps of 0.2 ms).
  const cv::StepRates r = cv::step_rates(cv::StepsOfDt{4}, 40, 0.008, 0.04, 1.0);
  EXPECT_DOUBLE_EQ(r.steps_per_s, 10.0);
  EXPECT_DOUBLE_EQ(r.ms_per_step, 0.8);
  EXPECT_DOUBLE_EQ(r.realtime, 0.04);
  EXPECT_EQ(cv::stats_text("skirt", 1280, 720, 0.04, r, " | paused"),
            "clothsim skirt | 1280x720 | t 0.04 s | 10 steps/s | 0.80 ms/step | 0.04x real time | paused");
  // Without substeps the counts are the model's.
  const cv::StepRates one = cv::step_rates(cv::StepsOfDt{1}, 40, 0.008, 0.04, 1.0);
  EXPECT_DOUBLE_EQ(one.steps_per_s, 40.0);
  EXPECT_DOUBLE_EQ(one.ms_per_step, 0.2);
  // Nothing measured yet: zeros, not NaN.
  const cv::StepRates none = cv::step_rates(cv::StepsOfDt{4}, 0, 0.0, 0.0, 0.0);
  EXPECT_EQ(none.steps_per_s, 0.0);
  EXPECT_EQ(none.ms_per_step, 0.0);
  EXPECT_EQ(none.realtime, 0.0);
}

TEST(Renderer, SoftwareRenderersAreRecognised) {
  EXPECT_TRUE(cv::software_renderer("llvmpipe (LLVM 15.0.6, 256 bits)"));
  EXPECT_TRUE(cv::software_renderer("softpipe"));
  EXPECT_TRUE(cv::software_renderer("Google SwiftShader"));
  EXPECT_TRUE(cv::software_renderer("Microsoft Basic Render Driver (Software)"));
  EXPECT_FALSE(cv::software_renderer("NVIDIA GeForce RTX 3060/PCIe/SSE2"));
  EXPECT_FALSE(cv::software_renderer("AMD Radeon Graphics (radeonsi, gfx1103, LLVM 15.0.6)"));
  EXPECT_FALSE(cv::software_renderer("Mesa Intel(R) UHD Graphics 620 (KBL GT2)"));
  EXPECT_FALSE(cv::software_renderer(""));
}

TEST(ClothMesh, FlatClothNormalsPointAlongTheWinding) {
  clothsim::testing::HandScene h(6, 1.0f, 1.0f);
  const clothsim::Model model = hand_model(h);
  clothsim::State state = clothsim::make_state(model);
  std::vector<float> pos(h.positions), nrm(h.normals.size(), 0.0f);
  std::vector<double> scratch;
  ASSERT_TRUE(cv::update_cloth_vertices(h.scene, model, state, pos, nrm, scratch));
  // The grid is tilted by y = 0.15 x: its normal is (-0.15, 1, 0) normalised.
  const Eigen::Vector3d expect = Eigen::Vector3d(-0.15, 1.0, 0.0).normalized();
  for (std::uint32_t v = 0; v < 36; ++v)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(nrm[3 * v + k], expect[k], 1e-5) << "vertex " << v;
  // Moving a mass moves its render vertex; the floor's vertices are left alone.
  state.x.col(7) += Eigen::Vector3d(0.0, 0.5, 0.0);
  ASSERT_TRUE(cv::update_cloth_vertices(h.scene, model, state, pos, nrm, scratch));
  EXPECT_FLOAT_EQ(pos[3 * 7 + 1], static_cast<float>(state.x(1, 7)));
  for (std::size_t i = 3 * 36; i < pos.size(); ++i) EXPECT_EQ(pos[i], h.positions[i]);
}

TEST(ClothMesh, NormalsAreAreaWeightedAndSharedAcrossSeams) {
  // Two triangles folded along the edge (1, 2): masses 0..3, the big triangle dominates.
  clothsim::State state;
  state.x.resize(3, 4);
  state.x.col(0) << 0, 0, 0;
  state.x.col(1) << 1, 0, 0;
  state.x.col(2) << 0, 0, -1;
  state.x.col(3) << 1, 3, -1;  // second triangle tilted up, larger
  const std::uint32_t tris[] = {0, 1, 2, 1, 3, 2};
  std::vector<double> n(12, 0.0);
  cv::accumulate_mass_normals(state, 0, tris, 2, n);
  const Eigen::Vector3d n0(n[0], n[1], n[2]), n1(n[3], n[4], n[5]);
  const Eigen::Vector3d a = (state.x.col(1) - state.x.col(0)).cross(state.x.col(2) - state.x.col(0));
  const Eigen::Vector3d b = (state.x.col(3) - state.x.col(1)).cross(state.x.col(2) - state.x.col(1));
  EXPECT_NEAR((n0 - a.normalized()).norm(), 0.0, 1e-12);          // only in triangle a
  EXPECT_NEAR((n1 - (a + b).normalized()).norm(), 0.0, 1e-12);    // area-weighted sum
  EXPECT_GT(n1.dot(b.normalized()), n1.dot(a.normalized()));      // the larger face wins

  // A seam: render vertices 4 and 1 are the same mass, so they get the same position and normal.
  clothsim::testing::HandScene h(4, 1.0f, 1.0f);
  h.vertex_mass[5] = 1;  // pretend vertex 5 is a UV-seam copy of mass 1
  const clothsim::Model model = hand_model(h);
  clothsim::State s2 = clothsim::make_state(model);
  s2.x.col(1) += Eigen::Vector3d(0.1, 0.3, 0.0);
  std::vector<float> pos(h.positions), nrm(h.normals);
  std::vector<double> scratch;
  ASSERT_TRUE(cv::update_cloth_vertices(h.scene, model, s2, pos, nrm, scratch));
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(pos[3 * 5 + k], pos[3 * 1 + k]);
    EXPECT_EQ(nrm[3 * 5 + k], nrm[3 * 1 + k]);
  }
}

TEST(ClothMesh, NonFiniteStateIsNeverDrawn) {
  clothsim::testing::HandScene h(4);
  const clothsim::Model model = hand_model(h);
  clothsim::State state = clothsim::make_state(model);
  state.x(1, 3) = std::numeric_limits<double>::quiet_NaN();
  std::vector<float> pos(h.positions), nrm(h.normals);
  std::vector<double> scratch;
  EXPECT_FALSE(cv::update_cloth_vertices(h.scene, model, state, pos, nrm, scratch));
  EXPECT_EQ(pos, h.positions);
  for (float f : nrm) EXPECT_TRUE(std::isfinite(f));
}

TEST(ClothMesh, ModelSceneMismatchIsReported) {
  clothsim::testing::HandScene h(4);
  clothsim::Model model = hand_model(h);
  EXPECT_EQ(cv::check_model_matches_scene(h.scene, model), "");
  model.cloths[0].scene_cloth = 3;
  EXPECT_NE(cv::check_model_matches_scene(h.scene, model).find("scene has 1"), std::string::npos);
  model.cloths[0].scene_cloth = 0;
  model.cloths[0].mass_count = 5;
  EXPECT_NE(cv::check_model_matches_scene(h.scene, model), "");
}

TEST(Framing, CoversTheClothAndTheFloorBelowButNotTheWholeFloor) {
  clothsim::testing::HandScene h(6, 1.6f, 1.2f);  // cloth x, z in [-0.8, 0.8]; floor +-3 at y 0
  const clothsim::Model model = hand_model(h);
  Eigen::Vector3d lo, hi;
  cv::framing_box(h.scene, model, lo, hi);
  EXPECT_NEAR(lo.y(), 0.0, 1e-6);           // the floor's height is in
  EXPECT_NEAR(hi.y(), 1.2 + 0.15 * 0.8, 1e-5);
  EXPECT_NEAR(lo.x(), -0.88, 1e-6);         // the floor's width is clipped to 1.1x the cloth
  EXPECT_NEAR(hi.z(), 0.88, 1e-6);
}

TEST(Framing, APinnedClothGetsRoomToHangBelow) {
  clothsim::testing::HandScene h(6, 1.6f, 1.2f, /*pin_corner=*/true);
  const clothsim::Model model = hand_model(h);
  Eigen::Vector3d lo, hi;
  cv::framing_box(h.scene, model, lo, hi);
  EXPECT_NEAR(lo.y(), (1.2 - 0.15 * 0.8) - 1.6, 1e-5);  // its lowest rest point minus its width
}

TEST(Picking, RayFromAboveHitsTheMassUnderIt) {
  clothsim::testing::HandScene h(6, 1.0f, 1.0f);
  const clothsim::Model model = hand_model(h);
  const clothsim::State state = clothsim::make_state(model);
  for (std::uint32_t m : {0u, 7u, 14u, 35u}) {
    const Eigen::Vector3d p = state.x.col(m);
    // Slightly inside the cloth so edge masses are hit too.
    const Eigen::Vector3d aim = p + 0.05 * (Eigen::Vector3d(0, p.y(), 0) - Eigen::Vector3d(p.x(), p.y(), p.z()));
    const cv::Ray ray{aim + Eigen::Vector3d(0, 3, 0), Eigen::Vector3d(0, -1, 0)};
    const cv::Pick pick = cv::pick_mass(h.scene, model, state, ray, 0.05);
    EXPECT_EQ(pick.mass, static_cast<std::int32_t>(m));
    EXPECT_NEAR(pick.t, 3.0, 0.01);
  }
  const cv::Ray miss{Eigen::Vector3d(5, 3, 5), Eigen::Vector3d(0, -1, 0)};
  EXPECT_EQ(cv::pick_mass(h.scene, model, state, miss, 0.05).mass, -1);
  const cv::Ray away{Eigen::Vector3d(0, 3, 0), Eigen::Vector3d(0, 1, 0)};
  EXPECT_EQ(cv::pick_mass(h.scene, model, state, away, 0.05).mass, -1);  // behind the eye
}
