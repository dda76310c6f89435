// Runs a baked scene headless for the scene tests.
#pragma once

#include <clothsim/scene.hpp>
#include <clothsim/self_crossings.hpp>
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>

#include <blender2ogl/scene_types.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace clothsim::test {

/// The scene's object named `name` as (3 x V) vertices, or throws.
inline const b2o::Object& find_object(const b2o::Scene& s, const char* name) {
  for (std::uint32_t o = 0; o < s.object_count; ++o)
    if (std::strcmp(s.objects[o].name, name) == 0) return s.objects[o];
  throw std::runtime_error(std::string("scene has no object ") + name);
}

/// A Workspace with the substeps clothsim plans for the model (the stability guard's).
inline Workspace planned_workspace(const Model& m) {
  Workspace ws = make_workspace(m);
  ws.substeps = plan_substeps(m.options.dt, analyse_stability(m).dt_stable, SubstepPolicy{}).substeps;
  return ws;
}

/// One step of dt: the Workspace's substeps; false when a state was not finite.
inline bool step_dt(const Model& m, State& s, Workspace& ws) {
  for (int q = 0; q < ws.substeps; ++q)
    if (!step(m, s, ws).finite) return false;
  return true;
}

/// Whether step `step` of dt ends a frame of the crossing checks (every 0.05 s).
inline bool crossing_frame(const Model& m, long step) {
  return step % std::max(1L, std::lround(0.05 / m.options.dt)) == 0;
}

/// With self-collision on (every material's default): no edge of the cloths passes through
/// one of their triangles at this frame. Returns the count.
inline std::size_t expect_no_crossings(const Model& m, const State& s) {
  if (m.options.self_collision != Switch::On) return 0;
  const std::size_t n = count_self_crossings(m, s.x).crossings;
  EXPECT_EQ(n, 0u) << m.scene_name << ": " << n << " self-crossings at t = " << s.t << " s";
  return n;
}

/// Runs the model from rest for `seconds` with the planned substeps, checking every step of dt
/// that the state is finite and every 0.05 s that it has no self-crossing (a failure stops the
/// run); the state at the end.
inline State run_for(const Model& m, double seconds) {
  State s = make_state(m);
  Workspace ws = planned_workspace(m);
  const long steps = std::lround(seconds / m.options.dt);
  for (long i = 1; i <= steps; ++i)
    if (!step_dt(m, s, ws)) {
      ADD_FAILURE() << m.scene_name << ": not finite at step " << i;
      break;
    } else if (crossing_frame(m, i) && expect_no_crossings(m, s) > 0) {
      break;
    }
  return s;
}

inline Eigen::Vector3d vertex(const b2o::Scene& s, std::uint32_t v) {
  return {s.positions[3 * v], s.positions[3 * v + 1], s.positions[3 * v + 2]};
}

/// Smallest distance from `c` to the planes of the object's triangles (a closed convex
/// collider's inscribed radius about c).
inline double inscribed_radius(const b2o::Scene& s, const b2o::Object& o, const Eigen::Vector3d& c) {
  double r = 1e300;
  for (std::uint32_t i = 0; i < o.index_count; i += 3) {
    const Eigen::Vector3d a = vertex(s, s.indices[o.first_index + i]), b = vertex(s, s.indices[o.first_index + i + 1]),
                          d = vertex(s, s.indices[o.first_index + i + 2]);
    const Eigen::Vector3d n = (b - a).cross(d - a).normalized();
    r = std::min(r, std::abs(n.dot(c - a)));
  }
  return r;
}

}  // namespace clothsim::test
