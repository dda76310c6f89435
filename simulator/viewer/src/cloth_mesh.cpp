#include <clothsim/view/cloth_mesh.hpp>

#include <blender2ogl/scene_types.h>
#include <clothsim/sim.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace clothsim::view {

std::string check_model_matches_scene(const b2o::Scene& scene, const Model& model) {
  for (std::size_t c = 0; c < model.cloths.size(); ++c) {
    const ClothRange& r = model.cloths[c];
    if (r.first_mass + r.mass_count > model.mass_count())
      return "cloth " + std::to_string(c) + " of the model runs past its masses";
    if (r.scene_cloth < 0) continue;  // built in code: drawn as springs only
    if (static_cast<std::uint32_t>(r.scene_cloth) >= scene.cloth_count)
      return "cloth " + std::to_string(c) + " names scene cloth " + std::to_string(r.scene_cloth) +
             " but the scene has " + std::to_string(scene.cloth_count);
    const b2o::Cloth& sc = scene.cloths[r.scene_cloth];
    if (sc.mass_count != r.mass_count)
      return "cloth " + std::to_string(c) + " has " + std::to_string(r.mass_count) +
             " masses, scene cloth has " + std::to_string(sc.mass_count);
    if (sc.object >= scene.object_count) return "scene cloth names a missing object";
    if (!sc.vertex_mass && !sc.mass_vertex_offsets)
      return "scene cloth has no vertex <-> mass map";
  }
  return {};
}

void accumulate_mass_normals(const State& state, std::uint32_t first, const std::uint32_t* tris,
                             std::uint32_t triangle_count, std::vector<double>& n) {
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    const std::uint32_t a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
    const Eigen::Vector3d pa = state.x.col(first + a);
    // The cross product's length is twice the area: the area weighting comes for free.
    const Eigen::Vector3d w = (state.x.col(first + b) - pa).cross(state.x.col(first + c) - pa);
    for (std::uint32_t m : {a, b, c})
      for (int k = 0; k < 3; ++k) n[3 * m + k] += w[k];
  }
  for (std::size_t m = 0; m + 2 < n.size(); m += 3) {
    const double len = std::sqrt(n[m] * n[m] + n[m + 1] * n[m + 1] + n[m + 2] * n[m + 2]);
    if (len > 0.0) {
      n[m] /= len; n[m + 1] /= len; n[m + 2] /= len;
    } else {
      n[m] = 0.0; n[m + 1] = 1.0; n[m + 2] = 0.0;  // a mass in no triangle: any unit normal
    }
  }
}

bool update_cloth_vertices(const b2o::Scene& scene, const Model& model, const State& state,
                           std::vector<float>& positions, std::vector<float>& normals,
                           std::vector<double>& mass_normals) {
  if (!state.x.allFinite()) return false;
  for (const ClothRange& r : model.cloths) {
    if (r.scene_cloth < 0) continue;
    const b2o::Cloth& sc = scene.cloths[r.scene_cloth];
    const b2o::Object& obj = scene.objects[sc.object];
    mass_normals.assign(3 * static_cast<std::size_t>(r.mass_count), 0.0);
    accumulate_mass_normals(state, r.first_mass, sc.triangles, sc.triangle_count, mass_normals);
    auto write = [&](std::uint32_t vertex, std::uint32_t local_mass) {
      const auto col = state.x.col(r.first_mass + local_mass);
      for (int k = 0; k < 3; ++k) {
        positions[3 * vertex + k] = static_cast<float>(col[k]);
        normals[3 * vertex + k] = static_cast<float>(mass_normals[3 * local_mass + k]);
      }
    };
    if (sc.vertex_mass) {
      for (std::uint32_t i = 0; i < obj.vertex_count; ++i) write(obj.first_vertex + i, sc.vertex_mass[i]);
    } else {
      for (std::uint32_t m = 0; m < sc.mass_count; ++m)
        for (std::uint32_t j = sc.mass_vertex_offsets[m]; j < sc.mass_vertex_offsets[m + 1]; ++j)
          write(sc.mass_vertices[j], m);
    }
  }
  return true;
}

void framing_box(const b2o::Scene& scene, const Model& model, Eigen::Vector3d& lo,
                 Eigen::Vector3d& hi) {
  const double inf = std::numeric_limits<double>::infinity();
  lo.setConstant(inf);
  hi.setConstant(-inf);
  for (const ClothRange& r : model.cloths)
    for (std::uint32_t m = 0; m < r.mass_count; ++m) {
      lo = lo.cwiseMin(model.x0.col(r.first_mass + m));
      hi = hi.cwiseMax(model.x0.col(r.first_mass + m));
    }
  const bool have_cloth = lo.x() <= hi.x();
  // A pinned cloth hangs: leave room below it for its own width.
  bool pinned = false;
  for (std::uint8_t p : model.pinned) pinned = pinned || p != 0;
  if (have_cloth && pinned) lo.y() -= std::max(hi.x() - lo.x(), hi.z() - lo.z());
  Eigen::Vector3d c_lo = lo, c_hi = hi;
  if (have_cloth) {  // the horizontal window in which colliders count
    const Eigen::Vector3d mid = 0.5 * (lo + hi), half = 0.55 * (hi - lo);
    c_lo = mid - half;
    c_hi = mid + half;
  }
  // Collider triangles that overlap the window count with their box clipped to it, so a
  // large floor adds its height but not its width.
  for (std::uint32_t o = 0; o < scene.object_count; ++o) {
    const b2o::Object& obj = scene.objects[o];
    if (obj.cloth != b2o::kNone) continue;
    for (std::uint32_t t = obj.first_index; t + 2 < obj.first_index + obj.index_count; t += 3) {
      Eigen::Vector3d t_lo = Eigen::Vector3d::Constant(inf), t_hi = -t_lo;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t i = scene.indices[t + k];
        const Eigen::Vector3d p(scene.positions[3 * i], scene.positions[3 * i + 1],
                                scene.positions[3 * i + 2]);
        t_lo = t_lo.cwiseMin(p);
        t_hi = t_hi.cwiseMax(p);
      }
      if (!t_lo.allFinite() || !t_hi.allFinite()) continue;
      if (have_cloth) {
        if (t_hi.x() < c_lo.x() || t_lo.x() > c_hi.x() || t_hi.z() < c_lo.z() || t_lo.z() > c_hi.z())
          continue;
        for (int k : {0, 2}) {
          t_lo[k] = std::max(t_lo[k], c_lo[k]);
          t_hi[k] = std::min(t_hi[k], c_hi[k]);
        }
      }
      lo = lo.cwiseMin(t_lo);
      hi = hi.cwiseMax(t_hi);
    }
  }
  if (!(lo.x() <= hi.x())) {  // nothing at all
    lo.setConstant(-1.0);
    hi.setConstant(1.0);
  }
}

namespace {

// Moeller-Trumbore; returns the ray parameter or +inf.
double ray_triangle(const Ray& ray, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = ray.dir.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14) return std::numeric_limits<double>::infinity();
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = ray.origin - a;
  const double u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d q = s.cross(e1);
  const double v = ray.dir.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return std::numeric_limits<double>::infinity();
  const double t = e2.dot(q) * inv;
  return t > 0.0 ? t : std::numeric_limits<double>::infinity();
}

}  // namespace

Pick pick_mass(const b2o::Scene& scene, const Model& model, const State& state, const Ray& ray,
               double radius) {
  Pick best;
  double best_t = std::numeric_limits<double>::infinity();
  bool any_triangles = false;
  for (const ClothRange& r : model.cloths) {
    if (r.scene_cloth < 0) continue;
    const b2o::Cloth& sc = scene.cloths[r.scene_cloth];
    any_triangles = any_triangles || sc.triangle_count > 0;
    for (std::uint32_t t = 0; t < sc.triangle_count; ++t) {
      const std::uint32_t* tri = sc.triangles + 3 * t;
      const double hit = ray_triangle(ray, state.x.col(r.first_mass + tri[0]),
                                      state.x.col(r.first_mass + tri[1]),
                                      state.x.col(r.first_mass + tri[2]));
      if (!(hit < best_t)) continue;
      best_t = hit;
      const Eigen::Vector3d p = ray.origin + hit * ray.dir;
      double nearest = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) {
        const double d = (state.x.col(r.first_mass + tri[k]) - p).squaredNorm();
        if (d < nearest) {
          nearest = d;
          best.mass = static_cast<std::int32_t>(r.first_mass + tri[k]);
        }
      }
      best.t = hit;
    }
  }
  if (best.mass >= 0 || any_triangles) return best;
  // No triangles to hit: the mass nearest the ray, in front of the eye, within radius.
  double best_d = radius * radius;
  for (const ClothRange& r : model.cloths)
    for (std::uint32_t m = r.first_mass; m < r.first_mass + r.mass_count; ++m) {
      const Eigen::Vector3d q = state.x.col(m) - ray.origin;
      const double t = q.dot(ray.dir);
      if (t <= 0.0) continue;
      const double d = (q - t * ray.dir).squaredNorm();
      if (d < best_d) {
        best_d = d;
        best.mass = static_cast<std::int32_t>(m);
        best.t = t;
      }
    }
  return best;
}

}  // namespace clothsim::view
