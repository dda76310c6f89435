// The stability guard's eigenvalue estimate (omega_max_lanczos) against a dense eigensolver,
// and its iteration count on a large cloth (a power iteration needs thousands).
#include <clothsim/model_builder.hpp>
#include <clothsim/stability.hpp>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <iostream>

#include "inline_scenes.hpp"

namespace clothsim {
namespace {

// omega_max of the linearised springs by a dense eigensolver: K from the spring blocks
// k (n n^T + max(0, 1 - L0/len) (I - n n^T)), restricted to free masses, scaled by M^-1/2.
double dense_omega_max(const Model& m, const Eigen::Matrix3Xd& x) {
  const auto n = static_cast<Eigen::Index>(m.mass_count());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (std::size_t s = 0; s < m.spring_count(); ++s) {
    const Eigen::Index a = m.spring_a[s], b = m.spring_b[s];
    const double k = m.spring_kind[s] == 0 ? m.options.k_struct : m.options.k_bend;
    const Eigen::Vector3d e = x.col(a) - x.col(b);
    const double len = e.norm();
    const Eigen::Vector3d u = e / len;
    const Eigen::Matrix3d nn = u * u.transpose();
    const double c = std::max(0.0, 1.0 - m.rest_length0[static_cast<Eigen::Index>(s)] / len);
    const Eigen::Matrix3d B = k * (nn + c * (Eigen::Matrix3d::Identity() - nn));
    K.block<3, 3>(3 * a, 3 * a) += B;
    K.block<3, 3>(3 * b, 3 * b) += B;
    K.block<3, 3>(3 * a, 3 * b) -= B;
    K.block<3, 3>(3 * b, 3 * a) -= B;
  }
  Eigen::VectorXd s(3 * n);
  for (Eigen::Index i = 0; i < n; ++i)
    s.segment<3>(3 * i).setConstant(m.pinned[static_cast<std::size_t>(i)] ? 0.0 : 1.0 / std::sqrt(m.mass[i]));
  const Eigen::MatrixXd A = s.asDiagonal() * K * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A, Eigen::EigenvaluesOnly);
  return std::sqrt(es.eigenvalues().maxCoeff());
}

TEST(StabilityGuard, LanczosMatchesADenseEigensolver) {
  Options o = seed_options();
  o.k_struct = 700.0;
  o.k_bend = 90.0;
  Model m = test::grid_model(o, 14, 11, {0u, 13u});
  // masses from 0.001 to 1 kg (an ill-conditioned M), deterministic
  std::uint64_t seed = 77;
  for (Eigen::Index i = 0; i < m.mass.size(); ++i) {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    m.mass[i] = std::pow(10.0, -3.0 * static_cast<double>(seed >> 11) * 0x1.0p-53);
    if (!m.pinned[static_cast<std::size_t>(i)]) m.inv_mass[i] = 1.0 / m.mass[i];
  }
  // at rest and stretched by 10 % (the transverse terms switch on)
  for (double stretch : {1.0, 1.1}) {
    const Eigen::Matrix3Xd x = stretch * m.x0;
    const OmegaEstimate est = omega_max_lanczos(m, &x);
    const double ref = dense_omega_max(m, x);
    EXPECT_NEAR(est.omega / ref, 1.0, 1e-9) << "stretch " << stretch;
    EXPECT_LE(est.omega, ref * (1.0 + 1e-12)) << "a Ritz value never exceeds lambda_max";
    EXPECT_LT(est.residual, 1e-7);
    EXPECT_LE(est.omega, omega_max_bound(m, false) * (1.0 + 1e-12));
  }
}

TEST(StabilityGuard, LanczosConvergesInAFewHundredIterationsOnA128x128Cloth) {
  Options o = seed_options();
  o.mass = 2e-4;
  const Model m = test::grid_model(o, 128, 128, {0u, 127u});
  const OmegaEstimate est = omega_max_lanczos(m);
  EXPECT_LE(est.iterations, 400);
  EXPECT_GT(est.omega, 0.0);
  EXPECT_LE(est.omega, omega_max_bound(m, false) * (1.0 + 1e-12));
  // converged: a tighter run (more iterations) moves it by less than 1e-6
  const OmegaEstimate tight = omega_max_lanczos(m, nullptr, 2000, 1e-11);
  std::cout << "128 x 128: " << est.iterations << " Lanczos iterations (residual " << est.residual
            << "), " << tight.iterations << " to residual 1e-11\n";
  EXPECT_NEAR(est.omega / tight.omega, 1.0, 1e-6);
  EXPECT_GE(tight.omega, est.omega * (1.0 - 1e-12));
}

// Lanczos stopped by its cap before converging: its Ritz value may be short of omega_max, so
// the guard takes Gershgorin's safe bound for the springs instead, and says so.
TEST(StabilityGuard, UnconvergedLanczosFallsBackToTheSafeBound) {
  Options o = seed_options();
  o.mass = 2e-4;
  const Model m = test::grid_model(o, 64, 64, {0u, 63u});
  const OmegaEstimate few = omega_max_lanczos(m, nullptr, 3);
  EXPECT_FALSE(few.converged);
  const StabilityReport capped = analyse_stability(m, 3);
  EXPECT_TRUE(capped.springs_by_bound);
  EXPECT_EQ(capped.omega_springs, omega_max_bound(m, false));
  EXPECT_NE(describe(capped, Integrator::SymplecticEuler).find("Lanczos did not converge"), std::string::npos);
  const StabilityReport full = analyse_stability(m);
  EXPECT_FALSE(full.springs_by_bound);
  EXPECT_TRUE(omega_max_lanczos(m).converged);
  EXPECT_GE(capped.omega_springs, full.omega_springs);  // safe: never a larger step
  EXPECT_LE(capped.dt_stable, full.dt_stable);
}

}  // namespace
}  // namespace clothsim
