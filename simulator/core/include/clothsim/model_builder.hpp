// Builds a Model in code: cloths (positions, springs, pins) and colliders. The scene
// adapter (clothsim_scene) uses it for baked scenes; tests use it for tiny inline scenes.
#pragma once

#include <clothsim/sim.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace clothsim {

/// One spring between two masses of a cloth (local indices).
struct SpringSpec {
  std::uint32_t a = 0, b = 0;
  std::uint8_t kind = 0;         ///< 0 structural, 1 bend
  double rest_length = -1.0;     ///< m; < 0: the distance between the rest positions
};

class ModelBuilder {
 public:
  explicit ModelBuilder(const Options& options, std::string scene_name = {});

  /// Adds a cloth; positions is (3 x k), triangles 3 local mass indices each (a material's
  /// masses and spring constants come from their areas; the seed model needs none). Throws
  /// std::invalid_argument on a bad index, a spring joining a mass to itself or a non-finite
  /// position. Returns the cloth's index. The model keeps the springs turned from their lower
  /// mass (spring_a < spring_b) and ordered by it, highest first (stable): the order the
  /// gathered spring pass adds fastest.
  std::size_t add_cloth(const Eigen::Matrix3Xd& positions, std::span<const SpringSpec> springs,
                        std::span<const std::uint32_t> pins, std::span<const std::uint32_t> triangles = {},
                        std::int32_t scene_cloth = -1);

  void set_colliders(std::shared_ptr<const ColliderSet> colliders);

  /// The finished Model (the builder is left empty): the options resolved (resolve_options(),
  /// the seed model when one of its options was set), then the masses, spring constants,
  /// damping and contact of the seed model or of the material (material.hpp). Throws
  /// std::invalid_argument when the options mix the two models, or a material's cloth has no
  /// triangles.
  Model build();

 private:
  Model model_;
};

}  // namespace clothsim
