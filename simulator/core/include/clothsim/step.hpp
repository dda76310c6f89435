// The force stage and the step's scratch memory, shared by every integrator.
#pragma once

#include <clothsim/sim.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace clothsim {

namespace detail {
struct CollisionScratch;
struct SelfScratch;
struct SpringSplit;
}  // namespace detail
struct IntegratorScratch;

/// Per-mass spring lists (CSR) for the gathered spring forces: the springs of mass i are
/// entry[start[i] .. start[i+1]), in increasing spring index, so every mass sums its springs
/// in the scatter loop's order whatever the thread count. An entry is the spring index, with
/// the top bit set when i is the spring's b end (the force is subtracted). Built once. (With
/// ModelBuilder's spring order every list is a run of a ends, then a run of b ends.)
struct SpringAdjacency {
  static constexpr std::uint32_t kB = 0x80000000u;  ///< entry flag: i is the b end
  std::vector<std::uint32_t> start;   ///< (n + 1)
  std::vector<std::uint32_t> entry;   ///< (2 s)
  /// One thread works in blocks of kBlock masses: block_springs[block_start[b] ..
  /// block_start[b+1]) are the springs whose lower mass is in block b (computed just before
  /// the block's masses gather them), in increasing order; where they are consecutive indices
  /// (ModelBuilder's order) the passes take them as a range, without the list.
  static constexpr std::size_t kBlock = 1024;
  std::vector<std::uint32_t> block_start;    ///< (blocks + 1)
  std::vector<std::uint32_t> block_springs;  ///< (s)
  /// When every mass's springs as the a end are consecutive indices at the head of its list
  /// (ModelBuilder's order), run[i] says how many: the AVX2 gather then reads them as a
  /// range, without their entries. Empty otherwise, and from 2^27 springs on.
  std::vector<std::uint32_t> run;
  /// Throws std::length_error for more than 2^31 - 1 springs.
  static SpringAdjacency build(const Model& model);
  std::size_t bytes() const {
    return (start.size() + entry.size() + block_start.size() + block_springs.size() + run.size()) *
           sizeof(std::uint32_t);
  }
};

/// Scratch memory for step(), sized once from a Model so that step() never allocates, and
/// what a run decides for itself (the Model holds what the user asked for).
struct Workspace {
  int substeps = 1;                          ///< steps per dt: step() takes h = model.options.dt / substeps
  int threads = 1;                           ///< threads of the force and update loops (same bits for any count)
  Eigen::Matrix3Xd f;                        ///< (3 x n) total force at the current stage, N
  Eigen::Matrix3Xd pinned_x;                 ///< (3 x p) positions of the pinned masses, saved per step (turning pins: at the step's end)
  std::vector<std::uint32_t> pinned_index;   ///< (p) the pinned masses
  std::vector<std::int32_t> contact_hint;    ///< (n x colliders) closest-triangle hints, -1 = none (unused
                                             ///< when `collision` is set)
  /// The collision query's memory between steps (ContactCache certificates, per thread chunk),
  /// made by make_workspace when the model has colliders. Copies of the Workspace share it
  /// (results stay exact); do not step two copies at the same time.
  std::shared_ptr<detail::CollisionScratch> collision;
  /// The self-contact stage's memory between steps (its pairs, bounds and trees), made by
  /// make_workspace when the model has self-collision on; shared by copies like `collision`.
  std::shared_ptr<detail::SelfScratch> self;
  /// (3 x n) the contact forces of the last force stage, apart, for the friction of the
  /// force-based integrators (empty without friction or colliders, or for XPBD).
  Eigen::Matrix3Xd contact_f;
  std::vector<std::uint32_t> stretched;      ///< the springs past the strain limit (limit_strain's list)
  std::vector<std::uint8_t> moved;           ///< (n) limit_strain's marks: masses its last pass moved
  std::vector<std::uint32_t> moved_list;     ///< those masses
  std::vector<std::uint8_t> listed;          ///< (s) limit_strain's marks: springs in its next pass
  /// The masses the colliders held in the last step (n; with a strain limit and colliders), and
  /// limit_strain's attachments to them: each mass's nearest held mass along the cloth's
  /// structural springs (kNoMass: none) and that path's rest length, m; `frontier` its heap;
  /// `anchored` the held masses the attachments were found for (they change only with them).
  std::vector<std::uint8_t> held, anchored;
  std::vector<std::uint32_t> anchor;
  std::vector<double> reach;
  std::vector<std::pair<double, std::uint32_t>> frontier;
  /// The air drag's memory (empty without it, Model::air = 0): each face's change of normal
  /// velocity over the step, and each mass's faces (CSR: face_list[face_start[i] ..
  /// face_start[i+1])), so that every mass sums its faces in one order for any thread count.
  Eigen::Matrix3Xd face_dv;
  std::vector<std::uint32_t> face_start, face_list;
  Drag drag;                                 ///< the drag of the state being stepped
  double last_penetration = 0.0;             ///< m, deepest point behind a collider in the last force stage
  std::uint32_t last_contacts = 0;           ///< points inside a collider band in the last force stage
  /// The gathered spring forces; shared by copies of the Workspace.
  /// Without it (a Workspace not made by make_workspace) the forces use the scatter loop.
  std::shared_ptr<const SpringAdjacency> adjacency;
  /// More threads: which springs and masses each thread takes (made once per thread count, so
  /// that each thread works block by block as one thread does). Shared by copies.
  std::shared_ptr<detail::SpringSplit> spring_split;
  /// (4 s + 4) each spring's force on its a end, c dx with c = k (l - |dx|) / |dx| (0 if |dx| = 0),
  /// as x, y, z, 0 in 32-byte blocks from the first 32-byte aligned element.
  std::vector<double> spring_f;
  /// Scratch of the other integrators (integrators.hpp); shared by copies of the Workspace.
  std::shared_ptr<IntegratorScratch> integrator_scratch;
};

Workspace make_workspace(const Model& model);

/// What the self-contact stage has done in a Workspace and its copies: its detections and the
/// builds of its candidate lists (docs/collision.md, "Self-contact"); nullopt with it off.
struct SelfContactCounts {
  std::uint64_t detections = 0, list_builds = 0;
  /// Pairs a detection found nearer than their moving pin's move over one step: the guarantee
  /// assumes none (docs/collision.md, "Self-contact", the guarantee); and the time of the first (-1: none).
  std::uint64_t pin_overruns = 0;
  double first_pin_overrun_t = -1.0;
  /// Steps run in parts (up to 8), each with its own detection, so that no turning pin moved
  /// past a pair's gap; pins that would need more parts are counted in pin_overruns instead.
  std::uint64_t split_steps = 0;
};
std::optional<SelfContactCounts> self_contact_counts(const Workspace& ws);

/// Total force on every mass at positions x and velocities v (report eqs. 2-5 plus the
/// damping term of eq. 6, so that a = f / m):
///   f = m g - gamma v + springs (eq. 4) + penalty (eq. 12, every collider) + drag.
/// Writes f (3 x n, already sized); records the deepest penetration in ws. Never allocates.
/// The user's drag is read from ws.drag (step() copies State::drag there). Every integrator
/// calls it; it calls the contact stage (add_contact_forces).
void compute_forces(const Model& model, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                    Eigen::Matrix3Xd& f, Workspace& ws);

/// The penalty forces of every collider on the masses at x (report eq. 12), added to f, on
/// ws.threads threads for large models; records the deepest penetration and the contacts in ws.
void add_contact_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f, Workspace& ws);

/// Coulomb friction of the force-based integrators, after their update: for each mass in
/// contact, with the normal impulse h |f_c| / m of the step's contact force f_c (ws.contact_f),
/// the tangential velocity v_t stops when |v_t| <= static_friction * that impulse, else loses
/// friction * that impulse (Bridson, Fedkiw, Anderson 2002). Never adds energy.
void apply_friction(const Model& model, State& state, const Workspace& ws, double h);

/// Pinned masses around an integrator's update: save_pins() keeps their positions in ws,
/// restore_pins() puts the exact bits back and zeroes their velocities.
void save_pins(const State& s, Workspace& ws);
void restore_pins(State& s, const Workspace& ws);

/// Adds the spring forces of report eq. 4 to f: the plain scatter loop over springs (the
/// reference the gathered version is tested and benchmarked against).
void add_spring_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f);

/// The same sums through ws.adjacency (a per-mass gather, threaded, bit-identical to the
/// scatter loop for every thread count); falls back to the scatter without an adjacency.
void add_spring_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f,
                       Workspace& ws);

/// The thread count for "N threads" as a user gives it: n itself, or all the cores for n <= 0.
int resolve_threads(int n);
/// Whether step() splits any of its loops between threads for this model; when it does not
/// (a small model), it runs on one thread whatever ws.threads says.
bool step_splits(const Model& model);
/// The cores this process may run on (OpenMP's count, capped by OMP_NUM_THREADS when that is
/// lower; 1 without OpenMP): the most --threads auto uses.
int core_count();

/// 1/2 sum m |v|^2 over the free masses, J.
double kinetic_energy(const Model& model, const State& state);

/// The largest strain of a structural spring at positions x, |x_a - x_b| / rest - 1 (0 for a
/// model without structural springs): how far the cloth is stretched.
double max_strain(const Model& model, const Eigen::Matrix3Xd& x);

/// Gershgorin bound on the highest angular frequency of the linearised system, rad/s:
/// omega_max^2 <= 2 max_i (sum_j k_ij + k_contact) / m_i, with k_contact = k_rep when the
/// model has colliders. Symplectic Euler is stable for dt < 2 / omega_max.
double gershgorin_omega_max(const Model& model);

/// A 64-bit FNV-1a hash of the bytes of x and v (for determinism tests).
std::uint64_t state_hash(const State& state);

}  // namespace clothsim
