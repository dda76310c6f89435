// ngons.h: the scene baked by blender2ogl 0.1.0 from ngons_crlf.obj.
// Generated: do not edit; change the model and re-run the bake.
//
//   #include "ngons.h"
//   const b2o::Scene& s = b2o::gen::ngons::scene;  // fields: blender2ogl/scene_types.h
//   const b2o::Object& o = s.objects[b2o::gen::ngons::object::Penta_Gon];
//
// Object and cloth indices below are named after the objects (cleaned into C++
// identifiers; Object::name keeps the name as written in the file).
#ifndef B2O_GEN_ngons_H
#define B2O_GEN_ngons_H

#ifdef __ASSEMBLER__
/* Bulk arrays, assembled through ngons.S: the bytes of ngons.099691c6471c5a1c.bin
   (680 bytes, fnv1a64 099691c6471c5a1c), found through -I<dir>. */
	.section .rodata.b2o.ngons,"a",@progbits
	.balign 16
	.globl b2o_ngons_positions
	.type b2o_ngons_positions, @object
	.size b2o_ngons_positions, 144
b2o_ngons_positions:
	.incbin "ngons.099691c6471c5a1c.bin", 0, 144
	.balign 16
	.globl b2o_ngons_normals
	.type b2o_ngons_normals, @object
	.size b2o_ngons_normals, 144
b2o_ngons_normals:
	.incbin "ngons.099691c6471c5a1c.bin", 144, 144
	.balign 16
	.globl b2o_ngons_texcoords
	.type b2o_ngons_texcoords, @object
	.size b2o_ngons_texcoords, 96
b2o_ngons_texcoords:
	.incbin "ngons.099691c6471c5a1c.bin", 288, 96
	.balign 16
	.globl b2o_ngons_indices
	.type b2o_ngons_indices, @object
	.size b2o_ngons_indices, 72
b2o_ngons_indices:
	.incbin "ngons.099691c6471c5a1c.bin", 384, 72
	.balign 16
	.globl b2o_ngons_cloth0_rest_positions
	.type b2o_ngons_cloth0_rest_positions, @object
	.size b2o_ngons_cloth0_rest_positions, 48
b2o_ngons_cloth0_rest_positions:
	.incbin "ngons.099691c6471c5a1c.bin", 464, 48
	.balign 16
	.globl b2o_ngons_cloth0_mass_vertex_offsets
	.type b2o_ngons_cloth0_mass_vertex_offsets, @object
	.size b2o_ngons_cloth0_mass_vertex_offsets, 20
b2o_ngons_cloth0_mass_vertex_offsets:
	.incbin "ngons.099691c6471c5a1c.bin", 512, 20
	.balign 16
	.globl b2o_ngons_cloth0_mass_vertices
	.type b2o_ngons_cloth0_mass_vertices, @object
	.size b2o_ngons_cloth0_mass_vertices, 16
b2o_ngons_cloth0_mass_vertices:
	.incbin "ngons.099691c6471c5a1c.bin", 544, 16
	.balign 16
	.globl b2o_ngons_cloth0_springs
	.type b2o_ngons_cloth0_springs, @object
	.size b2o_ngons_cloth0_springs, 96
b2o_ngons_cloth0_springs:
	.incbin "ngons.099691c6471c5a1c.bin", 560, 96
	.balign 16
	.globl b2o_ngons_cloth0_triangles
	.type b2o_ngons_cloth0_triangles, @object
	.size b2o_ngons_cloth0_triangles, 24
b2o_ngons_cloth0_triangles:
	.incbin "ngons.099691c6471c5a1c.bin", 656, 24
	.globl b2o_ngons_bake_1e7aa9874a450108
	.type b2o_ngons_bake_1e7aa9874a450108, @object
	.size b2o_ngons_bake_1e7aa9874a450108, 1
b2o_ngons_bake_1e7aa9874a450108:
	.byte 0
	.section .note.GNU-stack,"",@progbits
#else  // C++ from here on

#include <blender2ogl/scene_types.h>

#include <cstdint>
#include <cstring>

static_assert(::b2o::kFormatVersion == 2, "ngons.h was baked for scene format 2; re-run blender2ogl");

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
/// Identifies this bake (its tables and bulk bytes).
inline constexpr std::uint64_t bake_id = 0x1e7aa9874a450108ull;

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

/// The value baked with `--param key=value` (its text), or `fallback` when the bake had none.
inline const char* param(const char* key, const char* fallback) noexcept {
  for (std::uint32_t i = 0; i < scene.param_count; ++i)
    if (std::strcmp(scene.params[i].key, key) == 0) return scene.params[i].value;
  return fallback;
}

}  // namespace b2o::gen::ngons

#ifdef B2O_NGONS_DEFINE_SCENE
// Compiled once, in ngons.cpp: the small tables as text; the bulk arrays are the
// symbols of the assembler part above. The last symbol exists only in an object assembled
// from this very header (a stale ngons.S object fails to link).
extern "C" {
extern const float b2o_ngons_positions[];
extern const float b2o_ngons_normals[];
extern const float b2o_ngons_texcoords[];
extern const std::uint32_t b2o_ngons_indices[];
extern const float b2o_ngons_cloth0_rest_positions[];
extern const std::uint32_t b2o_ngons_cloth0_mass_vertex_offsets[];
extern const std::uint32_t b2o_ngons_cloth0_mass_vertices[];
extern const ::b2o::Spring b2o_ngons_cloth0_springs[];
extern const std::uint32_t b2o_ngons_cloth0_triangles[];
extern const unsigned char b2o_ngons_bake_1e7aa9874a450108[];
}

namespace b2o::gen::ngons {
namespace {
constexpr ::b2o::Material kMaterials[] = {
    {"DefaultMaterial", {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.333334p-1f, 0x1.333334p-1f, 0x1.333334p-1f}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, 0x0p+0f, 0x1p+0f, ::b2o::kNone},
};
constexpr ::b2o::Submesh kSubmeshes[] = {
    {0u, 9u, 0},
    {9u, 6u, 0},
    {15u, 3u, 0},
};
constexpr ::b2o::Object kObjects[] = {
    {"Penta Gon", "Penta_Gon", 0u, 5u, 0u, 9u, 0u, 1u, ::b2o::kNone},
    {"class", "class_", 5u, 4u, 9u, 6u, 1u, 1u, 0},
    {"Penta-Gon", "Penta_Gon_2", 9u, 3u, 15u, 3u, 2u, 1u, ::b2o::kNone},
};
constexpr ::b2o::Cloth kCloths[] = {
    {1u, 4u, b2o_ngons_cloth0_rest_positions, b2o_ngons_cloth0_mass_vertex_offsets, b2o_ngons_cloth0_mass_vertices, nullptr,
     6u, b2o_ngons_cloth0_springs, 5u, 2u, b2o_ngons_cloth0_triangles, 0u, nullptr},
};
}  // namespace

const ::b2o::Scene scene = {
    ::b2o::kFormatVersion, "ngons", "ngons_crlf.obj",
    12u, b2o_ngons_positions, b2o_ngons_normals, b2o_ngons_texcoords,
    18u, b2o_ngons_indices,
    3u, kObjects,
    3u, kSubmeshes,
    1u, kMaterials,
    0u, nullptr,
    1u, kCloths,
    0u, nullptr,
};

extern const unsigned char* const bake_check;
const unsigned char* const bake_check = b2o_ngons_bake_1e7aa9874a450108;

}  // namespace b2o::gen::ngons
#endif  // B2O_NGONS_DEFINE_SCENE
#endif  // __ASSEMBLER__
#endif  // B2O_GEN_ngons_H
