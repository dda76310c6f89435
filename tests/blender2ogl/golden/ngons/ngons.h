// ngons.h: the scene baked by blender2ogl 0.1.0 from ngons_crlf.obj.
// Generated: do not edit; change the model and re-run the bake.
//
//   #include "ngons.h"
//   const b2o::Scene& s = b2o::gen::ngons::scene;  // fields: blender2ogl/scene_types.h
//   const b2o::Object& o = s.objects[b2o::gen::ngons::object::Penta_Gon];
//
// Object and cloth indices below are named after the objects (cleaned into C++
// identifiers; Object::name keeps the name as written in the file).
#ifndef B2O_GEN_NGONS_H
#define B2O_GEN_NGONS_H

#include <blender2ogl/scene_types.h>

#include <cstdint>
#include <cstring>

static_assert(::b2o::kFormatVersion == 1, "ngons.h was baked for scene format 1; re-run blender2ogl");

namespace b2o::gen::ngons {

inline constexpr std::uint32_t vertex_count = 12u;
inline constexpr std::uint32_t index_count = 18u;
inline constexpr std::uint32_t triangle_count = 6u;
inline constexpr std::uint32_t object_count = 3u;
inline constexpr std::uint32_t material_count = 1u;
inline constexpr std::uint32_t texture_count = 0u;
inline constexpr std::uint32_t cloth_count = 1u;
inline constexpr std::uint32_t param_count = 0u;
inline constexpr bool has_vertex_mass = false;
/// Ties this header to the ngons.cpp/.S/.bin of the same bake (checked when they build).
inline constexpr std::uint64_t bake_id = 0x458f1accc7c24307ull;

/// Indices into scene.objects.
namespace object {
inline constexpr std::uint32_t Penta_Gon = 0u;  // Penta Gon
inline constexpr std::uint32_t class_ = 1u;  // class
inline constexpr std::uint32_t Penta_Gon_2 = 2u;  // Penta-Gon
}  // namespace object

/// Indices into scene.cloths (objects given masses and springs).
namespace cloth {
inline constexpr std::uint32_t class_ = 0u;  // 4 masses, 6 springs, 0 pins
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

}  // namespace b2o::gen::ngons

#endif  // B2O_GEN_NGONS_H
