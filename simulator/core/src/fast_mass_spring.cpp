// Fast mass-spring (Liu, Bargteil, O'Brien, Kavan 2013): implicit Euler by local/global
// iterations with a prefactored sparse Cholesky, refactored when dt or stiffness change.
#include "integrator_scratch.hpp"
#include "stages.hpp"

#include <vector>

namespace clothsim::detail {

namespace {

void fms_precompute(const Model& m, IntegratorScratch& sc, double h) {
  // (M + h gamma + h^2 L) over the free masses, L = sum_s k_s (e_a - e_b)(e_a - e_b)^T.
  // Damping is implicit too: explicit damping is unstable for light masses (h gamma / m > 2).
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(m.mass_count() + 4 * m.spring_count());
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (sc.compact[i] >= 0)
      t.emplace_back(sc.compact[i], sc.compact[i], m.mass[static_cast<Eigen::Index>(i)] + h * m.damping_of(i));
  const double h2 = h * h;
  double ksum = m.damping + m.drag;  // the key: damping is in the matrix too
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

}  // namespace

void fast_mass_spring(const Model& m, State& s, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  double ksum = m.damping + m.drag;
  for (std::size_t k = 0; k < m.spring_count(); ++k) ksum += m.spring_stiffness(k);
  if (sc.llt_h != h || sc.llt_ksum != ksum) fms_precompute(m, sc, h);
  // External forces = everything but the springs and the damping (gravity, contact, drag),
  // explicit. The force stage's damping is -gamma v (step.hpp), added back here.
  compute_forces(m, s.x, s.v, ws.f, ws);
  sc.f2.setZero();
  add_spring_forces(m, s.x, sc.f2);
  sc.fext = ws.f - sc.f2;
  for (Eigen::Index i = 0; i < s.v.cols(); ++i) sc.fext.col(i) += m.damping_of(static_cast<std::size_t>(i)) * s.v.col(i);
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
        sc.b.row(sc.compact[i]) = (m.mass[c] * sc.y.col(c) + h * m.damping_of(i) * s.x.col(c)).transpose();
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


}  // namespace clothsim::detail
