#include <clothsim/closed_mesh.hpp>

#include <clothsim/collision.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <map>
#include <numbers>
#include <utility>

namespace clothsim {

SolidInfo analyse_solid(const TriangleCorners& corners) {
  SolidInfo info;
  const Eigen::Index tris = corners.cols() / 3;
  // Weld corners by exact position (an export may split vertices at UV seams).
  std::map<std::array<double, 3>, std::uint32_t> ids;
  auto id = [&ids](const Eigen::Vector3d& p) {
    const auto [it, added] = ids.try_emplace({p.x(), p.y(), p.z()}, static_cast<std::uint32_t>(ids.size()));
    return it->second;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;  // (from, to) -> count
  bool any = false;
  for (Eigen::Index t = 0; t < tris; ++t) {
    const Eigen::Vector3d a = corners.col(3 * t), b = corners.col(3 * t + 1), c = corners.col(3 * t + 2);
    info.signed_volume += a.dot(b.cross(c)) / 6.0;
    const std::uint32_t v[3] = {id(a), id(b), id(c)};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;
    any = true;
    for (int k = 0; k < 3; ++k) ++directed[{v[k], v[(k + 1) % 3]}];
  }
  info.closed = any && std::all_of(directed.begin(), directed.end(), [&directed](const auto& e) {
                  if (e.second != 1) return false;
                  const auto back = directed.find({e.first.second, e.first.first});
                  return back != directed.end() && back->second == 1;
                });
  return info;
}

double winding_number(const TriangleCorners& corners, const Eigen::Vector3d& p) {
  double sum = 0.0;
  const Eigen::Index tris = corners.cols() / 3;
  for (Eigen::Index t = 0; t < tris; ++t) {
    const Eigen::Vector3d a = corners.col(3 * t) - p, b = corners.col(3 * t + 1) - p, c = corners.col(3 * t + 2) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2.0 * std::atan2(num, den);  // the solid angle of the triangle seen from p
  }
  return sum / (4.0 * std::numbers::pi);
}

std::int64_t count_inside(const TriangleCorners& corners, const Eigen::Matrix3Xd& points, double work_budget) {
  if (corners.cols() < 3 || points.cols() == 0) return 0;
  const Eigen::Vector3d lo = corners.rowwise().minCoeff(), hi = corners.rowwise().maxCoeff();
  std::vector<Eigen::Index> in_box;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = points.col(i);
    if ((p.array() >= lo.array()).all() && (p.array() <= hi.array()).all()) in_box.push_back(i);
  }
  if (static_cast<double>(in_box.size()) * static_cast<double>(corners.cols() / 3) > work_budget) return -1;
  std::int64_t n = 0;
  for (const Eigen::Index i : in_box)
    if (std::abs(winding_number(corners, points.col(i))) > 0.5) ++n;
  return n;
}

std::vector<std::string> collider_warnings(const Model& model, double work_budget) {
  std::vector<std::string> out;
  if (!model.colliders) return out;
  const ColliderSet& set = *model.colliders;
  for (std::size_t o = 0; o < set.object_count(); ++o) {
    const std::size_t tris = set.input_triangle_count(o);
    TriangleCorners corners(3, static_cast<Eigen::Index>(3 * tris));
    for (std::size_t t = 0; t < tris; ++t) {
      Eigen::Vector3d a, b, c;
      set.triangle(o, t, a, b, c);
      const auto k = static_cast<Eigen::Index>(3 * t);
      corners.col(k) = a;
      corners.col(k + 1) = b;
      corners.col(k + 2) = c;
    }
    const SolidInfo solid = analyse_solid(corners);
    if (!solid.closed) continue;
    const std::string name = "'" + set.object_name(o) + "'";
    char num[64];
    if (solid.signed_volume < 0.0) {
      std::snprintf(num, sizeof num, "%.3g", solid.signed_volume);
      out.push_back("warning: collider " + name + " faces point inwards (signed volume " + num +
                    " m^3): the cloth will be pushed into it; fix the export (Blender: Recalculate Outside)");
    }
    const std::int64_t inside = count_inside(corners, model.x0, work_budget);
    if (inside > 0)
      out.push_back("warning: " + std::to_string(inside) + " of " + std::to_string(model.mass_count()) +
                    " masses start inside collider " + name + " (move the cloth or the collider)");
  }
  return out;
}

}  // namespace clothsim
