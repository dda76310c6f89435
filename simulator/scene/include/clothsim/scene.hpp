// clothsim_scene: turns a baked b2o::Scene into a Model (masses, springs, pins, colliders).
#pragma once

#include <clothsim/sim.hpp>

#include <string>
#include <vector>

namespace b2o { struct Scene; }

namespace clothsim {

/// The Scene::params keys a scene may bake to override Options (the command line
/// overrides both): dt, mass, k_struct, k_bend, damping, gravity_x, gravity_y, gravity_z,
/// epsilon, k_rep. blender2ogl_add_scene() accepts exactly these as PARAMS keys (the list
/// BLENDER2OGL_PARAM_KEYS in cmake/Blender2oglBake.cmake; SceneAdapter.ParamKeysAreTheCMakeList
/// checks the two agree): add a key in both places.
const std::vector<std::string>& scene_param_keys();

/// `base` with the scene's baked params applied. Keys that are not option names are
/// returned in `unknown` (when given) and otherwise ignored.
Options scene_options(const b2o::Scene& scene, Options base = {},
                      std::vector<std::string>* unknown = nullptr);

/// Every cloth object becomes masses + springs (+ pins); every other object with triangles
/// becomes a collider. Rest lengths are recomputed in double from the rest positions.
/// Throws std::runtime_error naming the scene on inconsistent data.
Model build_model(const b2o::Scene& scene, const Options& options);

/// Number of collider triangles kept by the model's collider set (0 without colliders).
std::size_t collider_triangle_count(const Model& model);

}  // namespace clothsim
