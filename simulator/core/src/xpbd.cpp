// XPBD with small steps (Macklin, Mueller, Chentanez 2016; Macklin et al. 2019): per step the
// velocities take gravity, the bend springs and the user's pull explicitly (the bend springs
// are soft: the stability guard keeps the step under their limit), and the damping implicitly;
// the positions are predicted; one Gauss-Seidel pass treats every structural spring as a
// compliant distance constraint (alpha = 1/k, lambda from 0); the colliders push the points
// out to the contact distance, with Coulomb friction on the move (Macklin et al. 2014); the
// velocities are the positions' change. The pass goes colour by colour: no two springs of a
// colour share a mass, so a colour splits between threads and the result is the same for any
// count.
#include "integrator_scratch.hpp"
#include "parallel.hpp"
#include "stages.hpp"

#include <algorithm>
#include <cstdint>

namespace clothsim::detail {

namespace {


// Runs one(link) over every link, colour by colour, each colour split between threads.
template <class One>
void by_colour(const Colouring& c, const Workspace& ws, One one) {
  const std::size_t colours = c.start.size() - 1;
  for (std::size_t k = 0; k < colours; ++k) {
    const auto begin = static_cast<std::int64_t>(c.start[k]), end = static_cast<std::int64_t>(c.start[k + 1]);
    const bool serial = k + 1 == colours;  // (the last colour may share masses)
    const int nt = serial ? 1 : team(ws, static_cast<std::size_t>(end - begin));
    parallel_for(nt, end - begin, [&](std::int64_t j) { one(c.links[static_cast<std::size_t>(begin + j)]); });
  }
}

// One structural spring as a compliant distance constraint (lambda from 0): alpha~ = 1/(k h^2).
inline void project(const Link& l, const double* w, double inv_h2, double* x) {
  double* pa = x + 3 * std::size_t{l.a};
  double* pb = x + 3 * std::size_t{l.b};
  const double wa = w[l.a], wb = w[l.b];
  const double dx = pa[0] - pb[0], dy = pa[1] - pb[1], dz = pa[2] - pb[2];
  const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (len == 0.0) return;  // no direction: no correction (as the force stage)
  const double scale = (l.rest - len) / (wa + wb + inv_h2 / l.k) / len;
  pa[0] += wa * scale * dx, pa[1] += wa * scale * dy, pa[2] += wa * scale * dz;
  pb[0] -= wb * scale * dx, pb[1] -= wb * scale * dy, pb[2] -= wb * scale * dz;
}

// One bend spring's pull on the velocities over h (report eq. 4).
inline void bend(const Link& l, const double* w, double h, const double* x, double* v) {
  const std::size_t a = 3 * std::size_t{l.a}, b = 3 * std::size_t{l.b};
  const double dx = x[a] - x[b], dy = x[a + 1] - x[b + 1], dz = x[a + 2] - x[b + 2];
  const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (len == 0.0) return;
  const double c = h * l.k * (l.rest - len) / len, ca = c * w[l.a], cb = c * w[l.b];
  v[a] += ca * dx, v[a + 1] += ca * dy, v[a + 2] += ca * dz;
  v[b] -= cb * dx, v[b + 1] -= cb * dy, v[b + 2] -= cb * dz;
}

// The user's pull on the dragged mass, over h.
void pull(const Model& m, State& s, const Workspace& ws, double h) {
  const Drag& d = ws.drag;
  if (d.mass < 0 || static_cast<std::size_t>(d.mass) >= m.mass_count() || !(d.k > 0.0) || m.inv_mass[d.mass] == 0.0)
    return;
  const Eigen::Vector3d to = d.target - s.x.col(d.mass);
  const double len = to.norm();
  s.v.col(d.mass) += h * m.inv_mass[d.mass] * d.k * (len > d.reach ? (d.reach / len) * to : to);
}

// The velocities take the bend springs, the pull, gravity and the damping (implicitly:
// v <- (v + h g) / (1 + h gamma / m), stable for any step); the positions are predicted.
void predict(const Model& m, State& s, IntegratorScratch& sc, const Workspace& ws, double h) {
  const double* w = m.inv_mass.data();
  by_colour(sc.bend, ws, [&](const Link& l) { bend(l, w, h, s.x.data(), s.v.data()); });
  pull(m, s, ws, h);
  const bool contact = m.colliders != nullptr;
  const auto n = static_cast<std::int64_t>(m.mass_count());
  parallel_for(team(ws, m.mass_count()), n, [&](std::int64_t i) {
    if (w[i] != 0.0) s.v.col(i) = (s.v.col(i) + h * m.gravity) / (1.0 + h * m.damping_of(static_cast<std::size_t>(i)) * w[i]);
    sc.xs.col(i) = s.x.col(i);
    s.x.col(i) += h * s.v.col(i);
    if (contact) sc.f2.col(i).setZero();
  });
}

// The colliders' pushes, with Coulomb friction on the step's tangential move (it is undone
// when shorter than static_friction times the push, else shortened by friction times it);
// then the velocities are the positions' change.
void push_out(const Model& m, State& s, IntegratorScratch& sc, Workspace& ws, double h) {
  const bool contact = m.colliders != nullptr;
  if (contact) add_contact_push(m, s.x, sc.f2, ws);
  const double mu_s = m.contact.static_friction, mu_k = m.contact.friction;
  const auto n = static_cast<std::int64_t>(m.mass_count());
  parallel_for(team(ws, m.mass_count()), n, [&](std::int64_t i) {
    const double depth = contact ? sc.f2.col(i).norm() : 0.0;
    if (!ws.held.empty()) ws.held[static_cast<std::size_t>(i)] = depth > 0.0;
    if (depth > 0.0 && m.inv_mass[i] != 0.0) {
      const Eigen::Vector3d nrm = sc.f2.col(i) / depth;
      s.x.col(i) += sc.f2.col(i);
      const Eigen::Vector3d move = s.x.col(i) - sc.xs.col(i);
      const Eigen::Vector3d tangent = move - nrm.dot(move) * nrm;
      const double slide = tangent.norm();
      s.x.col(i) -= slide <= mu_s * depth ? 1.0 * tangent : std::min(1.0, mu_k * depth / slide) * tangent;
    }
    s.v.col(i) = (s.x.col(i) - sc.xs.col(i)) / h;
  });
}

}  // namespace

void relax_structural(const Model&, Eigen::Matrix3Xd& x, const double* w, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  const double inv_h2 = 1.0 / (h * h);
  double* p = x.data();
  by_colour(sc.structural, ws, [&](const Link& l) { project(l, w, inv_h2, p); });
}

void xpbd(const Model& m, State& s, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  if (sc.bend.start.empty()) sc.structural = colour_springs(m, 0), sc.bend = colour_springs(m, 1);  // (once)
  predict(m, s, sc, ws, h);
  const double inv_h2 = 1.0 / (h * h);
  const double* w = m.inv_mass.data();
  double* x = s.x.data();
  by_colour(sc.structural, ws, [&](const Link& l) { project(l, w, inv_h2, x); });
  keep_in_reach(m, s.x, ws);
  push_out(m, s, sc, ws, h);
}

}  // namespace clothsim::detail
