// Integrators other than the seed's symplectic Euler; see integrators.hpp.
#include <clothsim/integrators.hpp>
#include <clothsim/step.hpp>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <array>
#include <cmath>
#include <vector>

namespace clothsim {

struct IntegratorScratch {
  // explicit stages (3 x n)
  Eigen::Matrix3Xd xs, vs, acc_x, acc_v, f2;
  // implicit Euler (Baraff & Witkin)
  std::vector<Eigen::Matrix3d> spring_k;  ///< (s) -df_a/dx_a, clamped to be PSD
  std::vector<Eigen::Matrix3d> precond;   ///< (n) inverse diagonal blocks
  Eigen::Matrix3Xd r, z, p, ap, dv, rhs;
  // fast mass-spring (Liu et al. 2013)
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt;
  double llt_h = -1.0, llt_ksum = -1.0;
  std::vector<int> compact;               ///< (n) index among the free masses, -1 if pinned
  int free_count = 0;
  Eigen::Matrix3Xd d, y, fext;            ///< (3 x s) spring directions; (3 x n) inertia target
  Eigen::MatrixXd b, sol;                 ///< (free x 3)
  ImplicitSettings settings;
  ImplicitStats stats;
};

std::shared_ptr<IntegratorScratch> make_integrator_scratch(const Model& model) {
  auto s = std::make_shared<IntegratorScratch>();
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  const auto sc = static_cast<Eigen::Index>(model.spring_count());
  for (Eigen::Matrix3Xd* m : {&s->xs, &s->vs, &s->acc_x, &s->acc_v, &s->f2, &s->r, &s->z, &s->p,
                              &s->ap, &s->dv, &s->rhs, &s->y, &s->fext})
    *m = Eigen::Matrix3Xd::Zero(3, n);
  s->d = Eigen::Matrix3Xd::Zero(3, sc);
  s->spring_k.assign(static_cast<std::size_t>(sc), Eigen::Matrix3d::Zero());
  s->precond.assign(static_cast<std::size_t>(n), Eigen::Matrix3d::Zero());
  s->compact.assign(static_cast<std::size_t>(n), -1);
  for (Eigen::Index i = 0; i < n; ++i)
    if (!model.pinned[static_cast<std::size_t>(i)]) s->compact[static_cast<std::size_t>(i)] = s->free_count++;
  s->b = Eigen::MatrixXd::Zero(s->free_count, 3);
  s->sol = Eigen::MatrixXd::Zero(s->free_count, 3);
  // Rest directions: a spring whose ends coincide keeps the last direction it had.
  for (Eigen::Index k = 0; k < sc; ++k) {
    const Eigen::Vector3d e = model.x0.col(model.spring_a[static_cast<std::size_t>(k)]) -
                              model.x0.col(model.spring_b[static_cast<std::size_t>(k)]);
    const double len = e.norm();
    s->d.col(k) = len > 0.0 ? Eigen::Vector3d(e * (model.rest_length0[k] / len)) : Eigen::Vector3d::Zero();
  }
  return s;
}

void set_implicit_settings(IntegratorScratch& scratch, const ImplicitSettings& settings) {
  scratch.settings = settings;
}
ImplicitStats implicit_stats(const IntegratorScratch& scratch) { return scratch.stats; }

namespace {

constexpr std::array<Integrator, 8> kAll = {
    Integrator::SymplecticEuler, Integrator::ExplicitEuler, Integrator::Verlet,
    Integrator::Midpoint,        Integrator::RK4,           Integrator::ImplicitEuler,
    Integrator::FastMassSpring,  Integrator::XPBD};

// a = f / m row-wise; pinned masses have inv_mass 0.
auto accel(const Model& model, const Eigen::Matrix3Xd& f) {
  return (f.array().rowwise() * model.inv_mass.transpose().array()).matrix();
}


void explicit_euler(const Model& m, State& s, Workspace& ws, IntegratorScratch&, double h) {
  compute_forces(m, s.x, s.v, ws.f, ws);
  s.x.noalias() += h * s.v;
  s.v.noalias() += h * accel(m, ws.f);
}

void midpoint(const Model& m, State& s, Workspace& ws, IntegratorScratch& sc, double h) {
  compute_forces(m, s.x, s.v, ws.f, ws);
  sc.xs.noalias() = s.x + (0.5 * h) * s.v;
  sc.vs.noalias() = s.v + (0.5 * h) * accel(m, ws.f);
  compute_forces(m, sc.xs, sc.vs, ws.f, ws);
  s.x.noalias() += h * sc.vs;
  s.v.noalias() += h * accel(m, ws.f);
}

void rk4(const Model& m, State& s, Workspace& ws, IntegratorScratch& sc, double h) {
  // Stage i: position slope = the stage's velocity vs, velocity slope = a(xs, vs).
  compute_forces(m, s.x, s.v, ws.f, ws);
  sc.acc_x = s.v;
  sc.acc_v.noalias() = accel(m, ws.f);
  sc.xs.noalias() = s.x + (0.5 * h) * s.v;
  sc.vs.noalias() = s.v + (0.5 * h) * sc.acc_v;  // acc_v == k1 here
  for (int stage = 2; stage <= 4; ++stage) {
    compute_forces(m, sc.xs, sc.vs, ws.f, ws);
    const double w = stage == 4 ? 1.0 : 2.0;
    sc.acc_x.noalias() += w * sc.vs;
    sc.f2.noalias() = accel(m, ws.f);  // k_stage of v
    sc.acc_v.noalias() += w * sc.f2;
    if (stage < 4) {
      const double c = stage == 2 ? 0.5 * h : h;
      sc.xs.noalias() = s.x + c * sc.vs;
      sc.vs.noalias() = s.v + c * sc.f2;
    }
  }
  s.x.noalias() += (h / 6.0) * sc.acc_x;
  s.v.noalias() += (h / 6.0) * sc.acc_v;
}

void verlet(const Model& m, State& s, Workspace& ws, IntegratorScratch&, double h) {
  // Drift-kick-drift. The force stage's damping -gamma v is evaluated at v(t); replacing it by
  // the midpoint (v(t) + v(t+h))/2 keeps the method second order with damping:
  // v' = v + h/m (f(x_half, v) ) / (1 + h gamma / (2 m)).
  const double g = m.options.damping;
  s.x.noalias() += (0.5 * h) * s.v;
  compute_forces(m, s.x, s.v, ws.f, ws);
  for (Eigen::Index i = 0; i < s.x.cols(); ++i) {
    const double im = m.inv_mass[i];
    s.v.col(i) += (h * im / (1.0 + 0.5 * h * g * im)) * ws.f.col(i);
  }
  s.x.noalias() += (0.5 * h) * s.v;
}

// --- implicit Euler (Baraff & Witkin 1998) ----------------------------------------------

void spring_jacobians(const Model& m, const Eigen::Matrix3Xd& x, IntegratorScratch& sc) {
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    const Eigen::Vector3d e = x.col(m.spring_a[k]) - x.col(m.spring_b[k]);
    const double len = e.norm();
    const double ks = m.spring_stiffness(k);
    if (len <= 0.0) {  // coincident ends: isotropic stand-in, keeps the matrix SPD
      sc.spring_k[k] = ks * Eigen::Matrix3d::Identity();
      continue;
    }
    const Eigen::Vector3d n = e / len;
    const Eigen::Matrix3d nn = n * n.transpose();
    // -df_a/dx_a = k (n n^T + (1 - l/L)(I - n n^T)); the transverse term is indefinite when
    // the spring is compressed (l > L), so it is clamped at 0 (Choi & Ko 2002).
    const double c = std::max(0.0, 1.0 - m.rest_length0[static_cast<Eigen::Index>(k)] / len);
    sc.spring_k[k] = ks * (nn + c * (Eigen::Matrix3d::Identity() - nn));
  }
}

// y = (M + h gamma + h^2 K) p, pinned rows zero.
void apply_system(const Model& m, const IntegratorScratch& sc, double h, const Eigen::Matrix3Xd& p,
                  Eigen::Matrix3Xd& y) {
  const double hg = h * m.options.damping, h2 = h * h;
  for (Eigen::Index i = 0; i < p.cols(); ++i) y.col(i) = (m.mass[i] + hg) * p.col(i);
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    const Eigen::Vector3d t = h2 * (sc.spring_k[k] * (p.col(m.spring_a[k]) - p.col(m.spring_b[k])));
    y.col(m.spring_a[k]) += t;
    y.col(m.spring_b[k]) -= t;
  }
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (m.pinned[i]) y.col(static_cast<Eigen::Index>(i)).setZero();
}

void implicit_euler(const Model& m, State& s, Workspace& ws, IntegratorScratch& sc, double h) {
  compute_forces(m, s.x, s.v, ws.f, ws);  // penalty contact stays explicit (in f)
  spring_jacobians(m, s.x, sc);
  const double hg = h * m.options.damping, h2 = h * h;
  // block-Jacobi preconditioner
  for (Eigen::Index i = 0; i < s.x.cols(); ++i)
    sc.precond[static_cast<std::size_t>(i)] = (m.mass[i] + hg) * Eigen::Matrix3d::Identity();
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    sc.precond[m.spring_a[k]] += h2 * sc.spring_k[k];
    sc.precond[m.spring_b[k]] += h2 * sc.spring_k[k];
  }
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    sc.precond[i] = m.pinned[i] ? Eigen::Matrix3d::Zero() : Eigen::Matrix3d(sc.precond[i].inverse());
  // rhs = h (f - h K v), with -h^2 K v = (M + h gamma) v - A v.
  apply_system(m, sc, h, s.v, sc.ap);
  for (Eigen::Index i = 0; i < s.x.cols(); ++i) {
    const double mi = m.pinned[static_cast<std::size_t>(i)] ? 0.0 : m.mass[i] + hg;
    // -h^2 K v = (M + h g) v - A v
    sc.rhs.col(i) = h * ws.f.col(i) + (mi * s.v.col(i) - sc.ap.col(i));
    if (m.pinned[static_cast<std::size_t>(i)]) sc.rhs.col(i).setZero();
  }
  // preconditioned CG from dv = 0
  sc.dv.setZero();
  sc.r = sc.rhs;
  for (Eigen::Index i = 0; i < s.x.cols(); ++i) sc.z.col(i) = sc.precond[static_cast<std::size_t>(i)] * sc.r.col(i);
  sc.p = sc.z;
  double rz = (sc.r.array() * sc.z.array()).sum();
  const double b_norm = sc.rhs.norm();
  double r_norm = b_norm;
  int it = 0;
  if (b_norm > 0.0) {
    for (; it < sc.settings.cg_max_iterations; ++it) {
      apply_system(m, sc, h, sc.p, sc.ap);
      const double pap = (sc.p.array() * sc.ap.array()).sum();
      if (!(pap > 0.0)) break;
      const double alpha = rz / pap;
      sc.dv.noalias() += alpha * sc.p;
      sc.r.noalias() -= alpha * sc.ap;
      r_norm = sc.r.norm();
      if (r_norm <= sc.settings.cg_tolerance * b_norm) { ++it; break; }
      for (Eigen::Index i = 0; i < s.x.cols(); ++i) sc.z.col(i) = sc.precond[static_cast<std::size_t>(i)] * sc.r.col(i);
      const double rz_new = (sc.r.array() * sc.z.array()).sum();
      sc.p = sc.z + (rz_new / rz) * sc.p;
      rz = rz_new;
    }
  }
  sc.stats.cg_iterations = it;
  sc.stats.cg_residual = b_norm > 0.0 ? r_norm / b_norm : 0.0;
  s.v += sc.dv;
  s.x.noalias() += h * s.v;
}

// --- fast mass-spring (Liu, Bargteil, O'Brien, Kavan 2013) -------------------------------

void fms_precompute(const Model& m, IntegratorScratch& sc, double h) {
  // (M + h gamma + h^2 L) over the free masses, L = sum_s k_s (e_a - e_b)(e_a - e_b)^T.
  // Damping is implicit too: explicit damping is unstable for light masses (h gamma / m > 2).
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(m.mass_count() + 4 * m.spring_count());
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (sc.compact[i] >= 0)
      t.emplace_back(sc.compact[i], sc.compact[i], m.mass[static_cast<Eigen::Index>(i)] + h * m.options.damping);
  const double h2 = h * h;
  double ksum = m.options.damping;  // the key: damping is in the matrix too
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    const double w = h2 * m.spring_stiffness(k);
    ksum += m.spring_stiffness(k);
    const int a = sc.compact[m.spring_a[k]], b = sc.compact[m.spring_b[k]];
    if (a >= 0) t.emplace_back(a, a, w);
    if (b >= 0) t.emplace_back(b, b, w);
    if (a >= 0 && b >= 0) {
      t.emplace_back(a, b, -w);
      t.emplace_back(b, a, -w);
    }
  }
  Eigen::SparseMatrix<double> q(sc.free_count, sc.free_count);
  q.setFromTriplets(t.begin(), t.end());
  sc.llt.compute(q);
  sc.llt_h = h;
  sc.llt_ksum = ksum;
  ++sc.stats.factorizations;
}

void fast_mass_spring(const Model& m, State& s, Workspace& ws, IntegratorScratch& sc, double h) {
  double ksum = m.options.damping;
  for (std::size_t k = 0; k < m.spring_count(); ++k) ksum += m.spring_stiffness(k);
  if (sc.llt_h != h || sc.llt_ksum != ksum) fms_precompute(m, sc, h);
  // External forces = everything but the springs and the damping (gravity, contact, drag),
  // explicit. The force stage's damping is -gamma v (step.hpp), added back here.
  compute_forces(m, s.x, s.v, ws.f, ws);
  sc.f2.setZero();
  add_spring_forces(m, s.x, sc.f2);
  sc.fext = ws.f - sc.f2 + m.options.damping * s.v;
  sc.y.noalias() = s.x + h * s.v + (h * h) * accel(m, sc.fext);
  sc.xs = sc.y;
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (m.pinned[i]) sc.xs.col(static_cast<Eigen::Index>(i)) = s.x.col(static_cast<Eigen::Index>(i));
  const double h2 = h * h;
  for (int iter = 0; iter < sc.settings.fms_iterations; ++iter) {
    // local: the best rest-length direction of every spring
    for (std::size_t k = 0; k < m.spring_count(); ++k) {
      const Eigen::Vector3d e = sc.xs.col(m.spring_a[k]) - sc.xs.col(m.spring_b[k]);
      const double len = e.norm();
      if (len > 0.0) sc.d.col(static_cast<Eigen::Index>(k)) = e * (m.rest_length0[static_cast<Eigen::Index>(k)] / len);
    }
    // global: (M + h gamma + h^2 L) x = M y + h gamma x_n + h^2 J d, pinned ends on the right
    for (std::size_t i = 0; i < m.mass_count(); ++i)
      if (sc.compact[i] >= 0) {
        const auto c = static_cast<Eigen::Index>(i);
        sc.b.row(sc.compact[i]) = (m.mass[c] * sc.y.col(c) + h * m.options.damping * s.x.col(c)).transpose();
      }
    for (std::size_t k = 0; k < m.spring_count(); ++k) {
      const double w = h2 * m.spring_stiffness(k);
      const Eigen::Vector3d jd = w * sc.d.col(static_cast<Eigen::Index>(k));
      const int a = sc.compact[m.spring_a[k]], b = sc.compact[m.spring_b[k]];
      if (a >= 0) {
        sc.b.row(a) += jd.transpose();
        if (b < 0) sc.b.row(a) += w * s.x.col(m.spring_b[k]).transpose();
      }
      if (b >= 0) {
        sc.b.row(b) -= jd.transpose();
        if (a < 0) sc.b.row(b) += w * s.x.col(m.spring_a[k]).transpose();
      }
    }
    sc.sol = sc.llt.solve(sc.b);
    for (std::size_t i = 0; i < m.mass_count(); ++i)
      if (sc.compact[i] >= 0) sc.xs.col(static_cast<Eigen::Index>(i)) = sc.sol.row(sc.compact[i]).transpose();
  }
  s.v = (sc.xs - s.x) / h;
  s.x = sc.xs;
}

// --- XPBD (Macklin, Mueller, Chentanez 2016; "Small Steps", Macklin et al. 2019) -----------

void xpbd(const Model& m, State& s, Workspace& ws, IntegratorScratch& sc, double h) {
  // Predict with every force but the springs (gravity, damping, contact, drag: explicit),
  // then one Gauss-Seidel pass of compliant distance constraints, alpha = 1/k; lambda starts
  // at 0 every step (one iteration per small step, as "Small Steps" recommends).
  compute_forces(m, s.x, s.v, ws.f, ws);
  sc.f2.setZero();
  add_spring_forces(m, s.x, sc.f2);
  sc.fext = ws.f - sc.f2;
  sc.xs = s.x;  // x(t)
  s.v.noalias() += h * accel(m, sc.fext);
  s.x.noalias() += h * s.v;
  const double inv_h2 = 1.0 / (h * h);
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    const auto a = m.spring_a[k], b = m.spring_b[k];
    const double wa = m.inv_mass[a], wb = m.inv_mass[b];
    const double ks = m.spring_stiffness(k);
    if (ks <= 0.0 || wa + wb == 0.0) continue;
    const Eigen::Vector3d e = s.x.col(a) - s.x.col(b);
    const double len = e.norm();
    if (len == 0.0) continue;  // no direction: no correction (as the force stage)
    const double c = len - m.rest_length0[static_cast<Eigen::Index>(k)];
    const double dlambda = -c / (wa + wb + inv_h2 / ks);
    const Eigen::Vector3d corr = (dlambda / len) * e;
    s.x.col(a) += wa * corr;
    s.x.col(b) -= wb * corr;
  }
  s.v = (s.x - sc.xs) / h;
}

}  // namespace

std::span<const Integrator> all_integrators() { return kAll; }

const char* to_string(Integrator method) {
  switch (method) {
    case Integrator::SymplecticEuler: return "symplectic-euler";
    case Integrator::ExplicitEuler: return "explicit-euler";
    case Integrator::Verlet: return "verlet";
    case Integrator::Midpoint: return "midpoint";
    case Integrator::RK4: return "rk4";
    case Integrator::ImplicitEuler: return "implicit-euler";
    case Integrator::FastMassSpring: return "fast-mass-spring";
    case Integrator::XPBD: return "xpbd";
  }
  return "unknown";
}

std::optional<Integrator> parse_integrator(std::string_view name) {
  for (Integrator m : kAll)
    if (name == to_string(m)) return m;
  if (name == "leapfrog" || name == "velocity-verlet") return Integrator::Verlet;
  if (name == "rk2") return Integrator::Midpoint;
  if (name == "baraff-witkin") return Integrator::ImplicitEuler;
  if (name == "liu") return Integrator::FastMassSpring;
  return std::nullopt;
}

std::string integrator_names() {
  std::string out;
  for (Integrator m : kAll) {
    if (!out.empty()) out += ", ";
    out += to_string(m);
  }
  return out;
}

int integrator_order(Integrator method) {
  switch (method) {
    case Integrator::Verlet:
    case Integrator::Midpoint: return 2;
    case Integrator::RK4: return 4;
    default: return 1;
  }
}

int force_evaluations(Integrator method) {
  switch (method) {
    case Integrator::Midpoint: return 2;
    case Integrator::RK4: return 4;
    default: return 1;
  }
}

void integrate(const Model& model, State& state, Workspace& ws) {
  // Made on first use (once per Workspace), so make_workspace() need not know about it.
  if (!ws.integrator_scratch) ws.integrator_scratch = make_integrator_scratch(model);
  IntegratorScratch& sc = *ws.integrator_scratch;
  const double h = model.options.dt;
  save_pins(state, ws);
  switch (model.options.integrator) {
    case Integrator::SymplecticEuler:  // the core's; kept here for completeness
      state.x.noalias() += h * state.v;
      compute_forces(model, state.x, state.v, ws.f, ws);
      state.v.noalias() += h * accel(model, ws.f);
      break;
    case Integrator::ExplicitEuler: explicit_euler(model, state, ws, sc, h); break;
    case Integrator::Verlet: verlet(model, state, ws, sc, h); break;
    case Integrator::Midpoint: midpoint(model, state, ws, sc, h); break;
    case Integrator::RK4: rk4(model, state, ws, sc, h); break;
    case Integrator::ImplicitEuler: implicit_euler(model, state, ws, sc, h); break;
    case Integrator::FastMassSpring: fast_mass_spring(model, state, ws, sc, h); break;
    case Integrator::XPBD: xpbd(model, state, ws, sc, h); break;
  }
  restore_pins(state, ws);
}

}  // namespace clothsim
