// XPBD with small steps (Macklin, Mueller, Chentanez 2016; Macklin et al. 2019): per step the
// velocities take gravity, the bend springs and the user's pull explicitly (the bend springs
// are soft: the stability guard keeps the step under their limit), and the damping implicitly;
// the positions are predicted; one Gauss-Seidel pass treats every structural spring as a
// compliant distance constraint (alpha = 1/k, lambda from 0); the colliders push the points
// out to the contact distance, with Coulomb friction on the move (Macklin et al. 2014); the
// velocities are the positions' change. The pass goes colour by colour: no two springs of a
// colour share a mass, so a colour splits between threads, and goes four springs at a time in
// AVX2 (xpbd_avx2.cpp), with the same result for any thread count and either way.
#include "integrator_scratch.hpp"
#include "parallel.hpp"
#include "stages.hpp"
#include "xpbd_links.hpp"

#include <algorithm>
#include <cstdint>

namespace clothsim::detail {

namespace {

// Runs run(links, count, wide) over every colour's links, each colour split between threads;
// wide when no two of the links share a mass (the last colour may).
template <class Run>
void by_colour(const Colouring& c, const Workspace& ws, Run run) {
  const std::size_t colours = c.start.size() - 1;
  for (std::size_t k = 0; k < colours; ++k) {
    const std::size_t begin = c.start[k], count = c.start[k + 1] - begin;
    if (k + 1 == colours) {
      run(c.links.data() + begin, count, false);
      continue;
    }
    parallel_region(team(ws, count), [&](int t, int parts) {
      const std::size_t i0 = count * static_cast<std::size_t>(t) / static_cast<std::size_t>(parts);
      const std::size_t i1 = count * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(parts);
      run(c.links.data() + begin + i0, i1 - i0, true);
    });
  }
}

// Every structural spring projected once, colour by colour.
void project_all(const Colouring& c, const Workspace& ws, const double* w, double inv_h2, double* x) {
  by_colour(c, ws, [&](const Link* l, std::size_t n, bool wide) {
#ifdef CLOTHSIM_AVX2
    if (wide && use_avx2()) return project_links_avx2(l, n, w, inv_h2, x);
#endif
    (void)wide;
    for (std::size_t j = 0; j < n; ++j) project(l[j], w, inv_h2, x);
  });
}

// Every bend spring's pull on the velocities over h, colour by colour.
void bend_all(const Colouring& c, const Workspace& ws, const double* w, double h, const double* x, double* v) {
  by_colour(c, ws, [&](const Link* l, std::size_t n, bool wide) {
#ifdef CLOTHSIM_AVX2
    if (wide && use_avx2()) return bend_links_avx2(l, n, w, h, x, v);
#endif
    (void)wide;
    for (std::size_t j = 0; j < n; ++j) bend(l[j], w, h, x, v);
  });
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
  bend_all(sc.bend, ws, w, h, s.x.data(), s.v.data());
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
  project_all(sc.structural, ws, w, 1.0 / (h * h), x.data());
}

void xpbd(const Model& m, State& s, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  if (sc.bend.start.empty()) sc.structural = colour_springs(m, 0), sc.bend = colour_springs(m, 1);  // (once)
  predict(m, s, sc, ws, h);
  project_all(sc.structural, ws, m.inv_mass.data(), 1.0 / (h * h), s.x.data());
  keep_in_reach(m, s.x, ws);
  push_out(m, s, sc, ws, h);
}

}  // namespace clothsim::detail
