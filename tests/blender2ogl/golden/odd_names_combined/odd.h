// odd.h: the scene baked by blender2ogl 0.1.0 from odd_names.obj.
// Generated: do not edit; change the model and re-run the bake.
//
//   #include "odd.h"
//   const b2o::Scene& s = b2o::gen::odd::scene;  // fields: blender2ogl/scene_types.h
//   const b2o::Object& o = s.objects[b2o::gen::odd::object::Tischdecke];
//
// Object and cloth indices below are named after the objects (cleaned into C++
// identifiers; Object::name keeps the name as written in the file).
#ifndef B2O_GEN_odd_H
#define B2O_GEN_odd_H

#include <blender2ogl/scene_types.h>

#include <cstdint>
#include <cstring>

static_assert(::b2o::kFormatVersion == 2, "odd.h was baked for scene format 2; re-run blender2ogl");

namespace b2o::gen::odd {

inline constexpr std::uint32_t vertex_count = 18u;
inline constexpr std::uint32_t index_count = 18u;
inline constexpr std::uint32_t triangle_count = 6u;
inline constexpr std::uint32_t object_count = 6u;
inline constexpr std::uint32_t material_count = 1u;
inline constexpr std::uint32_t texture_count = 0u;
inline constexpr std::uint32_t cloth_count = 0u;
inline constexpr std::uint32_t param_count = 0u;
inline constexpr bool has_vertex_mass = false;

/// Indices into scene.objects.
namespace object {
inline constexpr std::uint32_t Tischdecke = 0u;  // Tischdecke_? ?
inline constexpr std::uint32_t say_hi_there = 1u;  // say"hi"?there?
inline constexpr std::uint32_t o3D_Cube = 2u;  // 3D.Cube
inline constexpr std::uint32_t int_ = 3u;  // int
inline constexpr std::uint32_t My_Object = 4u;  // My-Object
inline constexpr std::uint32_t My_Object_2 = 5u;  // My_Object
}  // namespace object

namespace detail {
inline constexpr float positions[] = {
    0x0p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f,
    0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x1p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x1p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+1f, 0x1p+0f, 0x0p+0f, 0x1p+1f,
    0x0p+0f, 0x1p+0f, 0x1p+1f, 0x0p+0f, 0x0p+0f, 0x1.8p+1f,
    0x1p+0f, 0x0p+0f, 0x1.8p+1f, 0x0p+0f, 0x1p+0f, 0x1.8p+1f,
    0x0p+0f, 0x0p+0f, 0x1p+2f, 0x1p+0f, 0x0p+0f, 0x1p+2f,
    0x0p+0f, 0x1p+0f, 0x1p+2f, 0x0p+0f, 0x0p+0f, 0x1.4p+2f,
    0x1p+0f, 0x0p+0f, 0x1.4p+2f, 0x0p+0f, 0x1p+0f, 0x1.4p+2f,
};
inline constexpr float normals[] = {
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
    0x0p+0f, 0x0p+0f, 0x1p+0f, 0x0p+0f, 0x0p+0f, 0x1p+0f,
};
inline constexpr float texcoords[] = {
    0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f,
    0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f,
    0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f,
    0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f,
    0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f,
    0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f, 0x0p+0f,
};
inline constexpr std::uint32_t indices[] = {
    0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 10u, 11u,
    12u, 13u, 14u, 15u, 16u, 17u,
};
inline constexpr ::b2o::Material kMaterials[] = {
    {"DefaultMaterial", {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.333334p-1f, 0x1.333334p-1f, 0x1.333334p-1f}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, 0x0p+0f, 0x1p+0f, ::b2o::kNone},
};
inline constexpr ::b2o::Submesh kSubmeshes[] = {
    {0u, 3u, 0},
    {3u, 3u, 0},
    {6u, 3u, 0},
    {9u, 3u, 0},
    {12u, 3u, 0},
    {15u, 3u, 0},
};
inline constexpr ::b2o::Object kObjects[] = {
    {"Tischdecke_\303\274\303\251", "Tischdecke", 0u, 3u, 0u, 3u, 0u, 1u, ::b2o::kNone},
    {"say\"hi\"\\there\?", "say_hi_there", 3u, 3u, 3u, 3u, 1u, 1u, ::b2o::kNone},
    {"3D.Cube", "o3D_Cube", 6u, 3u, 6u, 3u, 2u, 1u, ::b2o::kNone},
    {"int", "int_", 9u, 3u, 9u, 3u, 3u, 1u, ::b2o::kNone},
    {"My-Object", "My_Object", 12u, 3u, 12u, 3u, 4u, 1u, ::b2o::kNone},
    {"My_Object", "My_Object_2", 15u, 3u, 15u, 3u, 5u, 1u, ::b2o::kNone},
};
}  // namespace detail

/// The baked scene; all of its arrays are read-only data in this header.
inline const ::b2o::Scene scene = {
    ::b2o::kFormatVersion, "odd", "odd_names.obj",
    18u, detail::positions, detail::normals, detail::texcoords,
    18u, detail::indices,
    6u, detail::kObjects,
    6u, detail::kSubmeshes,
    1u, detail::kMaterials,
    0u, nullptr,
    0u, nullptr,
    0u, nullptr,
};

/// The object named `name` as written in the file, or nullptr.
inline const ::b2o::Object* find_object(const char* name) noexcept {
  for (std::uint32_t i = 0; i < scene.object_count; ++i)
    if (std::strcmp(scene.objects[i].name, name) == 0) return &scene.objects[i];
  return nullptr;
}

/// The value baked with `--param key=value` (its text), or `fallback` when the bake had none.
inline const char* param(const char* key, const char* fallback) noexcept {
  for (std::uint32_t i = 0; i < scene.param_count; ++i)
    if (std::strcmp(scene.params[i].key, key) == 0) return scene.params[i].value;
  return fallback;
}

}  // namespace b2o::gen::odd

#endif  // B2O_GEN_odd_H
