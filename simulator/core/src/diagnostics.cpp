// What a run reports about a state and a model: kinetic energy, a stability estimate, a hash.
#include <clothsim/step.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace clothsim {

double kinetic_energy(const Model& model, const State& state) {
  double e = 0.0;
  for (Eigen::Index i = 0; i < state.v.cols(); ++i)
    if (!model.pinned[static_cast<std::size_t>(i)]) e += 0.5 * model.mass[i] * state.v.col(i).squaredNorm();
  return e;
}

double max_strain(const Model& model, const Eigen::Matrix3Xd& x) {
  double worst = 0.0;
  for (std::size_t s = 0; s < model.spring_count(); ++s) {
    const double rest = model.rest_length0[static_cast<Eigen::Index>(s)];
    if (model.spring_kind[s] != 0 || !(rest > 0.0)) continue;
    worst = std::max(worst, (x.col(model.spring_a[s]) - x.col(model.spring_b[s])).norm() / rest - 1.0);
  }
  return worst;
}

double gershgorin_omega_max(const Model& model) {
  const std::size_t n = model.mass_count();
  std::vector<double> ksum(n, model.colliders ? model.contact.k_rep : 0.0);
  for (std::size_t s = 0; s < model.spring_count(); ++s) {
    ksum[model.spring_a[s]] += model.spring_stiffness(s);
    ksum[model.spring_b[s]] += model.spring_stiffness(s);
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

}  // namespace clothsim
