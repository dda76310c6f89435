// Forces and time integration (report eqs. 1-7). Nothing here allocates after make_workspace().
#include <clothsim/step.hpp>
#include <clothsim/integrators.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>

#ifdef _OPENMP
#include <omp.h>
#endif

#ifdef CLOTHSIM_HAVE_COLLISION
#include <clothsim/collision.hpp>
#endif

namespace clothsim {

namespace {

std::atomic<int> g_threads{1};

// Threads for a loop of `work` items: below ~4k items a parallel region costs more than it saves.
int team(std::size_t work) {
  const int t = g_threads.load(std::memory_order_relaxed);
  return work >= 4096 ? t : 1;
}

}  // namespace

void set_threads(int n) {
#ifdef _OPENMP
  g_threads = n > 0 ? n : omp_get_num_procs();
#else
  (void)n;
  g_threads = 1;
#endif
}

int threads() { return g_threads.load(); }

SpringAdjacency SpringAdjacency::build(const Model& model) {
  const std::size_t n = model.mass_count(), s_count = model.spring_count();
  SpringAdjacency a;
  a.start.assign(n + 1, 0);
  for (std::size_t s = 0; s < s_count; ++s) {
    ++a.start[model.spring_a[s] + 1];
    ++a.start[model.spring_b[s] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) a.start[i + 1] += a.start[i];
  a.other.resize(2 * s_count);
  a.spring.resize(2 * s_count);
  std::vector<std::uint32_t> fill(a.start.begin(), a.start.end() - 1);
  for (std::size_t s = 0; s < s_count; ++s) {  // increasing s: the scatter's order per mass
    const std::uint32_t ma = model.spring_a[s], mb = model.spring_b[s];
    a.other[fill[ma]] = mb;
    a.spring[fill[ma]++] = static_cast<std::uint32_t>(s);
    a.other[fill[mb]] = ma;
    a.spring[fill[mb]++] = static_cast<std::uint32_t>(s);
  }
  return a;
}

State make_state(const Model& model) {
  State s;
  s.x = model.x0;
  s.v = Eigen::Matrix3Xd::Zero(3, model.x0.cols());
  return s;
}

Workspace make_workspace(const Model& model) {
  Workspace ws;
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  ws.f = Eigen::Matrix3Xd::Zero(3, n);
  ws.adjacency = std::make_shared<const SpringAdjacency>(SpringAdjacency::build(model));
  ws.spring_c.assign(model.spring_count(), 0.0);
  for (std::size_t i = 0; i < model.pinned.size(); ++i)
    if (model.pinned[i]) ws.pinned_index.push_back(static_cast<std::uint32_t>(i));
  ws.pinned_x = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(ws.pinned_index.size()));
#ifdef CLOTHSIM_HAVE_COLLISION
  if (model.colliders) ws.contact_hint.assign(model.mass_count() * model.colliders->object_count(), -1);
#endif
  return ws;
}

void add_spring_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) {
  const std::size_t s_count = model.spring_count();
  const std::uint32_t* sa = model.spring_a.data();
  const std::uint32_t* sb = model.spring_b.data();
  const double* rest = model.rest_length0.data();
  const double* k = model.stiffness.data();
  const double* px = x.data();
  double* pf = f.data();
  for (std::size_t s = 0; s < s_count; ++s) {
    const std::size_t a = 3 * std::size_t{sa[s]}, b = 3 * std::size_t{sb[s]};
    const double dx = px[a] - px[b], dy = px[a + 1] - px[b + 1], dz = px[a + 2] - px[b + 2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (len == 0.0) continue;  // coincident ends: no direction, no force
    // eq. 4: f_a = dx/|dx| k (l - |dx|), f_b = -f_a
    const double c = k[s] * (rest[s] - len) / len;
    pf[a] += c * dx;
    pf[a + 1] += c * dy;
    pf[a + 2] += c * dz;
    pf[b] -= c * dx;
    pf[b + 1] -= c * dy;
    pf[b + 2] -= c * dz;
  }
}

namespace {

bool has_adjacency(const Model& model, const Workspace& ws) {
  return ws.adjacency && ws.adjacency->start.size() == model.mass_count() + 1 &&
         ws.spring_c.size() == model.spring_count();
}

// Pass 1 of the gather: c_s = k (l - |dx|) / |dx| per spring, the scatter's arithmetic.
// |dx| = 0 gives c = 0 (the scatter skips such a spring; adding 0 * 0 changes nothing but the
// sign of an exactly -0.0 partial force, which m g - gamma v never produces).
void spring_coefficients(const Model& model, const Eigen::Matrix3Xd& x, std::vector<double>& cs) {
  const auto s_count = static_cast<std::int64_t>(model.spring_count());
  const std::uint32_t* sa = model.spring_a.data();
  const std::uint32_t* sb = model.spring_b.data();
  const double* rest = model.rest_length0.data();
  const double* k = model.stiffness.data();
  const double* px = x.data();
  double* c = cs.data();
  [[maybe_unused]] const int nt = team(cs.size());
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t s = 0; s < s_count; ++s) {
    const std::size_t a = 3 * std::size_t{sa[s]}, b = 3 * std::size_t{sb[s]};
    const double dx = px[a] - px[b], dy = px[a + 1] - px[b + 1], dz = px[a + 2] - px[b + 2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    c[s] = len == 0.0 ? 0.0 : k[s] * (rest[s] - len) / len;
  }
}

// Pass 2: f_i (+)= sum over i's springs, in increasing spring index, of c_s (x_i - x_j).
// For i = b this is c (x_b - x_a) = -(c dx) exactly, so f_b + that == the scatter's f_b - c dx.
// With `base`, f_i starts from m_i g - gamma v_i (the same two roundings as the Eigen form).
template <bool base>
void gather_springs(const Model& model, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd* v,
                    Eigen::Matrix3Xd& f, const Workspace& ws) {
  const SpringAdjacency& adj = *ws.adjacency;
  const auto n = static_cast<std::int64_t>(model.mass_count());
  const std::uint32_t* start = adj.start.data();
  const std::uint32_t* other = adj.other.data();
  const std::uint32_t* spring = adj.spring.data();
  const double* c = ws.spring_c.data();
  const double* px = x.data();
  const double* pv = base ? v->data() : nullptr;
  const double* m = model.mass.data();
  const double g0 = model.options.gravity[0], g1 = model.options.gravity[1], g2 = model.options.gravity[2];
  const double gamma = model.options.damping;
  double* pf = f.data();
  [[maybe_unused]] const int nt = team(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i) {
    const double xi = px[3 * i], yi = px[3 * i + 1], zi = px[3 * i + 2];
    double fx, fy, fz;
    if constexpr (base) {
      fx = g0 * m[i] - gamma * pv[3 * i];
      fy = g1 * m[i] - gamma * pv[3 * i + 1];
      fz = g2 * m[i] - gamma * pv[3 * i + 2];
    } else {
      fx = pf[3 * i], fy = pf[3 * i + 1], fz = pf[3 * i + 2];
    }
    for (std::uint32_t e = start[i], end = start[i + 1]; e < end; ++e) {
      const std::size_t j = 3 * std::size_t{other[e]};
      const double cs = c[spring[e]];
      fx += cs * (xi - px[j]);
      fy += cs * (yi - px[j + 1]);
      fz += cs * (zi - px[j + 2]);
    }
    pf[3 * i] = fx;
    pf[3 * i + 1] = fy;
    pf[3 * i + 2] = fz;
  }
}

}  // namespace

void add_spring_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f,
                       Workspace& ws) {
  if (!has_adjacency(model, ws)) return add_spring_forces(model, x, f);
  spring_coefficients(model, x, ws.spring_c);
  gather_springs<false>(model, x, nullptr, f, ws);
}

void compute_forces(const Model& model, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                    Eigen::Matrix3Xd& f, Workspace& ws) {
  const Options& o = model.options;
  if (has_adjacency(model, ws)) {
    // gravity, the damping of eq. 6 (a = (f - gamma v)/m) and the springs in one pass per mass
    spring_coefficients(model, x, ws.spring_c);
    gather_springs<true>(model, x, &v, f, ws);
  } else {
    f.noalias() = o.gravity * model.mass.transpose() - o.damping * v;
    add_spring_forces(model, x, f);
  }
  ws.last_penetration = 0.0;
  ws.last_contacts = 0;
#ifdef CLOTHSIM_HAVE_COLLISION
  if (model.colliders) {
    PenaltyStats stats;
    accumulate_penalty(*model.colliders, x, o.epsilon, o.k_rep, f, stats,
                       std::span<std::int32_t>(ws.contact_hint));
    ws.last_penetration = stats.max_penetration;
    ws.last_contacts = static_cast<std::uint32_t>(stats.contacts);
  }
#endif
  const Drag& d = ws.drag;
  if (d.mass >= 0 && static_cast<std::size_t>(d.mass) < model.mass_count() && d.k > 0.0)
    f.col(d.mass) += d.k * (d.target - x.col(d.mass));
}

namespace {

bool all_finite(const State& s) {
  // A sum is NaN/inf as soon as one entry is (or the state is absurdly large).
  return std::isfinite(s.x.sum() + s.v.sum());
}

void save_pins(const State& s, Workspace& ws) {
  for (std::size_t p = 0; p < ws.pinned_index.size(); ++p)
    ws.pinned_x.col(static_cast<Eigen::Index>(p)) = s.x.col(ws.pinned_index[p]);
}

void restore_pins(State& s, const Workspace& ws) {
  // Pinned masses keep their exact bits (x + h*0 would turn -0.0 into +0.0).
  for (std::size_t p = 0; p < ws.pinned_index.size(); ++p) {
    s.x.col(ws.pinned_index[p]) = ws.pinned_x.col(static_cast<Eigen::Index>(p));
    s.v.col(ws.pinned_index[p]).setZero();
  }
}

}  // namespace

void step_symplectic_euler(const Model& model, State& state, Workspace& ws) {
  const double h = model.options.dt;
  save_pins(state, ws);
  const auto n = static_cast<std::int64_t>(model.mass_count());
  double* px = state.x.data();
  double* pv = state.v.data();
  const double* pf = ws.f.data();
  const double* im = model.inv_mass.data();
  [[maybe_unused]] const int nt = team(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t e = 0; e < 3 * n; ++e) px[e] += h * pv[e];  // eq. 1
  compute_forces(model, state.x, state.v, ws.f, ws);            // eqs. 2-5 at x(t+h)
  // eqs. 6-7 (damping is in f): v += h (f / m), as h * (f * (1/m))
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i)
    for (std::int64_t r = 0; r < 3; ++r) pv[3 * i + r] += h * (pf[3 * i + r] * im[i]);
  restore_pins(state, ws);
}

StepStatus step(const Model& model, State& state, Workspace& ws) {
  ws.drag = state.drag;
  switch (model.options.integrator) {
    case Integrator::SymplecticEuler:
      step_symplectic_euler(model, state, ws);
      break;
    default:  // the other integrators (integrators.cpp, issue 5)
      integrate(model, state, ws);
      break;
  }
  state.t += model.options.dt;
  ++state.steps;
  state.max_penetration = std::max(state.max_penetration, ws.last_penetration);
  return StepStatus{all_finite(state)};
}

double kinetic_energy(const Model& model, const State& state) {
  double e = 0.0;
  for (Eigen::Index i = 0; i < state.v.cols(); ++i)
    if (!model.pinned[static_cast<std::size_t>(i)]) e += 0.5 * model.mass[i] * state.v.col(i).squaredNorm();
  return e;
}

double gershgorin_omega_max(const Model& model) {
  const std::size_t n = model.mass_count();
  std::vector<double> ksum(n, model.colliders ? model.options.k_rep : 0.0);
  for (std::size_t s = 0; s < model.spring_count(); ++s) {
    ksum[model.spring_a[s]] += model.stiffness[static_cast<Eigen::Index>(s)];
    ksum[model.spring_b[s]] += model.stiffness[static_cast<Eigen::Index>(s)];
  }
  double w2 = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    if (!model.pinned[i]) w2 = std::max(w2, 2.0 * ksum[i] / model.mass[static_cast<Eigen::Index>(i)]);
  return std::sqrt(w2);
}

std::uint64_t state_hash(const State& state) {
  std::uint64_t h = 14695981039346656037ull;
  auto mix = [&h](const double* p, Eigen::Index count) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < static_cast<std::size_t>(count) * sizeof(double); ++i) {
      h ^= bytes[i];
      h *= 1099511628211ull;
    }
  };
  mix(state.x.data(), state.x.size());
  mix(state.v.data(), state.v.size());
  return h;
}

std::string validate_options(const Options& o) {
  auto num = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  auto positive = [&](const char* name, double v) -> std::string {
    if (std::isfinite(v) && v > 0.0) return {};
    return std::string(name) + " must be a finite number > 0 (got " + num(v) + ")";
  };
  auto non_negative = [&](const char* name, double v) -> std::string {
    if (std::isfinite(v) && v >= 0.0) return {};
    return std::string(name) + " must be a finite number >= 0 (got " + num(v) + ")";
  };
  for (const std::string& why : {positive("dt", o.dt), positive("mass", o.mass), non_negative("k_struct", o.k_struct),
                                 non_negative("k_bend", o.k_bend), non_negative("damping", o.damping),
                                 positive("epsilon", o.epsilon), non_negative("k_rep", o.k_rep)})
    if (!why.empty()) return why;
  if (!o.gravity.allFinite()) return "gravity must be finite";
  return {};
}

}  // namespace clothsim
