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

// Greedy edge colouring of the springs, in spring order; a spring that finds none of 63
// colours free goes to a last colour that the pass takes on one thread.
void colour_springs(const Model& m, IntegratorScratch& sc) {
  constexpr int kSerial = 63;
  std::vector<std::uint64_t> used(m.mass_count(), 0);
  std::vector<std::uint8_t> colour(m.spring_count());
  std::vector<std::uint32_t> count(kSerial + 1, 0);
  for (std::size_t s = 0; s < m.spring_count(); ++s) {
    if (m.spring_kind[s] != 0) continue;  // (the bend springs are forces)
    const std::uint64_t taken = used[m.spring_a[s]] | used[m.spring_b[s]];
    const int c = ~taken & ((std::uint64_t{1} << kSerial) - 1) ? __builtin_ctzll(~taken) : kSerial;
    colour[s] = static_cast<std::uint8_t>(c);
    if (c < kSerial) used[m.spring_a[s]] |= std::uint64_t{1} << c, used[m.spring_b[s]] |= std::uint64_t{1} << c;
    ++count[static_cast<std::size_t>(c)];
  }
  sc.colour_start.assign(kSerial + 2, 0);
  for (int c = 0; c <= kSerial; ++c) sc.colour_start[static_cast<std::size_t>(c) + 1] = sc.colour_start[static_cast<std::size_t>(c)] + count[static_cast<std::size_t>(c)];
  sc.colour_springs.resize(sc.colour_start.back());
  std::vector<std::uint32_t> fill(sc.colour_start.begin(), sc.colour_start.end() - 1);
  for (std::size_t s = 0; s < m.spring_count(); ++s)
    if (m.spring_kind[s] == 0) sc.colour_springs[fill[colour[s]]++] = static_cast<std::uint32_t>(s);
}

// One spring as a compliant distance constraint (lambda from 0): alpha~ = 1 / (k h^2).
inline void project_spring(const Model& m, std::uint32_t s, double inv_h2, double* x) {
  const std::uint32_t a = m.spring_a[s], b = m.spring_b[s];
  const double wa = m.inv_mass[a], wb = m.inv_mass[b], k = m.spring_stiffness(s);
  if (!(k > 0.0) || wa + wb == 0.0) return;
  double* pa = x + 3 * std::size_t{a};
  double* pb = x + 3 * std::size_t{b};
  const double dx = pa[0] - pb[0], dy = pa[1] - pb[1], dz = pa[2] - pb[2];
  const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (len == 0.0) return;  // no direction: no correction (as the force stage)
  const double c = len - m.rest_length0[static_cast<Eigen::Index>(s)];
  const double scale = -c / (wa + wb + inv_h2 / k) / len;
  pa[0] += wa * scale * dx, pa[1] += wa * scale * dy, pa[2] += wa * scale * dz;
  pb[0] -= wb * scale * dx, pb[1] -= wb * scale * dy, pb[2] -= wb * scale * dz;
}

// The bend springs' pull on the velocities (report eq. 4), spring by spring.
void bend_forces(const Model& m, State& s, double h) {
  const double* x = s.x.data();
  double* v = s.v.data();
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    if (m.spring_kind[k] == 0) continue;
    const std::size_t a = m.spring_a[k], b = m.spring_b[k];
    const double dx = x[3 * a] - x[3 * b], dy = x[3 * a + 1] - x[3 * b + 1], dz = x[3 * a + 2] - x[3 * b + 2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (len == 0.0) continue;
    const double c = h * m.spring_stiffness(k) * (m.rest_length0[static_cast<Eigen::Index>(k)] - len) / len;
    const double ca = c * m.inv_mass[static_cast<Eigen::Index>(a)], cb = c * m.inv_mass[static_cast<Eigen::Index>(b)];
    v[3 * a] += ca * dx, v[3 * a + 1] += ca * dy, v[3 * a + 2] += ca * dz;
    v[3 * b] -= cb * dx, v[3 * b + 1] -= cb * dy, v[3 * b + 2] -= cb * dz;
  }
}

// The velocities: gravity, the bend springs and the user's pull explicitly, the damping
// implicitly (v <- (v + h a) / (1 + h gamma / m): stable for any step).
void take_forces(const Model& m, State& s, const Workspace& ws, double h) {
  bend_forces(m, s, h);
  const auto n = static_cast<std::int64_t>(m.mass_count());
  [[maybe_unused]] const int nt = team(ws, m.mass_count());
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i) {
    const double im = m.inv_mass[i];
    if (im == 0.0) continue;
    const double rate = m.damping_of(static_cast<std::size_t>(i)) * im;
    s.v.col(i) = (s.v.col(i) + h * m.gravity) / (1.0 + h * rate);
  }
  const Drag& d = ws.drag;
  if (d.mass >= 0 && static_cast<std::size_t>(d.mass) < m.mass_count() && d.k > 0.0 && m.inv_mass[d.mass] > 0.0) {
    const Eigen::Vector3d pull = d.target - s.x.col(d.mass);
    const double len = pull.norm();
    s.v.col(d.mass) += h * m.inv_mass[d.mass] * d.k * (len > d.reach ? (d.reach / len) * pull : pull);
  }
}

// The springs, colour by colour.
void project_springs(const Model& m, const IntegratorScratch& sc, const Workspace& ws, double h, double* x) {
  const double inv_h2 = 1.0 / (h * h);
  const std::size_t colours = sc.colour_start.size() - 1;
  for (std::size_t c = 0; c < colours; ++c) {
    const auto begin = static_cast<std::int64_t>(sc.colour_start[c]), end = static_cast<std::int64_t>(sc.colour_start[c + 1]);
    const bool serial = c + 1 == colours;  // (the last colour may share masses)
    [[maybe_unused]] const int nt = serial ? 1 : team(ws, static_cast<std::size_t>(end - begin));
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
    for (std::int64_t j = begin; j < end; ++j) project_spring(m, sc.colour_springs[static_cast<std::size_t>(j)], inv_h2, x);
  }
}

// The colliders' pushes, with Coulomb friction on the step's tangential move: it is undone
// when shorter than static_friction times the push, else shortened by friction times it.
void push_out(const Model& m, State& s, IntegratorScratch& sc, Workspace& ws) {
  if (!m.colliders) return;
  sc.f2.setZero();
  add_contact_push(m, s.x, sc.f2, ws);
  const double mu_s = m.contact.static_friction, mu_k = m.contact.friction;
  const auto n = static_cast<std::int64_t>(m.mass_count());
  [[maybe_unused]] const int nt = team(ws, m.mass_count());
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i) {
    const Eigen::Vector3d push = sc.f2.col(i);
    const double depth = push.norm();
    if (!(depth > 0.0) || m.inv_mass[i] == 0.0) continue;
    s.x.col(i) += push;
    const Eigen::Vector3d nrm = push / depth;
    const Eigen::Vector3d move = s.x.col(i) - sc.xs.col(i);
    const Eigen::Vector3d tangent = move - nrm.dot(move) * nrm;
    const double slide = tangent.norm();
    if (slide <= mu_s * depth) s.x.col(i) -= tangent;
    else s.x.col(i) -= std::min(1.0, mu_k * depth / slide) * tangent;
  }
}

}  // namespace

void xpbd(const Model& m, State& s, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  if (sc.colour_start.empty()) colour_springs(m, sc);  // (once per Workspace)
  take_forces(m, s, ws, h);
  sc.xs = s.x;  // x(t)
  s.x.noalias() += h * s.v;
  project_springs(m, sc, ws, h, s.x.data());
  push_out(m, s, sc, ws);
  s.v = (s.x - sc.xs) / h;
}

}  // namespace clothsim::detail
