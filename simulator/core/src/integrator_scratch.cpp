// Sizes the integrators' scratch once per Model.
#include "integrator_scratch.hpp"

#include <clothsim/step.hpp>

namespace clothsim {

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

}  // namespace clothsim
