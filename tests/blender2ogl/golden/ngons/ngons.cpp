// ngons.cpp: tables of the scene baked by blender2ogl 0.1.0 from ngons_crlf.obj.
// Generated: do not edit.
#include "ngons.h"

static_assert(b2o::gen::ngons::bake_id == 0x458f1accc7c24307ull,
              "ngons.h and ngons.cpp come from different bakes; re-run blender2ogl");

// Bulk arrays, defined in ngons.S from the bytes of ngons.bin; the last symbol
// exists only in the .S of the same bake (a mixed set fails to link).
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
extern const unsigned char b2o_ngons_bake_458f1accc7c24307[];
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
const unsigned char* const bake_check = b2o_ngons_bake_458f1accc7c24307;

}  // namespace b2o::gen::ngons
