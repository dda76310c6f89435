// clothsim_scene: turns a baked b2o::Scene into a Model (masses, springs, pins, colliders).
#pragma once

#include <clothsim/sim.hpp>

#include <string>
#include <vector>

namespace b2o { struct Scene; }

namespace clothsim {

/// A scene's baked PARAMS (blender2ogl_add_scene's PARAMS), read against the options table
/// (options.hpp): each key names an option.
struct BakedParams {
  Options options;                    ///< `base` with every accepted value applied
  std::vector<std::string> unknown;   ///< keys that are no option (ignored)
  struct Refused {
    std::string key, why;             ///< why: worded to follow the key ("must be ... (got -1)")
  };
  std::vector<Refused> refused;       ///< values the option refuses (not applied)
  bool seed_given = false;            ///< an option of the seed model is baked (it selects that model)
  std::string friction_key;           ///< a friction key baked (friction, static_friction), or empty
};
BakedParams read_scene_params(const b2o::Scene& scene, Options base = {});

/// `base` with the scene's baked PARAMS applied and resolved (resolve_options(): the material
/// and the integrator decided); unknown keys are ignored. Throws std::runtime_error naming the
/// scene and the key for a value the option refuses, options of two models, or friction baked
/// into a scene without colliders.
Options scene_options(const b2o::Scene& scene, Options base = {});

/// Every cloth object becomes masses + springs (+ pins); every other object with triangles
/// becomes a collider. Rest lengths are recomputed in double from the rest positions.
/// Throws std::runtime_error naming the scene on inconsistent data.
Model build_model(const b2o::Scene& scene, const Options& options);

/// Whether the scene has a collider: an object with triangles that is not cloth.
bool has_colliders(const b2o::Scene& scene);

/// Number of collider triangles kept by the model's collider set (0 without colliders).
std::size_t collider_triangle_count(const Model& model);

}  // namespace clothsim
