// grid.h: the scene baked by blender2ogl 0.1.0 from grid.obj.
// Generated: do not edit; change the model and re-run the bake.
//
//   #include "grid.h"
//   const b2o::Scene& s = b2o::gen::grid::scene;  // fields: blender2ogl/scene_types.h
//   const b2o::Object& o = s.objects[b2o::gen::grid::object::Cloth];
//
// Object and cloth indices below are named after the objects (cleaned into C++
// identifiers; Object::name keeps the name as written in the file).
#ifndef B2O_GEN_GRID_H
#define B2O_GEN_GRID_H

#include <blender2ogl/scene_types.h>

#include <cstdint>
#include <cstring>

static_assert(::b2o::kFormatVersion == 1, "grid.h was baked for scene format 1; re-run blender2ogl");

namespace b2o::gen::grid {

inline constexpr std::uint32_t vertex_count = 13u;
inline constexpr std::uint32_t index_count = 30u;
inline constexpr std::uint32_t triangle_count = 10u;
inline constexpr std::uint32_t object_count = 2u;
inline constexpr std::uint32_t material_count = 2u;
inline constexpr std::uint32_t texture_count = 1u;
inline constexpr std::uint32_t cloth_count = 1u;
inline constexpr std::uint32_t param_count = 2u;
inline constexpr bool has_vertex_mass = true;
/// Ties this header to the grid.cpp/.S/.bin of the same bake (checked when they build).
inline constexpr std::uint64_t bake_id = 0x61e2c840d54b2dd6ull;

/// Indices into scene.objects.
namespace object {
inline constexpr std::uint32_t Cloth = 0u;  // Cloth
inline constexpr std::uint32_t Floor = 1u;  // Floor
}  // namespace object

/// Indices into scene.cloths (objects given masses and springs).
namespace cloth {
inline constexpr std::uint32_t Cloth = 0u;  // 9 masses, 24 springs, 2 pins
}  // namespace cloth

/// The baked scene; all of its arrays are read-only data linked into the program.
extern const ::b2o::Scene scene;

/// The object named `name` as written in the file, or nullptr.
inline const ::b2o::Object* find_object(const char* name) noexcept {
  for (std::uint32_t i = 0; i < scene.object_count; ++i)
    if (std::strcmp(scene.objects[i].name, name) == 0) return &scene.objects[i];
  return nullptr;
}

/// The value baked with `--param key=value`, or `fallback` when the bake had none.
inline double param(const char* key, double fallback) noexcept {
  for (std::uint32_t i = 0; i < scene.param_count; ++i)
    if (std::strcmp(scene.params[i].key, key) == 0) return scene.params[i].value;
  return fallback;
}

}  // namespace b2o::gen::grid

#endif  // B2O_GEN_GRID_H
