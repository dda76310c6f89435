// grid.cpp: tables of the scene baked by blender2ogl 0.1.0 from grid.obj.
// Generated: do not edit.
#include "grid.h"

static_assert(b2o::gen::grid::bake_id == 0x61e2c840d54b2dd6ull,
              "grid.h and grid.cpp come from different bakes; re-run blender2ogl");

// Bulk arrays, defined in grid.S from the bytes of grid.bin; the last symbol
// exists only in the .S of the same bake (a mixed set fails to link).
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
extern const unsigned char b2o_grid_bake_61e2c840d54b2dd6[];
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
    {"dt", 0x1.0624dd2f1a9fcp-9},  // 0.002
    {"k_rep", 0x1.f4p+10},  // 2000
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
const unsigned char* const bake_check = b2o_grid_bake_61e2c840d54b2dd6;

}  // namespace b2o::gen::grid
