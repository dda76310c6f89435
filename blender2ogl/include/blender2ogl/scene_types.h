// The baked scene: the one description of what blender2ogl writes and what programs read.
//
// Generated scene headers include this file; a generated source defines one `b2o::Scene`
// whose pointers refer to read-only arrays linked into the program (bulk data arrives through
// an assembler `.incbin` of a sidecar .bin, so it never passes through the C++ parser).
// Everything here is plain data: pointers, counts and PODs, no constructors, no allocation.
//
// Shapes are written as (rows x columns); all arrays are tightly packed, row-major.
#ifndef BLENDER2OGL_SCENE_TYPES_H
#define BLENDER2OGL_SCENE_TYPES_H

#include <cstdint>

namespace b2o {

/// Bumped whenever a field below changes; generated code static_asserts against it.
inline constexpr std::uint32_t kFormatVersion = 2;

/// Marks an absent index (no material, no texture, not a cloth).
inline constexpr std::int32_t kNone = -1;

enum class SpringKind : std::uint32_t {
  Structural = 0,  ///< a unique triangle edge
  Bend = 1,        ///< joins the two vertices opposite an interior edge
};

/// One spring between two masses of the same cloth (indices are local to the cloth).
struct Spring {
  std::uint32_t a, b;
  float rest_length;  ///< distance between the welded rest positions of a and b
  SpringKind kind;
};
static_assert(sizeof(Spring) == 16, "Spring is baked as 16 raw bytes");

/// An image as it was found next to the .mtl: the file's bytes, not decoded.
struct Texture {
  const char* name;             ///< path as written in the .mtl
  const unsigned char* bytes;   ///< (size) encoded file bytes: PNG, JPEG, ...
  std::uint32_t size;
};

/// A Wavefront material (the .mtl fields blender2ogl keeps).
struct Material {
  const char* name;
  float ambient[3];             ///< Ka
  float diffuse[3];             ///< Kd
  float specular[3];            ///< Ks
  float shininess;              ///< Ns
  float opacity;                ///< d
  std::int32_t diffuse_texture; ///< map_Kd: index into Scene::textures, or kNone
};

/// A run of triangles drawn with one material.
struct Submesh {
  std::uint32_t first_index;    ///< into Scene::indices (a multiple of 3)
  std::uint32_t index_count;    ///< a multiple of 3
  std::int32_t material;        ///< index into Scene::materials, or kNone
};

/// A named object of the export (an `o` or `g` of the OBJ). Its vertices, indices and
/// submeshes are contiguous ranges of the scene's arrays; indices are scene-global.
struct Object {
  const char* name;             ///< as written in the file
  const char* identifier;       ///< the C++ identifier the generated header uses for it
  std::uint32_t first_vertex, vertex_count;
  std::uint32_t first_index, index_count;
  std::uint32_t first_submesh, submesh_count;
  std::int32_t cloth;           ///< index into Scene::cloths, or kNone (a static collider)
};

/// Mass-spring data of one object given masses and springs (`-a OBJECT`).
/// Masses are the object's render vertices welded by exact position; mass indices are local.
struct Cloth {
  std::uint32_t object;                    ///< index into Scene::objects
  std::uint32_t mass_count;
  const float* rest_positions;             ///< (mass_count x 3)
  const std::uint32_t* mass_vertex_offsets;///< (mass_count + 1) CSR offsets into mass_vertices
  const std::uint32_t* mass_vertices;      ///< scene-global render vertices of each mass
  const std::uint32_t* vertex_mass;        ///< (object vertex_count) render vertex -> mass; nullptr without -r
  std::uint32_t spring_count;
  const Spring* springs;                   ///< (spring_count) structural first, then bend
  std::uint32_t structural_count;          ///< springs[0, structural_count) are structural
  std::uint32_t triangle_count;
  const std::uint32_t* triangles;          ///< (triangle_count x 3) mass indices, degenerate ones left out
  std::uint32_t pin_count;
  const std::uint32_t* pins;               ///< (pin_count) sorted mass indices that never move
};

/// A named value given to the bake (`--param key=value`), e.g. a scene's own dt or
/// integrator, as written: the program that reads the scene interprets it.
struct Param {
  const char* key;
  const char* value;  ///< the text after '=' ("0.002", "xpbd")
};

struct Scene {
  std::uint32_t format_version;            ///< == kFormatVersion
  const char* name;                        ///< the scene's name (the generated namespace)
  const char* source;                      ///< input file name, without directories
  std::uint32_t vertex_count;
  const float* positions;                  ///< (vertex_count x 3) as in the file (Blender: Y up)
  const float* normals;                    ///< (vertex_count x 3) from the file, or generated
  const float* texcoords;                  ///< (vertex_count x 2) zeros when the file had none
  std::uint32_t index_count;
  const std::uint32_t* indices;            ///< (index_count / 3 x 3) triangles
  std::uint32_t object_count;
  const Object* objects;
  std::uint32_t submesh_count;
  const Submesh* submeshes;
  std::uint32_t material_count;
  const Material* materials;
  std::uint32_t texture_count;
  const Texture* textures;
  std::uint32_t cloth_count;
  const Cloth* cloths;
  std::uint32_t param_count;
  const Param* params;
};

}  // namespace b2o

#endif  // BLENDER2OGL_SCENE_TYPES_H
