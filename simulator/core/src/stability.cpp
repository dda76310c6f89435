// The stability guard; see stability.hpp and docs/stability.md.
#include <clothsim/integrators.hpp>
#include <clothsim/material.hpp>
#include <clothsim/stability.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <complex>
#include <limits>
#include <cstdio>
#include <stdexcept>
#include <vector>

#ifdef CLOTHSIM_HAVE_COLLISION
#include <clothsim/collision.hpp>
#endif

namespace clothsim {

namespace {

double min_free_mass(const Model& m) {
  double r = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (!m.pinned[i]) r = std::min(r, m.mass[static_cast<Eigen::Index>(i)]);
  return r;
}
double max_free_mass(const Model& m) {
  double r = 0.0;
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (!m.pinned[i]) r = std::max(r, m.mass[static_cast<Eigen::Index>(i)]);
  return r;
}
bool has_colliders(const Model& m) {
#ifdef CLOTHSIM_HAVE_COLLISION
  return m.colliders && m.colliders->triangle_count() > 0;
#else
  return m.colliders != nullptr;
#endif
}


// The largest eigenvalue of the symmetric tridiagonal matrix with diagonal a and
// off-diagonal b (|b| = |a| - 1), by bisection on Sturm counts: O(size) per halving.
double tridiagonal_max_eigenvalue(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t m = a.size();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < m; ++i) {  // Gershgorin
    const double r = (i > 0 ? std::abs(b[i - 1]) : 0.0) + (i + 1 < m ? std::abs(b[i]) : 0.0);
    lo = std::min(lo, a[i] - r);
    hi = std::max(hi, a[i] + r);
  }
  // number of eigenvalues below x
  auto below = [&](double x) {
    std::size_t count = 0;
    double d = 1.0;
    for (std::size_t i = 0; i < m; ++i) {
      d = (a[i] - x) - (i > 0 ? b[i - 1] * b[i - 1] / d : 0.0);
      if (d == 0.0) d = -1e-300;
      if (d < 0.0) ++count;
    }
    return count;
  };
  for (int i = 0; i < 200 && hi - lo > 4e-16 * std::max(std::abs(lo), std::abs(hi)); ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (below(mid) == m ? hi : lo) = mid;
  }
  return hi;
}

// |last component| of the unit eigenvector of that matrix for the eigenvalue theta, by two
// steps of inverse iteration (Thomas algorithm; theta is accurate, so the solve is nearly
// singular and its result is the eigenvector up to scale).
double tridiagonal_last_component(const std::vector<double>& a, const std::vector<double>& b,
                                  double theta) {
  const std::size_t m = a.size();
  if (m == 1) return 1.0;
  std::vector<double> y(m, 1.0), c(m), d(m);
  const double tiny = 1e-300;
  for (int pass = 0; pass < 2; ++pass) {
    double den = a[0] - theta;
    if (den == 0.0) den = tiny;
    c[0] = b[0] / den;
    d[0] = y[0] / den;
    for (std::size_t i = 1; i < m; ++i) {
      den = (a[i] - theta) - b[i - 1] * c[i - 1];
      if (den == 0.0) den = tiny;
      c[i] = i + 1 < m ? b[i] / den : 0.0;
      d[i] = (y[i] - b[i - 1] * d[i - 1]) / den;
    }
    y[m - 1] = d[m - 1];
    for (std::size_t i = m - 1; i-- > 0;) y[i] = d[i] - c[i] * y[i + 1];
    double nrm = 0.0;
    for (double v : y) nrm += v * v;
    nrm = std::sqrt(nrm);
    if (!(nrm > 0.0) || !std::isfinite(nrm)) return 1.0;  // no estimate: report the worst case
    for (double& v : y) v /= nrm;
  }
  return std::abs(y[m - 1]);
}
}  // namespace

double omega_max_bound(const Model& model, bool include_contact, bool bend_only) {
  const std::size_t n = model.mass_count();
  const double kc = include_contact && has_colliders(model) ? model.contact.k_rep : 0.0;
  std::vector<double> diag(n, kc), off(n, 0.0);
  for (std::size_t s = 0; s < model.spring_count(); ++s) {
    if (bend_only && model.spring_kind[s] == 0) continue;
    const double k = model.spring_stiffness(s);
    const auto a = model.spring_a[s], b = model.spring_b[s];
    diag[a] += k;
    diag[b] += k;
    // off-diagonal blocks only couple free masses (pinned ones are not unknowns)
    if (!model.pinned[b]) off[a] += k;
    if (!model.pinned[a]) off[b] += k;
  }
  double w2 = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    if (!model.pinned[i]) w2 = std::max(w2, (diag[i] + off[i]) / model.mass[static_cast<Eigen::Index>(i)]);
  return std::sqrt(w2);
}

OmegaEstimate omega_max_lanczos(const Model& model, const Eigen::Matrix3Xd* x, int max_iterations,
                              double tolerance) {
  const Eigen::Matrix3Xd& pos = x ? *x : model.x0;
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  std::vector<Eigen::Matrix3d> blocks(model.spring_count());
  for (std::size_t s = 0; s < model.spring_count(); ++s) {
    const Eigen::Vector3d e = pos.col(model.spring_a[s]) - pos.col(model.spring_b[s]);
    const double len = e.norm(), k = model.spring_stiffness(s);
    if (len <= 0.0) {
      blocks[s] = k * Eigen::Matrix3d::Identity();
      continue;
    }
    const Eigen::Vector3d nrm = e / len;
    const Eigen::Matrix3d nn = nrm * nrm.transpose();
    const double c = std::max(0.0, 1.0 - model.rest_length0[static_cast<Eigen::Index>(s)] / len);
    blocks[s] = k * (nn + c * (Eigen::Matrix3d::Identity() - nn));
  }
  Eigen::VectorXd inv_sqrt_m(n);
  for (Eigen::Index i = 0; i < n; ++i)
    inv_sqrt_m[i] = model.pinned[static_cast<std::size_t>(i)] ? 0.0 : 1.0 / std::sqrt(model.mass[i]);

  Eigen::Matrix3Xd q(3, n), u(3, n), w(3, n);
  std::uint64_t seed = 0x9E3779B97F4A7C15ull;  // fixed: results are reproducible
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    q.data()[i] = static_cast<double>(seed >> 11) * 0x1.0p-53 - 0.5;
  }
  auto apply = [&](const Eigen::Matrix3Xd& in, Eigen::Matrix3Xd& out) {
    u = (in.array().rowwise() * inv_sqrt_m.transpose().array()).matrix();
    out.setZero();
    for (std::size_t s = 0; s < model.spring_count(); ++s) {
      const Eigen::Vector3d t = blocks[s] * (u.col(model.spring_a[s]) - u.col(model.spring_b[s]));
      out.col(model.spring_a[s]) += t;
      out.col(model.spring_b[s]) -= t;
    }
    out = (out.array().rowwise() * inv_sqrt_m.transpose().array()).matrix();
  };
  for (Eigen::Index i = 0; i < n; ++i)
    if (inv_sqrt_m[i] == 0.0) q.col(i).setZero();
  OmegaEstimate est;
  const double qn = q.norm();
  if (qn == 0.0 || model.spring_count() == 0) return est;
  q /= qn;
  // Lanczos (no reorthogonalisation): the largest Ritz value of the tridiagonal T_j is the
  // maximum of the Rayleigh quotient over the Krylov space K_j(A, q), so it is a lower bound of
  // lambda_max that converges much faster than the power iteration (whose iterate is one vector
  // of the same space): on a large cloth the top eigenvalues are dense and the power iteration
  // needs thousands of iterations (skirt_hires: ~7 s), Lanczos a few hundred (128 x 128
  // masses: 266, test StabilityGuard.LanczosConvergesInAFewHundredIterationsOnA128x128Cloth).
  // Lost orthogonality only duplicates converged Ritz values; the largest one stays below
  // lambda_max up to rounding.
  std::vector<double> alpha, beta;  // T_j: diagonal, off-diagonal
  Eigen::Matrix3Xd q_old = Eigen::Matrix3Xd::Zero(3, n);
  double lambda = 0.0, lambda_old = 0.0, beta_prev = 0.0;
  int flat = 0;
  for (int it = 1; it <= max_iterations; ++it) {
    apply(q, w);
    w -= beta_prev * q_old;
    const double a = (q.array() * w.array()).sum();
    w -= a * q;
    const double b = w.norm();
    alpha.push_back(a);
    est.iterations = it;
    lambda = tridiagonal_max_eigenvalue(alpha, beta);
    if (!(lambda > 0.0)) break;
    // |A y - theta y| = beta_j |last component of the unit Ritz vector| (Paige)
    est.residual = b * tridiagonal_last_component(alpha, beta, lambda) / lambda;
    if (est.residual < tolerance || !(b > 1e-14 * lambda)) {
      est.converged = true;
      break;
    }
    // Near-degenerate top eigenvalues stall the residual but not the Ritz value.
    flat = std::abs(lambda - lambda_old) <= 1e-13 * lambda ? flat + 1 : 0;
    if (flat >= 5) {
      est.converged = true;
      break;
    }
    lambda_old = lambda;
    beta.push_back(b);
    beta_prev = b;
    q_old.swap(q);
    q = w / b;
  }
  est.omega = std::sqrt(std::max(lambda, 0.0));
  return est;
}

double omega_contact(const Model& model) {
  if (!has_colliders(model)) return 0.0;
  const double m = min_free_mass(model);
  return std::isfinite(m) ? std::sqrt(model.contact.k_rep / m) : 0.0;
}

double stable_dt(Integrator method, double omega, double zeta) {
  // An overflowed omega or damping rate (masses of 1e-300 kg) has no usable step.
  if (!std::isfinite(omega) || !std::isfinite(zeta)) return 0.0;
  if (!(omega > 0.0)) return std::numeric_limits<double>::infinity();
  const double w2 = omega * omega;
  // The method's one-step map on (x, v) for x'' = -w2 x - 2 zeta v, as the code does it.
  auto map = [&](double h, double x, double v, double& x1, double& v1) {
    auto a = [&](double xx, double vv) { return -w2 * xx - 2.0 * zeta * vv; };
    switch (method) {
      case Integrator::Auto:  // (resolved when the Model is built: the seed's method)
      case Integrator::SymplecticEuler:
        x1 = x + h * v;
        v1 = v + h * a(x1, v);
        break;
      case Integrator::ExplicitEuler:
        x1 = x + h * v;
        v1 = v + h * a(x, v);
        break;
      case Integrator::Verlet: {
        const double xh = x + 0.5 * h * v;
        v1 = v + h * a(xh, v) / (1.0 + h * zeta);
        x1 = xh + 0.5 * h * v1;
        break;
      }
      case Integrator::Midpoint: {
        const double xm = x + 0.5 * h * v, vm = v + 0.5 * h * a(x, v);
        x1 = x + h * vm;
        v1 = v + h * a(xm, vm);
        break;
      }
      case Integrator::RK4: {
        const double k1x = v, k1v = a(x, v);
        const double k2x = v + 0.5 * h * k1v, k2v = a(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
        const double k3x = v + 0.5 * h * k2v, k3v = a(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
        const double k4x = v + h * k3v, k4v = a(x + h * k3x, v + h * k3v);
        x1 = x + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
        v1 = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
        break;
      }
      case Integrator::ImplicitEuler: {
        const double dv = h * (a(x, v) - h * w2 * v) / (1.0 + 2.0 * zeta * h + h * h * w2);
        v1 = v + dv;
        x1 = x + h * v1;
        break;
      }
      case Integrator::XPBD: {  // one constraint: the projection is implicit Euler, damping too
        x1 = (x + h * v / (1.0 + 2.0 * zeta * h)) / (1.0 + h * h * w2);
        v1 = (x1 - x) / h;
        break;
      }
      case Integrator::FastMassSpring: {  // springs and damping implicit, by local/global
        x1 = (x * (1.0 + 2.0 * zeta * h) + h * v) / (1.0 + 2.0 * zeta * h + h * h * w2);
        v1 = (x1 - x) / h;
        break;
      }
    }
  };
  auto radius = [&](double h) {
    double g00 = 0, g10 = 0, g01 = 0, g11 = 0;
    map(h, 1.0, 0.0, g00, g10);
    map(h, 0.0, 1.0, g01, g11);
    const double tr = g00 + g11, det = g00 * g11 - g01 * g10;
    const std::complex<double> disc = std::sqrt(std::complex<double>(0.25 * tr * tr - det));
    return std::max(std::abs(0.5 * tr + disc), std::abs(0.5 * tr - disc));
  };
  auto stable = [&](double h) { return radius(h) <= 1.0 + 1e-12; };
  // Unstable already at h omega = 1e-3: treat as never stable (explicit Euler without damping).
  // A damping rate above omega sets the scale instead: XPBD and the symplectic methods treat
  // damping explicitly, stable only for h zeta below about 1 (--mass 1e-45, --damping 0.1).
  double lo = 1e-3 / std::max(omega, zeta);
  if (!stable(lo)) return 0.0;
  double hi = lo;
  while (stable(hi)) {
    lo = hi;
    hi *= 2.0;
    if (hi > 1e6 / omega) return std::numeric_limits<double>::infinity();
  }
  for (int i = 0; i < 100 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return lo;
}

StabilityReport analyse_stability(const Model& model, int lanczos_iterations) {
  StabilityReport r;
  const OmegaEstimate lanczos = omega_max_lanczos(model, nullptr, lanczos_iterations);
  r.lanczos_iterations = lanczos.iterations;
  r.springs_by_bound = !lanczos.converged && lanczos.omega > 0.0;
  r.omega_springs = r.springs_by_bound ? omega_max_bound(model, false) : lanczos.omega;
  r.omega_bound = omega_max_bound(model, true);
  // Stiffnesses whose k / m overflows (--k-struct 1e308) leave Lanczos no finite vector (it
  // would say 0 rad/s and let the run blow up); the bound tells.
  if (!std::isfinite(r.omega_bound) || !std::isfinite(r.omega_springs))
    r.omega_springs = std::numeric_limits<double>::infinity();
  r.omega_contact = omega_contact(model);
  r.omega_max = std::sqrt(r.omega_springs * r.omega_springs + r.omega_contact * r.omega_contact);
  for (std::size_t i = 0; i < model.mass_count(); ++i)  // the weakest damping rate
    if (!model.pinned[i]) {
      const double rate = model.damping_of(i) / (2.0 * model.mass[static_cast<Eigen::Index>(i)]);
      r.zeta = r.zeta > 0.0 ? std::min(r.zeta, rate) : rate;
    }
  r.dt_stable = stable_dt(model.options.integrator, r.omega_max, r.zeta);
  // The penalty contact is an explicit force in every integrator (the implicit ones solve only
  // the springs implicitly: implicit_euler.cpp, xpbd.cpp, fast_mass_spring.cpp), and a one-sided
  // spring taken explicitly gains energy at each bounce as h omega_contact nears its linear
  // limit 2: a point dropped 0.3 m rebounds 0.889 m at h omega_c = 1.8 (0.9 x 2 / omega_c, the
  // safe step), 0.308 m at 1.0.
  // So the contact's own limit is set so that the safe step (0.9 dt_stable) has h omega_c = 1.
  // Without it the implicit methods' guard says dt_stable inf, and a light cloth on a floor
  // bounces ever higher at the default dt (XPBD: 8 m up after 3 s).
  const Integrator method = model.options.integrator;
  if (method == Integrator::XPBD) {  // no limit: its step is the one its accuracy and contact need
    r.dt_stable = xpbd_step(model);
    r.dt_stable_symplectic = stable_dt(Integrator::SymplecticEuler, r.omega_max, r.zeta);
    return r;
  }
  if (r.omega_contact > 0.0) {
    const double implicit_springs =
        method == Integrator::ImplicitEuler || method == Integrator::XPBD || method == Integrator::FastMassSpring
            ? stable_dt(method, r.omega_springs, r.zeta)
            : r.dt_stable;
    const double contact = 1.0 / (0.9 * r.omega_contact);
    r.dt_stable = std::min(implicit_springs, r.dt_stable);
    if (contact < r.dt_stable) r.dt_stable = contact, r.contact_limited = true;
  }
  r.dt_stable_symplectic = stable_dt(Integrator::SymplecticEuler, r.omega_max, r.zeta);
  return r;
}

std::string describe(const StabilityReport& r, Integrator method) {
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "stability: omega_max %.4g rad/s (springs %.4g by %s, contact %.4g; "
                "the springs' Gershgorin bound %.4g) -> %s dt_stable %.4g s",
                r.omega_max, r.omega_springs,
                r.springs_by_bound ? "Gershgorin: Lanczos did not converge" : "Lanczos", r.omega_contact,
                r.omega_bound, to_string(method), r.dt_stable);
  if (r.contact_limited)
    return std::string(buf) + " (set by the contact: h omega_contact = 1 at the safe step, 0.9 dt_stable)";
  return buf;
}

namespace {
std::string fmt_g(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}
}  // namespace

std::string never_stable_reason(const StabilityReport& r, Integrator method) {
  char buf[400];
  if (!std::isfinite(r.omega_max) || !std::isfinite(r.zeta))
    std::snprintf(buf, sizeof buf,
                  "no step size is stable: %s overflows; the masses are too light for %s (or those are too large)",
                  !std::isfinite(r.omega_max) ? ("omega_max (" + fmt_g(r.omega_max) + " rad/s)").c_str()
                                              : ("the damping rate (" + fmt_g(r.zeta) + " 1/s)").c_str(),
                  !std::isfinite(r.omega_max) ? "the springs (--k-struct, --k-bend) or the contact (--k-rep)"
                                              : "the damping");
  else if (r.zeta == 0.0)
    std::snprintf(buf, sizeof buf,
                  "%s is unstable at every step size without damping, and this model has none "
                  "(damping 0); choose another integrator or add damping",
                  to_string(method));
  else
    std::snprintf(buf, sizeof buf,
                  "%s is unstable at every step size (down to h omega_max = 1e-3) with this little "
                  "damping: rate %.4g 1/s against omega_max %.4g rad/s; choose another integrator "
                  "or more damping",
                  to_string(method), r.zeta, r.omega_max);
  return buf;
}

SubstepPolicy parse_substeps(std::string_view text) {
  SubstepPolicy p;
  if (text == "auto") return p;
  if (text == "off") {
    p.mode = SubstepPolicy::Mode::Off;
    return p;
  }
  int n = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (ec != std::errc{} || ptr != text.data() + text.size() || n < 1 || n > p.max_substeps)
    throw std::invalid_argument("--substeps: expected auto, off or a whole number 1.." +
                                std::to_string(p.max_substeps) + ", got '" + std::string(text) + "'");
  p.mode = SubstepPolicy::Mode::Fixed;
  p.count = n;
  return p;
}

SubstepPlan plan_substeps(double dt, double dt_stable, const SubstepPolicy& policy) {
  SubstepPlan plan;
  char buf[320];
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    plan.ok = false;
    plan.message = "dt must be a finite number > 0";
    return plan;
  }
  switch (policy.mode) {
    case SubstepPolicy::Mode::Fixed: plan.substeps = policy.count; break;
    case SubstepPolicy::Mode::Off: plan.substeps = 1; break;
    case SubstepPolicy::Mode::Auto: {
      if (!(dt_stable > 0.0)) {
        plan.ok = false;  // why: never_stable_reason(), which knows the model's damping
        plan.message = "this integrator is unstable at every step size on this model";
        return plan;
      }
      const double need = std::ceil(dt / (policy.margin * dt_stable));
      if (need > policy.max_substeps) {
        plan.ok = false;
        std::snprintf(buf, sizeof buf,
                      "dt %.4g s would need %.3g substeps to stay under dt_stable %.4g s "
                      "(more than %d); choose a smaller dt or another integrator",
                      dt, need, dt_stable, policy.max_substeps);
        plan.message = buf;
        return plan;
      }
      plan.substeps = std::max(1, static_cast<int>(need));
      if (plan.substeps > 1) {
        std::snprintf(buf, sizeof buf,
                      "dt %.4g s is above the safe step %.4g s (%.2g x dt_stable %.4g s): taking %d "
                      "substeps of %.4g s (--substeps off to refuse instead)",
                      dt, policy.margin * dt_stable, policy.margin, dt_stable, plan.substeps,
                      dt / plan.substeps);
        plan.message = buf;
      }
      break;
    }
  }
  plan.h = dt / plan.substeps;
  // off and N use the same limit as auto, the safe step margin * dt_stable: off refuses exactly
  // when auto would substep. N is the user's explicit choice: taken, with a warning (a blow-up
  // is then caught by step()'s finite check and reported, never passed on).
  const double safe = policy.margin * dt_stable;
  const bool above_safe = !(std::ceil(plan.h / safe) <= 1.0);  // auto's test: it would substep
  if (policy.mode != SubstepPolicy::Mode::Auto && above_safe) {
    plan.ok = policy.mode == SubstepPolicy::Mode::Fixed;
    const char* prefix = plan.ok ? "warning: " : "";
    const char* what = plan.h >= dt_stable ? "h omega_max too large; the run would blow up"
                                           : "inside the guard's margin; the run may blow up";
    const double need = dt_stable > 0.0 ? std::ceil(dt / safe) : 0.0;
    if (need >= 1.0 && need <= policy.max_substeps)
      std::snprintf(buf, sizeof buf,
                    "%sstep %.4g s is above the safe step %.4g s (%.2g x the stability limit "
                    "dt_stable %.4g s; %s): use a smaller dt, --substeps auto or --substeps %d",
                    prefix, plan.h, safe, policy.margin, dt_stable, what, static_cast<int>(need));
    else
      std::snprintf(buf, sizeof buf,
                    "%sstep %.4g s is above the safe step %.4g s (%.2g x the stability limit "
                    "dt_stable %.4g s; %s): use a smaller dt or another integrator",
                    prefix, plan.h, safe, policy.margin, dt_stable, what);
    plan.message = buf;
  }
  return plan;
}

double max_stoppable_speed(double epsilon, double k_rep, double mass, double h) {
  return std::min(epsilon * std::sqrt(k_rep / mass), epsilon / h);
}

double xpbd_step(const Model& model) {
  const double fall = std::sqrt(2.0 * model.gravity.norm() * drop_height(model));
  const double bend = omega_max_bound(model, false, true);  // (explicit: symplectic Euler's limit)
  const double edge = mean_structural_length(model);
  double h = fall > 0.0 ? std::min(kXpbdStep, model.contact.band / fall) : kXpbdStep;
  if (edge > 0.0) h = std::min(h, edge / kXpbdSpeed);
  if (bend > 0.0) h = std::min(h, 2.0 / bend);
  return h;
}

double drop_height(const Model& model, double lowest_collider) {
  const double g = model.gravity.norm();
  if (!(g > 0.0) || max_free_mass(model) <= 0.0) return 0.0;
  const Eigen::Vector3d up = -model.gravity / g;
  if (std::isnan(lowest_collider)) {
    if (!has_colliders(model)) return 0.0;
#ifdef CLOTHSIM_HAVE_COLLISION
    const Eigen::Vector3d lo = model.colliders->bounds_min(), hi = model.colliders->bounds_max();
    lowest_collider = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d p((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
      lowest_collider = std::min(lowest_collider, up.dot(p));
    }
#else
    return 0.0;
#endif
  }
  double top = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < model.mass_count(); ++i)
    if (!model.pinned[i]) top = std::max(top, up.dot(model.x0.col(static_cast<Eigen::Index>(i))));
  return std::max(0.0, top - lowest_collider);
}

TunnellingReport check_tunnelling(const Model& model, double h, double lowest_collider) {
  TunnellingReport r;
  const ContactParams& c = model.contact;
  const double m_max = max_free_mass(model);
  const bool positions = model.options.integrator == Integrator::XPBD;  // (position-based contact)
  r.stop_speed = positions ? std::numeric_limits<double>::infinity()
                           : (m_max > 0.0 ? c.distance * std::sqrt(c.k_rep / m_max) : 0.0);
  r.see_speed = (positions ? c.band : c.distance) / h;
  r.max_speed = std::min(r.stop_speed, r.see_speed);
  if (!(model.gravity.norm() > 0.0) || m_max <= 0.0) return r;
  if (std::isnan(lowest_collider) && !has_colliders(model)) return r;
  r.drop_height = drop_height(model, lowest_collider);
  r.fall_speed = std::sqrt(2.0 * model.gravity.norm() * r.drop_height);
  r.warn = r.fall_speed >= r.max_speed;
  if (r.warn) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "warning: tunnelling: a fall of %.3g m reaches %.3g m/s, but the contact stops at "
                  "most %.3g m/s (eps sqrt(k_rep/m) = %.3g, eps/h = %.3g): raise k_rep or epsilon, "
                  "or lower dt",
                  r.drop_height, r.fall_speed, r.max_speed, r.stop_speed, r.see_speed);
    r.message = buf;
  }
  return r;
}

}  // namespace clothsim
