#include <clothsim/material.hpp>
#include <clothsim/model_builder.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>
#include <stdexcept>

namespace clothsim {

namespace {

// Pins that turn (Model::pin_origin, pin_axis): the groups of pinned masses (connected along
// the structural springs, by union-find), each group's centre and its cloth's centre.
void pin_spin_axes(Model& m) {
  const std::size_t n = m.mass_count();
  std::vector<std::uint32_t> root(n);
  std::iota(root.begin(), root.end(), 0u);
  const auto find = [&root](std::uint32_t i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  for (std::size_t s = 0; s < m.spring_count(); ++s)
    if (m.spring_kind[s] == 0 && m.pinned[m.spring_a[s]] && m.pinned[m.spring_b[s]]) {
      const std::uint32_t a = find(m.spring_a[s]), b = find(m.spring_b[s]);
      root[std::max(a, b)] = std::min(a, b);
    }
  Eigen::Matrix3Xd sum = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(n));
  std::vector<double> count(n, 0.0);
  std::vector<Eigen::Index> pins;
  for (std::size_t i = 0; i < n; ++i)
    if (m.pinned[i]) {
      const std::uint32_t r = find(static_cast<std::uint32_t>(i));
      sum.col(r) += m.x0.col(static_cast<Eigen::Index>(i));
      count[r] += 1.0;
      pins.push_back(static_cast<Eigen::Index>(i));
    }
  m.pin_origin = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(pins.size()));
  m.pin_axis = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(pins.size()));
  for (const ClothRange& c : m.cloths) {
    if (c.mass_count == 0) continue;
    const Eigen::Vector3d centre = m.x0.middleCols(c.first_mass, c.mass_count).rowwise().mean();
    for (std::size_t p = 0; p < pins.size(); ++p) {
      const auto i = static_cast<std::uint32_t>(pins[p]);
      if (i < c.first_mass || i - c.first_mass >= c.mass_count) continue;
      const std::uint32_t r = find(i);
      const Eigen::Vector3d out = sum.col(r) / count[r] - centre;
      const double len = out.norm();
      const auto q = static_cast<Eigen::Index>(p);
      m.pin_origin.col(q) = centre;
      // (a group centred on its cloth's centre has no outward axis: it stays put)
      m.pin_axis.col(q) = len > 1e-9 ? Eigen::Vector3d(out / len) : Eigen::Vector3d::Zero();
    }
  }
}

}  // namespace

ModelBuilder::ModelBuilder(const Options& options, std::string scene_name) {
  model_.options = options;
  model_.scene_name = std::move(scene_name);
  model_.x0.resize(3, 0);
}

std::size_t ModelBuilder::add_cloth(const Eigen::Matrix3Xd& positions,
                                    std::span<const SpringSpec> springs,
                                    std::span<const std::uint32_t> pins, std::span<const std::uint32_t> triangles,
                                    std::int32_t scene_cloth) {
  const auto k = static_cast<std::uint32_t>(positions.cols());
  const std::string which = "cloth " + std::to_string(model_.cloths.size());
  if (!positions.allFinite()) throw std::invalid_argument(which + ": a rest position is not finite");
  for (const auto& s : springs) {
    if (s.a >= k || s.b >= k)
      throw std::invalid_argument(which + ": spring " + std::to_string(s.a) + "-" + std::to_string(s.b) +
                                  " names a mass >= " + std::to_string(k));
    if (s.a == s.b) throw std::invalid_argument(which + ": spring joins mass " + std::to_string(s.a) + " to itself");
    if (s.kind > 1) throw std::invalid_argument(which + ": spring kind must be 0 or 1");
  }
  for (auto p : pins)
    if (p >= k) throw std::invalid_argument(which + ": pin " + std::to_string(p) + " names no mass");
  if (triangles.size() % 3 != 0) throw std::invalid_argument(which + ": triangles need 3 indices each");
  for (auto t : triangles)
    if (t >= k) throw std::invalid_argument(which + ": a triangle names mass " + std::to_string(t) + " >= " + std::to_string(k));

  ClothRange r;
  r.first_mass = static_cast<std::uint32_t>(model_.x0.cols());
  r.mass_count = k;
  r.first_spring = static_cast<std::uint32_t>(model_.spring_a.size());
  r.spring_count = static_cast<std::uint32_t>(springs.size());
  r.scene_cloth = scene_cloth;

  const Eigen::Index n0 = model_.x0.cols();
  model_.x0.conservativeResize(3, n0 + k);
  model_.x0.rightCols(k) = positions;
  model_.pinned.resize(model_.pinned.size() + k, 0);
  for (auto p : pins) model_.pinned[r.first_mass + p] = 1;

  const Eigen::Index s0 = model_.rest_length0.size();
  model_.rest_length0.conservativeResize(s0 + static_cast<Eigen::Index>(springs.size()));
  Eigen::Index si = s0;
  // Each spring from its lower mass (a < b), ordered by that mass, highest first (stable).
  // Then every mass meets its springs (in index order, the scatter loop's) first as the a end
  // (its springs to higher masses), then as the b end: the gathered pass adds one run and
  // subtracts one, with no sign per term (spring_forces.cpp). Turning a spring around changes no
  // bit of its forces (dx and c dx only change sign); the order changes their rounding only.
  std::vector<SpringSpec> sorted(springs.begin(), springs.end());
  for (auto& s : sorted)
    if (s.a > s.b) std::swap(s.a, s.b);
  std::stable_sort(sorted.begin(), sorted.end(), [](const SpringSpec& p, const SpringSpec& q) { return p.a > q.a; });
  for (const auto& s : sorted) {
    model_.spring_a.push_back(r.first_mass + s.a);
    model_.spring_b.push_back(r.first_mass + s.b);
    model_.spring_kind.push_back(s.kind);
    model_.rest_length0[si] =
        static_cast<float>(s.rest_length >= 0.0 ? s.rest_length : (positions.col(s.a) - positions.col(s.b)).norm());
    ++si;
  }
  for (auto t : triangles) model_.triangles.push_back(r.first_mass + t);
  model_.cloths.push_back(r);
  return model_.cloths.size() - 1;
}

void ModelBuilder::set_colliders(std::shared_ptr<const ColliderSet> colliders) {
  model_.colliders = std::move(colliders);
}

Model ModelBuilder::build() {
  Model& m = model_;
  m.options = resolve_options(m.options, seed_options_set(m.options));
  const Options& o = m.options;
  const Eigen::Index n = m.x0.cols();
  m.gravity = clothsim::gravity(o);
  m.spring_scale.assign(m.spring_count(), 1.0f);
  m.mass = Eigen::VectorXd::Constant(n, o.mass);
  if (is_seed(o)) {  // the 2016 program: per point and per spring
    m.spring_modulus[0] = o.k_struct;
    m.spring_modulus[1] = o.k_bend;
    m.damping = o.damping;
    m.contact = ContactParams{o.epsilon, o.epsilon, o.k_rep, o.friction, o.static_friction};
  } else {  // a material: from the triangles' areas
    if (n > 0 && m.triangles.empty())
      throw std::invalid_argument("a cloth of material '" + find_option("material")->text(o) +
                                  "' needs its triangles (its masses and springs come from their areas); "
                                  "without them use material seed");
    lump_masses(m.x0, m.triangles, o.density, m.mass);
    material_spring_scales(m, m.triangles);
    m.spring_modulus[0] = o.stretch;
    m.spring_modulus[1] = o.bend;
    m.drag = o.drag;
    m.air = air_drag_rate(o);
    m.strain_limit = o.strain_limit;
    if (m.strain_limit > 0.0 && std::count(m.pinned.begin(), m.pinned.end(), std::uint8_t{1}) > 0)
      long_range_attachments(m);
  }
  if (o.pin_spin != 0.0 && std::count(m.pinned.begin(), m.pinned.end(), std::uint8_t{1}) > 0) pin_spin_axes(m);
  m.inv_mass.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) m.inv_mass[i] = m.pinned[static_cast<std::size_t>(i)] ? 0.0 : 1.0 / m.mass[i];
  if (!is_seed(o)) m.contact = material_contact(m, o);  // (after the masses: the penalty scales with them)
  Model out = std::move(model_);
  model_ = Model{};
  model_.options = out.options;
  model_.x0.resize(3, 0);
  return out;
}

}  // namespace clothsim
