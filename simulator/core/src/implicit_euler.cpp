// Implicit Euler (Baraff & Witkin 1998): one Newton step, (M + h gamma + h^2 K) dv =
// h (f - h K v), matrix-free block-Jacobi CG; contact stays explicit.
#include "integrator_scratch.hpp"
#include "stages.hpp"

#include <Eigen/Dense>
#include <algorithm>

namespace clothsim::detail {

namespace {

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
  const double h2 = h * h;
  for (Eigen::Index i = 0; i < p.cols(); ++i)
    y.col(i) = (m.mass[i] + h * m.damping_of(static_cast<std::size_t>(i))) * p.col(i);
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    const Eigen::Vector3d t = h2 * (sc.spring_k[k] * (p.col(m.spring_a[k]) - p.col(m.spring_b[k])));
    y.col(m.spring_a[k]) += t;
    y.col(m.spring_b[k]) -= t;
  }
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (m.pinned[i]) y.col(static_cast<Eigen::Index>(i)).setZero();
}

}  // namespace

void implicit_euler(const Model& m, State& s, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  compute_forces(m, s.x, s.v, ws.f, ws);  // penalty contact stays explicit (in f)
  spring_jacobians(m, s.x, sc);
  const double h2 = h * h;
  // block-Jacobi preconditioner
  for (Eigen::Index i = 0; i < s.x.cols(); ++i)
    sc.precond[static_cast<std::size_t>(i)] =
        (m.mass[i] + h * m.damping_of(static_cast<std::size_t>(i))) * Eigen::Matrix3d::Identity();
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    sc.precond[m.spring_a[k]] += h2 * sc.spring_k[k];
    sc.precond[m.spring_b[k]] += h2 * sc.spring_k[k];
  }
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    sc.precond[i] = m.pinned[i] ? Eigen::Matrix3d::Zero() : Eigen::Matrix3d(sc.precond[i].inverse());
  // rhs = h (f - h K v), with -h^2 K v = (M + h gamma) v - A v.
  apply_system(m, sc, h, s.v, sc.ap);
  for (Eigen::Index i = 0; i < s.x.cols(); ++i) {
    const double mi = m.pinned[static_cast<std::size_t>(i)] ? 0.0 : m.mass[i] + h * m.damping_of(static_cast<std::size_t>(i));
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


}  // namespace clothsim::detail
