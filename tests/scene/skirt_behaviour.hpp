// The skirt scenes' behaviour test, shared by skirt_test and skirt_hires_test.
#pragma once

#include "scene_run.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <vector>

namespace clothsim::test {

/// What one run of a skirt scene showed (printed by the tests, checked by check_skirt).
struct SkirtRun {
  double first_sphere_contact_s = -1, wrapped_s = -1, first_floor_contact_s = -1, last_on_top_s = -1;
  double max_strain = 0, max_waist_radius = 0, kinetic_energy = 0;
};

/// Runs a skirt scene (a Skirt over a Sphere above a Floor) for 20 s with its baked params and
/// the planned substeps, and checks what the seed describes: it lands on the sphere, wraps it,
/// slides off to one side and comes to rest on the floor in folds; never deeper than its
/// contact band inside the sphere or below the floor; never stretched past 60 %; with
/// self-collision on, no layer through another in any frame 0.05 s apart.
/// Positions are checked every `check_every` steps of dt. `self_collision` overrides the
/// scene's when not Auto.
inline void check_skirt(const b2o::Scene& scene, int check_every, SkirtRun* out = nullptr,
                        Switch self_collision = Switch::Auto) {
  Options options = scene_options(scene);
  if (self_collision != Switch::Auto) options.self_collision = self_collision;
  const Model m = build_model(scene, options);
  ASSERT_GT(m.mass_count(), 300u);
  ASSERT_TRUE(m.colliders);
  const Options& o = m.options;
  EXPECT_EQ(o.gravity_y, -9.81);  // real gravity
  const double band = m.contact.band;

  // the sphere: centre = mean of its vertices; floor: its height
  const b2o::Object& sphere = find_object(scene, "Sphere");
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double r_out = 0.0;
  for (std::uint32_t v = 0; v < sphere.vertex_count; ++v) c += vertex(scene, sphere.first_vertex + v);
  c /= sphere.vertex_count;
  for (std::uint32_t v = 0; v < sphere.vertex_count; ++v)
    r_out = std::max(r_out, (vertex(scene, sphere.first_vertex + v) - c).norm());
  const double r_in = inscribed_radius(scene, sphere, c);
  const b2o::Object& floor = find_object(scene, "Floor");
  const double floor_y = vertex(scene, floor.first_vertex).y();

  // the waist: the skirt's top ring (highest masses at rest)
  std::vector<Eigen::Index> waist;
  const double y0_top = m.x0.row(1).maxCoeff();
  for (Eigen::Index k = 0; k < m.x0.cols(); ++k)
    if (m.x0(1, k) > y0_top - 1e-6) waist.push_back(k);
  ASSERT_GE(waist.size(), 8u);

  State s = make_state(m);
  Workspace ws = planned_workspace(m);
  const double near_sphere = r_out + band + 0.02;
  std::int64_t first_sphere_contact = -1, first_floor_contact = -1, wrapped_step = -1, last_on_top = -1;
  double max_strain = 0.0, max_waist_radius = 0.0;
  const int steps = static_cast<int>(std::lround(20.0 / o.dt));
  for (int i = 1; i <= steps; ++i) {
    ASSERT_TRUE(step_dt(m, s, ws)) << "step " << i;
    if (crossing_frame(m, i)) {
      ASSERT_EQ(expect_no_crossings(m, s), 0u) << "step " << i;
    }
    if (i % check_every != 0 && i != steps) continue;
    int above = 0, below = 0;
    for (Eigen::Index k = 0; k < s.x.cols(); ++k) {
      const Eigen::Vector3d p = s.x.col(k);
      const double r = (p - c).norm();
      ASSERT_GE(r, r_in - band) << "mass " << k << " deep inside the sphere at step " << i;
      ASSERT_GE(p.y(), floor_y - band) << "mass " << k << " below the floor at step " << i;
      if (r < near_sphere) (p.y() > c.y() ? above : below)++;
      if (p.y() < floor_y + band && first_floor_contact < 0) first_floor_contact = i;
    }
    if (above + below > 0 && first_sphere_contact < 0) first_sphere_contact = i;
    if (above >= 20 && below >= 20 && wrapped_step < 0) wrapped_step = i;
    if (above > 0) last_on_top = i;
    for (std::size_t j = 0; j < m.spring_count(); ++j)
      if (m.spring_kind[j] == 0)
        max_strain = std::max(max_strain, (s.x.col(m.spring_a[j]) - s.x.col(m.spring_b[j])).norm() /
                                                  m.rest_length0[static_cast<Eigen::Index>(j)]);
    Eigen::Vector3d wc = Eigen::Vector3d::Zero();
    for (Eigen::Index k : waist) wc += s.x.col(k);
    wc /= static_cast<double>(waist.size());
    for (Eigen::Index k : waist) {
      const Eigen::Vector3d d = s.x.col(k) - wc;
      max_waist_radius = std::max(max_waist_radius, std::hypot(d.x(), d.z()));
    }
  }
  ASSERT_GT(first_sphere_contact, 0) << "never touched the sphere";
  ASSERT_GT(first_floor_contact, 0) << "never reached the floor";
  EXPECT_LT(first_sphere_contact, first_floor_contact) << "reached the floor before the sphere";
  EXPECT_GT(wrapped_step, 0) << "never wrapped the sphere (cloth on both its upper and lower half)";
  EXPECT_LE(s.max_penetration, band);
  // stretched (rubber), but not torn apart (the seed's 0.1 kg per mass stretches springs 4.4x)
  EXPECT_LT(max_strain, 1.6) << "structural springs stretched past 60 %";
  // the waist does not widen past the sphere and drop over it
  EXPECT_LT(max_waist_radius, r_in) << "the waist widened past the sphere";
  // it stays on the sphere a while instead of dropping over it
  EXPECT_GT((last_on_top - wrapped_step) * o.dt, 1.0) << "wrapped only briefly";
  EXPECT_LT(last_on_top * o.dt, 15.0) << "still on top of the sphere at 15 s";

  // at rest on the floor, in folds, off the sphere to one side
  const double ke = kinetic_energy(m, s);
  EXPECT_LT(ke, 1e-3) << "still moving (or jittering) after 20 s";
  const double y_lo = s.x.row(1).minCoeff(), y_hi = s.x.row(1).maxCoeff();
  EXPECT_GE(y_lo, floor_y);
  EXPECT_LT(y_lo, floor_y + band);
  EXPECT_LT(y_hi, c.y()) << "part of the skirt is still up on the sphere";
  EXPECT_GT(y_hi - y_lo, 0.02) << "no folds: the skirt lies perfectly flat";
  int low = 0, touching = 0;
  for (Eigen::Index k = 0; k < s.x.cols(); ++k) {
    low += s.x(1, k) < floor_y + 0.3;
    touching += (s.x.col(k) - c).norm() < near_sphere;
  }
  EXPECT_GT(low, 3 * s.x.cols() / 4) << "most of the skirt is not on the floor";
  const Eigen::Vector3d mean = s.x.rowwise().mean();
  const double off = std::hypot(mean.x() - c.x(), mean.z() - c.z());
  EXPECT_GT(off, 0.5 * r_in) << "the skirt did not slide off to one side";
  if (out) *out = {first_sphere_contact * o.dt, wrapped_step * o.dt, first_floor_contact * o.dt,
                   last_on_top * o.dt, max_strain, max_waist_radius, ke};
  std::cout << scene.name << " after 20 s: y " << y_lo << " .. " << y_hi << ", kinetic energy " << ke
            << " J, first sphere contact step " << first_sphere_contact << ", wrapped at step " << wrapped_step
            << ", floor contact step " << first_floor_contact << ", last on the upper half step " << last_on_top
            << ", max structural strain " << max_strain << ", max waist radius " << max_waist_radius
            << " (sphere " << r_in << "), on the floor " << low << "/" << s.x.cols() << ", touching the sphere "
            << touching << ", centre off the axis " << off << " m\n";
}

}  // namespace clothsim::test
