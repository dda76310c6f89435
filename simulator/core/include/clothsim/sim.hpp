// clothsim core: the contract shared by the physics, the headless runner and the viewer.
//
// Three kinds of thing, kept apart (after MuJoCo's mjModel / mjData):
//   Options   - numbers a user sets (defaults from the 2016 report);
//   Model     - built once from a scene + Options, never changed by step();
//   State     - positions, velocities, time: the only thing step() changes.
// A Workspace holds step()'s scratch memory so that step() never allocates.
//
// This header depends on Eigen only: no GL, no file formats.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace clothsim {

/// Time integrators. The seed's method is the default.
enum class Integrator : std::uint8_t {
  SymplecticEuler,  ///< report eqs. 1-7: x += h v(t); f at x(t+h); v += h (f - gamma v)/m
  // Added for the work-precision study (issue 5); see integrators.hpp.
  ExplicitEuler,    ///< forward Euler: order 1, energy grows
  Verlet,           ///< leapfrog (drift-kick-drift): order 2, symplectic
  Midpoint,         ///< explicit midpoint (RK2): order 2
  RK4,              ///< classic Runge-Kutta: order 4
  ImplicitEuler,    ///< Baraff & Witkin 1998: one Newton step, CG
  FastMassSpring,   ///< Liu et al. 2013: local/global with a prefactored Cholesky
  XPBD,             ///< Macklin et al. 2016/2019: compliant springs, one iteration per (small) step
};

struct Options {
  double dt = 0.01;           ///< s, step size (report: 0.01)
  double mass = 0.1;          ///< kg per mass point (report: 0.1)
  double k_struct = 400.0;    ///< N/m, structural springs (report: 400)
  double k_bend = 50.0;       ///< N/m, bend springs (report: 1:8 of structural)
  double damping = 0.1;       ///< N s/m, gamma of report eq. 6
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  ///< m/s^2, Blender's OBJ export is Y up
  double epsilon = 0.1;       ///< m, collision band of report eq. 12
  double k_rep = 600.0;       ///< N/m, penalty constant: stops 7.7 m/s, stable with the springs at dt 0.01 (docs/physics.md)
  Integrator integrator = Integrator::SymplecticEuler;
};

/// A contiguous run of masses and springs that came from one cloth object of the scene.
struct ClothRange {
  std::uint32_t first_mass = 0, mass_count = 0;
  std::uint32_t first_spring = 0, spring_count = 0;
  std::int32_t scene_cloth = -1;  ///< index into b2o::Scene::cloths, -1 for scenes built in code
};

/// A user's pull on one mass (the report's f_interact): a spring of stiffness k from the
/// mass to `target`. The viewer sets it from the mouse; step() applies it.
struct Drag {
  std::int32_t mass = -1;  ///< -1: no drag
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double k = 0.0;
  /// m: the pull is k times the distance to the target, but at most this far: a target far
  /// away (a fast mouse) pulls like one at this distance, instead of flinging one mass through
  /// the cloth.
  double reach = std::numeric_limits<double>::infinity();
};

/// Static collider triangles (world space) and their broadphase; see collision/.
/// Declared here only by name; the collision module owns the definition.
struct ColliderSet;

/// Built once; step() reads it and never changes it. One Model can drive many States.
/// Per-mass arrays have n = mass_count() entries, per-spring arrays s = spring_count().
struct Model {
  Options options;                       ///< the options it was built with (k_struct, k_bend: see spring_stiffness)
  std::string scene_name;

  Eigen::Matrix3Xd x0;                   ///< (3 x n) initial positions
  Eigen::VectorXd mass;                  ///< (n) kg
  Eigen::VectorXd inv_mass;              ///< (n) 1/kg, 0 for pinned masses
  std::vector<std::uint8_t> pinned;      ///< (n) 1 if the mass never moves

  std::vector<std::uint32_t> spring_a, spring_b;  ///< (s) global mass indices
  Eigen::VectorXd rest_length0;          ///< (s) m
  std::vector<std::uint8_t> spring_kind; ///< (s) 0 structural (k_struct), 1 bend (k_bend): b2o::SpringKind

  std::vector<ClothRange> cloths;        ///< masses/springs grouped by cloth object

  /// Collider triangles with their broadphase, built once (may be empty).
  std::shared_ptr<const ColliderSet> colliders;

  std::size_t mass_count() const { return static_cast<std::size_t>(x0.cols()); }
  std::size_t spring_count() const { return spring_a.size(); }

  /// N/m. Not stored per spring: the kind says which of the two options applies.
  double spring_stiffness(std::size_t s) const { return spring_kind[s] == 0 ? options.k_struct : options.k_bend; }
};

/// The only thing that changes.
struct State {
  Eigen::Matrix3Xd x;                    ///< (3 x n) positions, m
  Eigen::Matrix3Xd v;                    ///< (3 x n) velocities, m/s
  double t = 0.0;                        ///< s, simulated time
  std::uint64_t steps = 0;               ///< steps taken
  Drag drag;                             ///< the user's pull, if any
  double max_penetration = 0.0;          ///< m, deepest any point was behind a collider so far
};

/// Scratch memory for step(); sized once from a Model (defined in step.hpp).
struct Workspace;

/// What one step() reports.
struct StepStatus {
  bool finite = true;  ///< false: a position or velocity became NaN/inf; the State is invalid
};

// --- the functions the runner and the viewer call (defined in the core library) ----------

/// The state at t = 0: x = x0, v = 0.
State make_state(const Model& model);

/// Advances `state` by model.options.dt with model.options.integrator. Never allocates.
StepStatus step(const Model& model, State& state, Workspace& ws);

}  // namespace clothsim
