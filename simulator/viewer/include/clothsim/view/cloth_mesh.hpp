// What the viewer derives from Model + State each frame: render positions and normals of the
// cloth objects, the box to frame, and mouse picking. No GL here, so it is unit-tested.
#pragma once

#include <clothsim/view/camera.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace b2o { struct Scene; }

namespace clothsim {
struct Model;
struct State;
}

namespace clothsim::view {

/// Empty when the model's cloths fit the scene (scene_cloth indices, mass counts), else a
/// one-line reason.
std::string check_model_matches_scene(const b2o::Scene& scene, const Model& model);

/// Writes the current positions and normals of every cloth object's render vertices into
/// positions/normals (scene vertex_count x 3, scene-global vertex order; other vertices are
/// left as they are). Normals are area-weighted per mass, so UV seams show no crease.
/// mass_normals is scratch (resized as needed). Returns false if a position is not finite
/// (then nothing is written).
bool update_cloth_vertices(const b2o::Scene& scene, const Model& model, const State& state,
                           std::vector<float>& positions, std::vector<float>& normals,
                           std::vector<double>& mass_normals);

/// Area-weighted unit normals per mass of one triangle list (mass indices local to `first`).
void accumulate_mass_normals(const State& state, std::uint32_t first, const std::uint32_t* tris,
                             std::uint32_t triangle_count, std::vector<double>& mass_normals);

/// The box the start view frames: the cloths at rest plus the colliders below/around them
/// (collider triangles within 1.1x the cloths' horizontal extent, clipped to it), so a 20 m floor does not
/// shrink the cloth to a dot; a pinned cloth gets room to hang below. Whole scene when there is no cloth.
void framing_box(const b2o::Scene& scene, const Model& model, Eigen::Vector3d& lo,
                 Eigen::Vector3d& hi);

struct Pick {
  std::int32_t mass = -1;  ///< global mass index, -1: nothing hit
  double t = 0.0;          ///< ray parameter of the hit point
};

/// The cloth mass under the ray: the nearest corner of the first cloth triangle hit; for
/// cloths without triangles, the mass nearest the ray within `radius` (m).
Pick pick_mass(const b2o::Scene& scene, const Model& model, const State& state, const Ray& ray,
               double radius);

}  // namespace clothsim::view
