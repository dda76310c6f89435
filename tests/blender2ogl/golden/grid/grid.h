// grid.h: the scene baked by blender2ogl 0.1.0 from grid.obj.
// Generated: do not edit; change the model and re-run the bake.
//
//   #include "grid.h"
//   const b2o::Scene& s = b2o::gen::grid::scene;  // fields: blender2ogl/scene_types.h
//   const b2o::Object& o = s.objects[b2o::gen::grid::object::Cloth];
//
// Object and cloth indices below are named after the objects (cleaned into C++
// identifiers; Object::name keeps the name as written in the file).
#ifndef B2O_GEN_grid_H
#define B2O_GEN_grid_H

#ifdef __ASSEMBLER__
/* Bulk arrays, assembled through grid.S: the bytes of grid.37536d974c7f0738.bin
   (1400 bytes, fnv1a64 37536d974c7f0738), found through -I<dir>. */
	.section .rodata.b2o.grid,"a",@progbits
	.balign 16
	.globl b2o_grid_positions
	.type b2o_grid_positions, @object
	.size b2o_grid_positions, 156
b2o_grid_positions:
	.incbin "grid.37536d974c7f0738.bin", 0, 156
	.balign 16
	.globl b2o_grid_normals
	.type b2o_grid_normals, @object
	.size b2o_grid_normals, 156
b2o_grid_normals:
	.incbin "grid.37536d974c7f0738.bin", 160, 156
	.balign 16
	.globl b2o_grid_texcoords
	.type b2o_grid_texcoords, @object
	.size b2o_grid_texcoords, 104
b2o_grid_texcoords:
	.incbin "grid.37536d974c7f0738.bin", 320, 104
	.balign 16
	.globl b2o_grid_indices
	.type b2o_grid_indices, @object
	.size b2o_grid_indices, 120
b2o_grid_indices:
	.incbin "grid.37536d974c7f0738.bin", 432, 120
	.balign 16
	.globl b2o_grid_texture0
	.type b2o_grid_texture0, @object
	.size b2o_grid_texture0, 81
b2o_grid_texture0:
	.incbin "grid.37536d974c7f0738.bin", 560, 81
	.balign 16
	.globl b2o_grid_cloth0_rest_positions
	.type b2o_grid_cloth0_rest_positions, @object
	.size b2o_grid_cloth0_rest_positions, 108
b2o_grid_cloth0_rest_positions:
	.incbin "grid.37536d974c7f0738.bin", 656, 108
	.balign 16
	.globl b2o_grid_cloth0_mass_vertex_offsets
	.type b2o_grid_cloth0_mass_vertex_offsets, @object
	.size b2o_grid_cloth0_mass_vertex_offsets, 40
b2o_grid_cloth0_mass_vertex_offsets:
	.incbin "grid.37536d974c7f0738.bin", 768, 40
	.balign 16
	.globl b2o_grid_cloth0_mass_vertices
	.type b2o_grid_cloth0_mass_vertices, @object
	.size b2o_grid_cloth0_mass_vertices, 36
b2o_grid_cloth0_mass_vertices:
	.incbin "grid.37536d974c7f0738.bin", 816, 36
	.balign 16
	.globl b2o_grid_cloth0_vertex_mass
	.type b2o_grid_cloth0_vertex_mass, @object
	.size b2o_grid_cloth0_vertex_mass, 36
b2o_grid_cloth0_vertex_mass:
	.incbin "grid.37536d974c7f0738.bin", 864, 36
	.balign 16
	.globl b2o_grid_cloth0_springs
	.type b2o_grid_cloth0_springs, @object
	.size b2o_grid_cloth0_springs, 384
b2o_grid_cloth0_springs:
	.incbin "grid.37536d974c7f0738.bin", 912, 384
	.balign 16
	.globl b2o_grid_cloth0_triangles
	.type b2o_grid_cloth0_triangles, @object
	.size b2o_grid_cloth0_triangles, 96
b2o_grid_cloth0_triangles:
	.incbin "grid.37536d974c7f0738.bin", 1296, 96
	.balign 16
	.globl b2o_grid_cloth0_pins
	.type b2o_grid_cloth0_pins, @object
	.size b2o_grid_cloth0_pins, 8
b2o_grid_cloth0_pins:
	.incbin "grid.37536d974c7f0738.bin", 1392, 8
	.globl b2o_grid_bake_009761ee67fe4ce9
	.type b2o_grid_bake_009761ee67fe4ce9, @object
	.size b2o_grid_bake_009761ee67fe4ce9, 1
b2o_grid_bake_009761ee67fe4ce9:
	.byte 0
	.section .note.GNU-stack,"",@progbits
#else  // C++ from here on

#include <blender2ogl/scene_types.h>

#include <cstdint>
#include <cstring>

static_assert(::b2o::kFormatVersion == 2, "grid.h was baked for scene format 2; re-run blender2ogl");

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
/// Identifies this bake (its tables and bulk bytes).
inline constexpr std::uint64_t bake_id = 0x009761ee67fe4ce9ull;

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

/// The value baked with `--param key=value` (its text), or `fallback` when the bake had none.
inline const char* param(const char* key, const char* fallback) noexcept {
  for (std::uint32_t i = 0; i < scene.param_count; ++i)
    if (std::strcmp(scene.params[i].key, key) == 0) return scene.params[i].value;
  return fallback;
}

}  // namespace b2o::gen::grid

#ifdef B2O_GRID_DEFINE_SCENE
// Compiled once, in grid.cpp: the small tables as text; the bulk arrays are the
// symbols of the assembler part above. The last symbol exists only in an object assembled
// from this very header (a stale grid.S object fails to link).
extern "C" {
extern const float b2o_grid_positions[];
extern const float b2o_grid_normals[];
extern const float b2o_grid_texcoords[];
extern const std::uint32_t b2o_grid_indices[];
extern const unsigned char b2o_grid_texture0[];
extern const float b2o_grid_cloth0_rest_positions[];
extern const std::uint32_t b2o_grid_cloth0_mass_vertex_offsets[];
extern const std::uint32_t b2o_grid_cloth0_mass_vertices[];
extern const std::uint32_t b2o_grid_cloth0_vertex_mass[];
extern const ::b2o::Spring b2o_grid_cloth0_springs[];
extern const std::uint32_t b2o_grid_cloth0_triangles[];
extern const std::uint32_t b2o_grid_cloth0_pins[];
extern const unsigned char b2o_grid_bake_009761ee67fe4ce9[];
}

namespace b2o::gen::grid {
namespace {
constexpr ::b2o::Texture kTextures[] = {
    {"checker.png", b2o_grid_texture0, 81u},
};
constexpr ::b2o::Material kMaterials[] = {
    {"Checker", {0x1p+0f, 0x1p+0f, 0x1p+0f}, {0x1.99999ap-1f, 0x1.666666p-1f, 0x1.333334p-1f}, {0x1p-1f, 0x1p-1f, 0x1p-1f}, 0x1.f4p+7f, 0x1p+0f, 0},
    {"Ground", {0x1.99999ap-4f, 0x1.99999ap-4f, 0x1.99999ap-4f}, {0x1.99999ap-3f, 0x1.333334p-2f, 0x1.99999ap-2f}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, 0x1.4p+3f, 0x1p-1f, ::b2o::kNone},
};
constexpr ::b2o::Submesh kSubmeshes[] = {
    {0u, 24u, 0},
    {24u, 6u, 1},
};
constexpr ::b2o::Object kObjects[] = {
    {"Cloth", "Cloth", 0u, 9u, 0u, 24u, 0u, 1u, 0},
    {"Floor", "Floor", 9u, 4u, 24u, 6u, 1u, 1u, ::b2o::kNone},
};
constexpr ::b2o::Cloth kCloths[] = {
    {0u, 9u, b2o_grid_cloth0_rest_positions, b2o_grid_cloth0_mass_vertex_offsets, b2o_grid_cloth0_mass_vertices, b2o_grid_cloth0_vertex_mass,
     24u, b2o_grid_cloth0_springs, 16u, 8u, b2o_grid_cloth0_triangles, 2u, b2o_grid_cloth0_pins},
};
constexpr ::b2o::Param kParams[] = {
    {"dt", "0.002"},
    {"k_rep", "2000"},
};
}  // namespace

const ::b2o::Scene scene = {
    ::b2o::kFormatVersion, "grid", "grid.obj",
    13u, b2o_grid_positions, b2o_grid_normals, b2o_grid_texcoords,
    30u, b2o_grid_indices,
    2u, kObjects,
    2u, kSubmeshes,
    2u, kMaterials,
    1u, kTextures,
    1u, kCloths,
    2u, kParams,
};

extern const unsigned char* const bake_check;
const unsigned char* const bake_check = b2o_grid_bake_009761ee67fe4ce9;

}  // namespace b2o::gen::grid
#endif  // B2O_GRID_DEFINE_SCENE
#endif  // __ASSEMBLER__
#endif  // B2O_GEN_grid_H
