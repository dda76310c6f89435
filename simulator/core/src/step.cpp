// Forces and time integration (report eqs. 1-7). Nothing here allocates after make_workspace().
#include <clothsim/step.hpp>
#include <clothsim/integrators.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>

#ifdef CLOTHSIM_HAVE_COLLISION
#include <clothsim/collision.hpp>
#endif

namespace clothsim {

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

void compute_forces(const Model& model, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                    Eigen::Matrix3Xd& f, Workspace& ws) {
  const Options& o = model.options;
  // gravity and the damping of eq. 6 (a = (f - gamma v)/m)
  f.noalias() = o.gravity * model.mass.transpose() - o.damping * v;
  add_spring_forces(model, x, f);
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
  state.x.noalias() += h * state.v;                    // eq. 1
  compute_forces(model, state.x, state.v, ws.f, ws);   // eqs. 2-5 at x(t+h)
  state.v.noalias() +=                                 // eqs. 6-7 (damping is in f)
      h * (ws.f.array().rowwise() * model.inv_mass.transpose().array()).matrix();
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
