// The stability guard: how large a step each integrator can take on a Model, how
// many substeps a requested dt needs, and how fast a cloth can hit a collider before the
// penalty contact lets it through. See docs/stability.md.
//
// Linearised about a configuration x, the undamped system is M a = -K x with K the spring
// stiffness matrix (clamped PSD). Its highest angular frequency omega_max (the largest
// eigenvalue of M^-1/2 K M^-1/2, square-rooted) sets the explicit methods' limits:
//   symplectic Euler, Verlet  h < 2 / omega_max
//   RK4                       h < 2 sqrt(2) / omega_max
//   explicit Euler, midpoint  only with damping (their stability regions miss the imaginary axis)
//   implicit Euler, Liu       no limit
// The contact adds k_rep / m on the diagonal (a penalty spring to the surface).
#pragma once

#include <clothsim/sim.hpp>

#include <limits>
#include <string>
#include <string_view>

namespace clothsim {

/// Safe upper bound on omega_max (Gershgorin's circles of M^-1 K), rad/s:
/// omega^2 <= max_i (2 sum_j k_ij + k_c) / m_i over free masses; k_c = k_rep if requested; of
/// the bend springs alone if `bend_only`.
double omega_max_bound(const Model& model, bool include_contact, bool bend_only = false);

/// What the Lanczos iteration found.
struct OmegaEstimate {
  double omega = 0.0;       ///< rad/s, sqrt of the largest Ritz value (a lower bound that converges)
  int iterations = 0;
  double residual = 0.0;    ///< |A y - lambda y| / lambda for the top Ritz vector y, at the end
  bool converged = false;   ///< stopped on the tolerance (or a stalled Ritz value), not the cap
};

/// omega_max of the springs by Lanczos iteration on M^-1/2 K M^-1/2 (free masses only),
/// K taken at positions x (the Model's rest positions when x is null). Deterministic.
OmegaEstimate omega_max_lanczos(const Model& model, const Eigen::Matrix3Xd* x = nullptr,
                               int max_iterations = 2000, double tolerance = 1e-7);

/// omega of the stiffest contact: sqrt(k_rep / m_min) over free masses (0 without colliders).
double omega_contact(const Model& model);

/// Largest h with the method linearly stable on x'' = -omega^2 x - 2 zeta x' (spectral radius
/// of its one-step map <= 1), found by bisection on the method's actual update formulas.
/// +infinity for the unconditionally stable methods; 0 when no h > 0 is stable.
double stable_dt(Integrator method, double omega, double zeta = 0.0);

/// s, XPBD's step: its structural springs are stable at any step, but its one pass carries a
/// pull about one edge a step, so the strain it leaves grows with the step over the edge: at
/// most kXpbdStep and the mean edge over kXpbdSpeed (a 1 m cloth hanging from two corners then
/// sags alike at 20 x 20 and 80 x 80 quads: tests/core/refinement_test.cpp); at most the
/// contact band over the fastest fall (a falling point moves less than the band per step); and
/// under the explicit limit 2 / omega of its bend springs.
inline constexpr double kXpbdStep = 1e-3;
inline constexpr double kXpbdSpeed = 50.0;  ///< m/s
double xpbd_step(const Model& model);

/// Everything the guard knows about a Model, printed at start and put in the JSON report.
struct StabilityReport {
  double omega_springs = 0.0;   ///< rad/s, Lanczos (a lower bound that converges); Gershgorin
                                ///< (safe) when Lanczos did not converge in its iterations
  int lanczos_iterations = 0;   ///< what Lanczos took
  bool springs_by_bound = false;  ///< Lanczos did not converge: omega_springs is Gershgorin's
  double omega_bound = 0.0;     ///< rad/s, Gershgorin with contact (safe)
  double omega_contact = 0.0;   ///< rad/s
  double omega_max = 0.0;       ///< rad/s, used for the limits: sqrt(springs^2 + contact^2) (Weyl)
  double zeta = 0.0;            ///< 1/s, damping rate gamma / (2 m_max) (the weakest)
  double dt_stable = 0.0;       ///< s, the limit for model.options.integrator
  /// dt_stable is the contact's limit 1 / (0.9 omega_contact): the penalty is explicit in every
  /// integrator and gains energy per bounce as h omega_contact nears 2
  bool contact_limited = false;
  double dt_stable_symplectic = 0.0;  ///< s, 2 / omega_max (the seed's method)
};
/// `lanczos_iterations`: the cap of omega_max_lanczos(); without convergence within it the
/// springs' omega is Gershgorin's safe bound (a Ritz value short of convergence can be low).
StabilityReport analyse_stability(const Model& model, int lanczos_iterations = 2000);

/// When report.dt_stable is 0 (no step size is stable): why, one line naming `method`: the
/// model has no damping (explicit Euler and midpoint need some), too little, or omega_max or
/// the damping rate overflowed (masses far too light).
std::string never_stable_reason(const StabilityReport& report, Integrator method);

/// One line for the terminal, e.g. "stability: omega_max 196 rad/s (...) -> dt_stable 0.0102 s".
std::string describe(const StabilityReport& report, Integrator method);

/// --substeps: auto (default), off, or a fixed count.
struct SubstepPolicy {
  enum class Mode { Auto, Off, Fixed } mode = Mode::Auto;
  int count = 1;          ///< for Fixed
  double margin = 0.9;    ///< Auto stays at or below margin * dt_stable
  int max_substeps = 100000;
};
/// Parses "auto", "off" or a positive integer; throws std::invalid_argument with a one-line
/// message naming --substeps otherwise.
SubstepPolicy parse_substeps(std::string_view text);

struct SubstepPlan {
  bool ok = true;          ///< false: refused (off, or auto beyond max_substeps); `message` says why
                           ///< and gives the limit. A fixed count above the limit is ok + a warning.
  int substeps = 1;        ///< steps of h = dt / substeps per requested dt
  double h = 0.0;          ///< s
  std::string message;     ///< empty, a note (auto substepping) or the refusal
};
/// Plans the substeps for a requested dt against the limit dt_stable.
SubstepPlan plan_substeps(double dt, double dt_stable, const SubstepPolicy& policy);

/// Tunnelling (penalty contact within a band eps): an impact at speed v is stopped only if
/// its kinetic energy fits in the band's spring, v < eps sqrt(k_rep / m), and it is seen at
/// all only if one step does not jump the band, v h < eps.
struct TunnellingReport {
  double drop_height = 0.0;   ///< m, highest cloth mass above the lowest collider point (along -g)
  double fall_speed = 0.0;    ///< m/s, sqrt(2 |g| drop_height)
  double stop_speed = 0.0;    ///< m/s, eps sqrt(k_rep / m_max)
  double see_speed = 0.0;     ///< m/s, eps / h
  double max_speed = 0.0;     ///< m/s, min(stop_speed, see_speed)
  bool warn = false;          ///< fall_speed >= max_speed
  std::string message;        ///< the warning, or empty
};
double max_stoppable_speed(double epsilon, double k_rep, double mass, double h);
/// m, the greatest height of a free cloth point above the lowest collider point along gravity
/// (`lowest_collider`; NaN: the lowest corner of the colliders' box), 0 without colliders or
/// gravity: a fall from there reaches sqrt(2 |g| H).
double drop_height(const Model& model, double lowest_collider = std::numeric_limits<double>::quiet_NaN());
/// lowest_collider: the lowest collider height along -g (m); NaN: the Model's colliders' box
/// is used (no colliders: nothing can tunnel, warn = false).
TunnellingReport check_tunnelling(const Model& model, double h,
                                  double lowest_collider = std::numeric_limits<double>::quiet_NaN());

}  // namespace clothsim
