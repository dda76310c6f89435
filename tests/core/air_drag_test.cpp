// The air's drag on a falling sheet against its closed forms: a flat sheet falls at its
// terminal speed sqrt(2 density g / (air_density C_D)) (drag per kilogram off); a sheet
// without air, or one moving edge-on, falls freely (v = g t).
#include <clothsim/material.hpp>
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>

#include <gtest/gtest.h>

#include <cmath>

#include "inline_scenes.hpp"

namespace clothsim {
namespace {

// The cloth's mean velocity after `seconds` of fall from rest, with the planned substeps.
Eigen::Vector3d fall(const Options& o, double seconds) {
  const Model m = test::square_cloth(o, 11, false);
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  ws.substeps = plan_substeps(m.options.dt, analyse_stability(m).dt_stable, SubstepPolicy{}).substeps;
  const int steps = static_cast<int>(std::lround(seconds / m.options.dt));
  for (int k = 0; k < steps * ws.substeps; ++k) EXPECT_TRUE(step(m, s, ws).finite);
  return s.v.rowwise().mean();
}

Options still_air() {
  Options o;
  o.drag = 0.0;  // (the material's drag per kilogram off: the air's alone)
  return o;
}

TEST(AirDrag, AFlatSheetFallsAtItsTerminalSpeed) {
  const Options o = still_air();
  const double density = 0.15;  // cotton, kg/m^2
  const double terminal = std::sqrt(2.0 * density * 9.81 / (o.air_density * kPlateDrag));
  const Eigen::Vector3d v = fall(o, 4.0);
  EXPECT_NEAR(-v.y(), terminal, 0.01 * terminal);
  EXPECT_NEAR(v.x(), 0.0, 1e-9);
  EXPECT_NEAR(v.z(), 0.0, 1e-9);
}

TEST(AirDrag, WithoutAirASheetFallsFreely) {
  Options o = still_air();
  o.air_density = 0.0;
  EXPECT_NEAR(-fall(o, 1.0).y(), 9.81, 1e-9 * 9.81);
}

TEST(AirDrag, ASheetMovingEdgeOnFallsFreely) {
  Options o = still_air();
  o.gravity_x = -9.81, o.gravity_y = 0.0;  // along the sheet's plane
  EXPECT_NEAR(-fall(o, 1.0).x(), 9.81, 1e-9 * 9.81);
}

}  // namespace
}  // namespace clothsim
