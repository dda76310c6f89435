// clothsim core: the contract shared by the physics, the headless runner and the viewer.
//
// Three kinds of thing, kept apart (after MuJoCo's mjModel / mjData):
//   Options   - numbers a user sets (the table in options.hpp; defaults from the 2016 report);
//   Model     - built once from a scene + Options, never changed by step();
//   State     - positions, velocities, time: the only thing step() changes.
// A Workspace holds step()'s scratch memory so that step() never allocates.
//
// This header depends on Eigen only: no GL, no file formats.
#pragma once

#include <clothsim/options.hpp>

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace clothsim {

/// Gravity as a vector, m/s^2.
inline Eigen::Vector3d gravity(const Options& o) { return {o.gravity_x, o.gravity_y, o.gravity_z}; }

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

/// How the cloth meets the colliders, derived when the Model is built (docs/physics.md,
/// "Contact"): from epsilon and k_rep for the seed model, from the material and the mesh
/// otherwise.
struct ContactParams {
  double distance = 0.0;  ///< m, the distance kept from a collider: the penalty band epsilon of
                          ///< report eq. 12, and where the position-based contact puts a point
  double band = 0.0;      ///< m, how far the position-based contact looks (>= distance)
  double k_rep = 0.0;     ///< N/m, the penalty stiffness of the force-based integrators
  double friction = 0.0, static_friction = 0.0;  ///< Coulomb coefficients, kinetic and static
};

/// Built once; step() reads it and never changes it. One Model can drive many States.
/// Per-mass arrays have n = mass_count() entries, per-spring arrays s = spring_count().
struct Model {
  Options options;                       ///< as built: "auto" decided, the material's values filled in
  std::string scene_name;

  Eigen::Matrix3Xd x0;                   ///< (3 x n) initial positions
  Eigen::VectorXd mass;                  ///< (n) kg: per point (seed), or a third of the adjacent triangles' area
                                         ///< times the density
  Eigen::VectorXd inv_mass;              ///< (n) 1/kg, 0 for pinned masses
  std::vector<std::uint8_t> pinned;      ///< (n) 1 if the mass never moves

  std::vector<std::uint32_t> spring_a, spring_b;  ///< (s) global mass indices
  Eigen::VectorXf rest_length0;          ///< (s) m, in float: 4 B a spring (7 digits)
  std::vector<std::uint8_t> spring_kind; ///< (s) 0 structural, 1 bend: b2o::SpringKind
  std::vector<std::uint32_t> triangles;  ///< (3 t) the cloths' faces, global mass indices
  /// (s) a spring's share of its kind's modulus: k = spring_modulus[kind] * scale. The seed
  /// model: 1 (k_struct, k_bend); a material: from the edge's rest length and adjacent areas.
  std::vector<float> spring_scale;
  double spring_modulus[2] = {0.0, 0.0}; ///< N/m: k_struct, k_bend; or the material's stretch (N/m) and bend (N m)

  /// Velocity damping of mass i: damping + drag * mass[i] (N s/m). The seed model's gamma is
  /// the same for every point; a material's drag is per kilogram.
  double damping = 0.0;                  ///< N s/m
  double drag = 0.0;                     ///< 1/s
  /// 1/m, the air's drag on a face per its normal speed: a face's normal velocity u decays as
  /// du/dt = -air |u| u (air_density C_D / (2 density); 0: none, as in the seed model).
  double air = 0.0;
  /// The strain no structural spring goes past after a step (0: none): the cloth's yarns are
  /// straight there (a material's strain_limit; the seed model has none).
  double strain_limit = 0.0;
  /// Long-range attachments (Kim, Chentanez, Mueller 2012) of a pinned cloth with a strain
  /// limit: each free mass's nearest pins along the cloth (up to kAttachments) and its distance
  /// to them there at rest; after a step no mass is farther from such a pin than
  /// (1 + strain_limit) times that, so a cloth hanging from its pins does not stretch however
  /// fine its mesh. Empty without pins or a strain limit.
  static constexpr std::size_t kAttachments = 2;
  std::vector<std::uint32_t> attach_pin;  ///< (n x kAttachments) the pin's mass, or kNoPin
  std::vector<float> attach_rest;         ///< (n x kAttachments) m, the distance along the cloth
  static constexpr std::uint32_t kNoPin = 0xffffffffu;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< m/s^2
  /// Pins that turn (options.pin_spin != 0; empty otherwise): for each pinned mass, in mass
  /// order, a point on its group's axis (its cloth's centre, the mean of the cloth's rest
  /// positions) and the unit axis from there through its group's centre (a group is a connected
  /// set of pinned masses along the structural springs). step() turns the mass's rest position
  /// about that axis by pin_spin t, right-handed; a group centred on its cloth's centre has no
  /// axis (zero here) and stays put.
  Eigen::Matrix3Xd pin_origin, pin_axis;

  ContactParams contact;
  std::vector<ClothRange> cloths;        ///< masses/springs grouped by cloth object

  /// Collider triangles with their broadphase, built once (may be empty).
  std::shared_ptr<const ColliderSet> colliders;

  std::size_t mass_count() const { return static_cast<std::size_t>(x0.cols()); }
  std::size_t spring_count() const { return spring_a.size(); }

  /// N/m.
  double spring_stiffness(std::size_t s) const {
    return spring_modulus[spring_kind[s] != 0] * static_cast<double>(spring_scale[s]);
  }
  /// N s/m, mass i's velocity damping.
  double damping_of(std::size_t i) const { return damping + drag * mass[static_cast<Eigen::Index>(i)]; }
  /// The bytes of the per-mass, per-spring and per-face arrays (not the colliders').
  std::size_t bytes() const {
    const auto doubles = static_cast<std::size_t>(x0.size() + mass.size() + inv_mass.size() + pin_origin.size() +
                                                  pin_axis.size());
    return sizeof(double) * doubles + pinned.size() + spring_kind.size() +
           sizeof(std::uint32_t) * (spring_a.size() + spring_b.size() + triangles.size() + attach_pin.size()) +
           sizeof(float) * (static_cast<std::size_t>(rest_length0.size()) + spring_scale.size() + attach_rest.size());
  }
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

/// N/m, the stiffness of a user's pull on mass i (Drag::k): one structural spring's modulus,
/// at most a quarter of m_i / h^2, so that the explicit pull stays stable at the step h.
inline double pull_stiffness(const Model& m, std::size_t i, double h) {
  return std::min(m.spring_modulus[0], 0.25 * m.mass[static_cast<Eigen::Index>(i)] / (h * h));
}

/// Advances `state` by one step of h = model.options.dt / ws.substeps with
/// model.options.integrator, on ws.threads threads. Never allocates.
StepStatus step(const Model& model, State& state, Workspace& ws);

}  // namespace clothsim
