#include <clothsim/closed_mesh.hpp>

#include <clothsim/collision.hpp>

#include <blender2ogl/solid_parts.hpp>

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdio>
#include <string>
#include <numbers>
#include <vector>

namespace clothsim {

namespace {

std::vector<b2o::SolidPart> parts_of(const TriangleCorners& corners) {
  return b2o::solid_parts(corners.data(), static_cast<std::size_t>(corners.cols() / 3));
}

SolidInfo solid_of(const std::vector<b2o::SolidPart>& parts) {
  SolidInfo info;
  info.closed = !parts.empty() && std::all_of(parts.begin(), parts.end(), [](const b2o::SolidPart& p) {
                  return p.closed && p.same_direction == 0;
                });
  for (const b2o::SolidPart& p : parts) info.signed_volume += p.volume;
  return info;
}

}  // namespace

SolidInfo analyse_solid(const TriangleCorners& corners) { return solid_of(parts_of(corners)); }

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

BehindCount count_behind(const ColliderSet& set, std::size_t o, const Eigen::Matrix3Xd& points, double eps) {
  BehindCount out;
  if (!set.built() || o >= set.object_count() || set.triangle_count(o) == 0 || !(eps > 0.0) || points.cols() == 0)
    return out;
  // within the cloth's size of the collider (farther, contact is not in sight)
  const Eigen::Vector3d lo = points.rowwise().minCoeff(), hi = points.rowwise().maxCoeff();
  const double radius = std::max(2.0 * eps, (hi - lo).norm());
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = points.col(i);
    if (!p.allFinite()) continue;
    const ColliderHit hit = set.query_object(o, p.data(), radius * radius, QueryMethod::Bvh, -1);
    if (!hit.valid()) continue;
    Eigen::Vector3d a, b, c;
    set.triangle(o, static_cast<std::size_t>(hit.triangle), a, b, c);
    const PointTriangle pt = point_triangle(p, a, b, c);
    if (pt.degenerate || !(pt.signed_distance < 0.0)) continue;
    // the foot of p on the plane on the triangle (its face or an edge): behind it, not beside
    // the collider's rim below its level
    const Eigen::Vector3d foot = p - pt.normal.dot(p - a) * pt.normal;
    if ((foot - pt.closest).norm() > 1e-9 * (1.0 + p.cwiseAbs().maxCoeff())) continue;
    if (pt.signed_distance >= -2.0 * eps) ++out.in_band;
    else ++out.farther;
  }
  return out;
}

LaunchCount count_launched(const ColliderSet& set, std::size_t o, const Eigen::Matrix3Xd& points,
                           const Eigen::VectorXd& mass, const std::vector<std::uint8_t>& pinned, double eps,
                           double k_rep, double gravity, double times) {
  LaunchCount out;
  if (!set.built() || o >= set.object_count() || set.triangle_count(o) == 0 || !(eps > 0.0) || !(k_rep > 0.0) ||
      points.cols() == 0 || mass.size() != points.cols())
    return out;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if (!pinned.empty() && pinned[static_cast<std::size_t>(i)]) continue;  // held: not thrown
    const Eigen::Vector3d p = points.col(i);
    if (!p.allFinite()) continue;
    // object o alone (all objects per object would be objects^2 work)
    const ColliderHit hit = set.query_object(o, p.data(), eps * eps, QueryMethod::Bvh, -1);
    if (!hit.valid()) continue;
    // signed as the force sees it: outside beside a sharp ridge is outside
    const double d = set.contact_distance(p, hit);
    if (!(d >= 0.0 && d < eps)) continue;
    const double push = k_rep * (eps - d), weight = mass[i] * gravity;
    if (push > times * weight) {
      ++out.count;
      if (weight > 0.0) out.worst = std::max(out.worst, push / weight);
      out.worst_push = std::max(out.worst_push, push);
    }
  }
  return out;
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
    // Per connected part, as the bake checks (b2o::solid_parts): a part whose faces point
    // inwards, or both ways, pushes the cloth into it.
    const std::vector<b2o::SolidPart> parts = parts_of(corners);
    const std::string name = "'" + set.object_name(o) + "'";
    double inward = 0.0;
    std::size_t inward_parts = 0, inconsistent = 0;
    for (const b2o::SolidPart& p : parts) {
      if (p.inward()) inward += p.volume, ++inward_parts;
      if (p.inconsistent()) inconsistent += p.same_direction;
    }
    char num[64];
    if (inward_parts > 0) {
      std::snprintf(num, sizeof num, "%.3g", inward);
      out.push_back("warning: collider " + name + " faces point inwards (signed volume " + num + " m^3" +
                    (parts.size() > 1 ? " in " + std::to_string(inward_parts) + " of its " + std::to_string(parts.size()) +
                                            " parts"
                                      : std::string()) +
                    "): the cloth will be pushed into it; fix the export (Blender: Recalculate Outside)");
    }
    if (inconsistent > 0)
      out.push_back("warning: collider " + name + " is closed with faces pointing both ways (" +
                    std::to_string(inconsistent) +
                    " edges used twice the same way): the cloth is pushed into it where they point inwards; fix "
                    "the export (Blender: Recalculate Outside)");
    // Masses that start deep in the contact band are thrown out of it at once (an epsilon as
    // large as the scene, a cloth placed just above a floor): a dice cloth at --epsilon 3 flies
    // 100 m up, a 1 cm cloth with the default 0.1 m band 7 km.
    const double eps = model.contact.distance;
    const char* eps_flag = is_seed(model.options) ? "--epsilon" : "--thickness";
    {
      const double g = gravity(model.options).norm();
      const LaunchCount l = count_launched(set, o, model.x0, model.mass, model.pinned, eps, model.contact.k_rep, g, 10.0);
      if (l.count > 0) {
        char what[240];
        if (g > 0.0)
          std::snprintf(what, sizeof what,
                        "start within the contact band of collider %s (epsilon %.3g m) and get up to %.3g times their "
                        "weight at once: they will be thrown off; ",
                        name.c_str(), eps, l.worst);
        else
          std::snprintf(what, sizeof what,
                        "start within the contact band of collider %s (epsilon %.3g m) and get up to %.3g N at once, "
                        "with no gravity to hold them: they will be thrown off; ",
                        name.c_str(), eps, l.worst_push);
        out.push_back("warning: " + std::to_string(l.count) + " of " + std::to_string(model.mass_count()) +
                      " masses " + what + "start the cloth farther than epsilon from it, or use a smaller " + eps_flag);
      }
    }
    // An open collider (a floor, a plate) pushes only towards its front. Masses that start
    // behind one of its faces (their foot on the face) are pulled through it on contact, or,
    // within its band, shot out to its front at once (a floor whose normals point down, a
    // cloth placed just under a floor).
    if (!solid_of(parts).closed) {
      const BehindCount b = count_behind(set, o, model.x0, eps);
      char band[96];
      std::snprintf(band, sizeof band, "%.3g m", 2.0 * eps);
      if (b.in_band > 0)
        out.push_back("warning: " + std::to_string(b.in_band) + " of " + std::to_string(model.mass_count()) +
                      " masses start behind collider " + name + " within its contact band (" + band +
                      "): its penalty force will push them through to its front side at once (move the cloth above it)");
      if (b.farther > 0)
        out.push_back("warning: " + std::to_string(b.farther) + " of " + std::to_string(model.mass_count()) +
                      " masses start behind collider " + name +
                      " (on the side its normals point away from): it pushes only towards its front, so on contact "
                      "it pulls the cloth through; if its normals are flipped, fix the export (Blender: Mesh > "
                      "Normals > Flip, or Recalculate Outside)");
      continue;
    }
    // Masses inside: only for a collider every part of which is a closed, consistent solid
    // (an open mesh has no inside).
    const std::int64_t inside = count_inside(corners, model.x0, work_budget);
    if (inside > 0)
      out.push_back("warning: " + std::to_string(inside) + " of " + std::to_string(model.mass_count()) +
                    " masses start inside collider " + name + " (move the cloth or the collider)");
  }
  return out;
}

}  // namespace clothsim
