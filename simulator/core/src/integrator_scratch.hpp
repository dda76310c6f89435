// The scratch memory of the integrators other than symplectic Euler (integrators.hpp), sized
// once per Model; the implicit solvers keep their factorization here.
#pragma once

#include <clothsim/integrators.hpp>

#include "spring_colouring.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
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
  // XPBD: each kind's springs by colour, made on first use
  detail::Colouring structural, bend;
  ImplicitSettings settings;
  ImplicitStats stats;
};


}  // namespace clothsim
