// A material in SI units turned into the Model's masses, spring scales and contact
// (material.hpp).
#include <clothsim/material.hpp>
#include <clothsim/stability.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <tuple>
#include <unordered_map>

namespace clothsim {

namespace {

double triangle_area(const Eigen::Matrix3Xd& x, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  return 0.5 * (x.col(b) - x.col(a)).cross(x.col(c) - x.col(a)).norm();
}

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
}

// Each edge's adjacent triangle area, and the hinge of each pair of triangles by their
// opposite points: (hinge length, the two triangles' area).
struct Adjacency {
  std::unordered_map<std::uint64_t, double> edge_area;
  std::unordered_map<std::uint64_t, std::pair<double, double>> hinge;  // opposite pair -> (|e|, A_e)
  double mean_area = 0.0;
};

Adjacency adjacency(const Eigen::Matrix3Xd& x, std::span<const std::uint32_t> t) {
  Adjacency adj;
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, double>> first;  // edge -> (opposite, area)
  const std::size_t count = t.size() / 3;
  for (std::size_t k = 0; k < count; ++k) {
    const std::uint32_t v[3] = {t[3 * k], t[3 * k + 1], t[3 * k + 2]};
    const double area = triangle_area(x, v[0], v[1], v[2]);
    adj.mean_area += area / static_cast<double>(count);
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = v[e], b = v[(e + 1) % 3], opposite = v[(e + 2) % 3];
      const std::uint64_t key = edge_key(a, b);
      adj.edge_area[key] += area;
      const auto [it, fresh] = first.try_emplace(key, opposite, area);
      if (!fresh)  // the second triangle of this edge: a hinge between the two opposite points
        adj.hinge[edge_key(it->second.first, opposite)] = {(x.col(a) - x.col(b)).norm(), it->second.second + area};
    }
  }
  return adj;
}

}  // namespace

void lump_masses(const Eigen::Matrix3Xd& x0, std::span<const std::uint32_t> triangles, double density,
                 Eigen::VectorXd& masses) {
  Eigen::VectorXd area = Eigen::VectorXd::Zero(masses.size());
  for (std::size_t k = 0; k + 2 < triangles.size(); k += 3) {
    const double a = triangle_area(x0, triangles[k], triangles[k + 1], triangles[k + 2]) / 3.0;
    for (int c = 0; c < 3; ++c) area[triangles[k + static_cast<std::size_t>(c)]] += a;
  }
  double sum = 0.0;
  Eigen::Index with = 0;
  for (Eigen::Index i = 0; i < area.size(); ++i)
    if (area[i] > 0.0) sum += area[i], ++with;
  const double fill = with > 0 ? sum / static_cast<double>(with) : 0.0;
  for (Eigen::Index i = 0; i < area.size(); ++i) masses[i] = density * (area[i] > 0.0 ? area[i] : fill);
}

void material_spring_scales(Model& m, std::span<const std::uint32_t> triangles) {
  const Adjacency adj = adjacency(m.x0, triangles);
  constexpr double kHinge = 183.0;  // theta0^2 / (1 - cos(theta0 / 2))^2 * 3 at theta0 = 60 degrees
  m.spring_scale.resize(m.spring_count());
  for (std::size_t s = 0; s < m.spring_count(); ++s) {
    const std::uint64_t key = edge_key(m.spring_a[s], m.spring_b[s]);
    const double rest = m.rest_length0[static_cast<Eigen::Index>(s)];
    const double l2 = rest > 0.0 ? rest * rest : 1.0;
    double scale = 0.0;
    if (m.spring_kind[s] == 0) {
      const auto it = adj.edge_area.find(key);
      scale = (it != adj.edge_area.end() ? it->second : 2.0 * adj.mean_area) / l2;
    } else {
      const auto it = adj.hinge.find(key);
      const double e = it != adj.hinge.end() ? it->second.first : 0.5 * rest;
      const double area = it != adj.hinge.end() ? it->second.second : 2.0 * adj.mean_area;
      scale = area > 0.0 ? kHinge * e * e / (area * l2) : 0.0;
    }
    m.spring_scale[s] = static_cast<float>(scale);
  }
}

void long_range_attachments(Model& m) {
  constexpr std::size_t K = Model::kAttachments;
  const std::size_t n = m.mass_count();
  m.attach_pin.assign(n * K, Model::kNoPin);
  m.attach_rest.assign(n * K, 0.0f);
  // the structural springs of every mass (CSR)
  std::vector<std::uint32_t> start(n + 1, 0), nb;
  for (std::size_t s = 0; s < m.spring_count(); ++s)
    if (m.spring_kind[s] == 0) ++start[m.spring_a[s] + 1], ++start[m.spring_b[s] + 1];
  for (std::size_t i = 0; i < n; ++i) start[i + 1] += start[i];
  nb.resize(start[n]);
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t s = 0; s < m.spring_count(); ++s)
    if (m.spring_kind[s] == 0) nb[fill[m.spring_a[s]]++] = static_cast<std::uint32_t>(s), nb[fill[m.spring_b[s]]++] = static_cast<std::uint32_t>(s);
  // Dijkstra from every pin at once: a mass is settled once per pin, at most K times
  using Item = std::tuple<double, std::uint32_t, std::uint32_t>;  // (distance, mass, pin)
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (std::size_t i = 0; i < n; ++i)
    if (m.pinned[i]) queue.emplace(0.0, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i));
  std::vector<std::uint8_t> settled(n, 0);
  while (!queue.empty()) {
    const auto [d, i, pin] = queue.top();
    queue.pop();
    std::uint32_t* pins = &m.attach_pin[std::size_t{i} * K];
    if (settled[i] == K || std::find(pins, pins + settled[i], pin) != pins + settled[i]) continue;
    m.attach_rest[std::size_t{i} * K + settled[i]] = static_cast<float>(d);
    pins[settled[i]++] = pin;
    for (std::uint32_t e = start[i]; e < start[i + 1]; ++e) {
      const std::uint32_t s = nb[e], j = m.spring_a[s] == i ? m.spring_b[s] : m.spring_a[s];
      if (settled[j] < K && !m.pinned[j]) queue.emplace(d + m.rest_length0[static_cast<Eigen::Index>(s)], j, pin);
    }
  }
  for (std::size_t i = 0; i < n; ++i)  // a pin's own attachments: none
    if (m.pinned[i]) std::fill_n(&m.attach_pin[i * K], K, Model::kNoPin);
}

double mean_structural_length(const Model& m) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t s = 0; s < m.spring_count(); ++s)
    if (m.spring_kind[s] == 0) sum += m.rest_length0[static_cast<Eigen::Index>(s)], ++count;
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

ContactParams material_contact(const Model& m, const Options& o) {
  ContactParams c;
  c.distance = std::max(o.thickness, 0.05 * mean_structural_length(m));
  c.band = std::max(2.0 * c.distance, 0.01);
  c.friction = o.friction;
  c.static_friction = o.static_friction;
  // The penalty of the force-based integrators: stops the scene's fastest fall with a margin of
  // 2 within the distance, and rests at most a tenth of it deep (k_rep / m = omega^2).
  const double g = m.gravity.norm(), fall = std::sqrt(2.0 * g * drop_height(m));
  const double omega = std::max(2.0 * fall / c.distance, std::sqrt(10.0 * g / c.distance));
  const double mean_mass = m.mass.size() > 0 ? m.mass.mean() : 0.0;
  c.k_rep = mean_mass * omega * omega;
  return c;
}

}  // namespace clothsim
