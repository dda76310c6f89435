// The stages of import_scene (import.cpp), a file each: the OBJ's material libraries, the read
// with assimp, materials and textures, meshes and objects.
#ifndef BLENDER2OGL_IMPORT_STAGES_HPP
#define BLENDER2OGL_IMPORT_STAGES_HPP
#include <assimp/Importer.hpp>
#include <assimp/scene.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "converter.hpp"
#include "prescan.hpp"

namespace b2o::conv {

/// `s` with A-Z as a-z.
inline std::string lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

/// A map_Kd line and the .mtl it is in (to report a missing texture at its line).
struct MapKdOf {
  MapKd map;
  std::filesystem::path mtl;
};

/// Files assimp reads from these bytes instead of the file's (the pre-scans' cleaned text).
using ReplacedFiles = std::vector<std::pair<std::filesystem::path, std::string>>;

/// What the pre-scans of an OBJ and its material libraries give the rest of the import
/// (all empty for another format).
struct ObjInput {
  ObjScan scan;
  std::vector<MapKdOf> map_kd;
  ReplacedFiles replaced;
};

/// import_libraries.cpp: pre-scans the .obj's material libraries (a missing one refused, or
/// warned with `allow_missing`) and warns of `usemtl` names none defines. Their map_Kd lines and
/// cleaned text go to `obj`; warnings and the files read to `out`.
void check_material_libraries(const std::filesystem::path& file, bool allow_missing, ObjInput& obj, Scene& out);

/// import_assimp.cpp: reads `file` with assimp (read_with_assimp) through `replaced`; refuses
/// what assimp cannot read or repairs (another format's index out of range), and a scene
/// without meshes. The scene belongs to `importer`.
const aiScene& read_model(Assimp::Importer& importer, const std::filesystem::path& file, bool is_obj,
                          ReplacedFiles replaced, NotSimpleFaces& not_simple, Scene& out);

/// import_materials.cpp: the scene's materials into out.materials, their textures read and
/// decoded into out.textures. Returns per assimp material its index in out.materials (-1: left out).
std::vector<std::int32_t> import_materials(const aiScene& ai, const std::filesystem::path& file, const ObjInput& obj,
                                           bool allow_missing, Scene& out);

/// import_mesh.cpp: appends a triangle mesh, transformed, to out's positions, normals,
/// texcoords and indices; corners with bit-identical attributes become one vertex. `object`
/// ("file: object 'name'") starts its messages.
void append_mesh(const aiMesh& mesh, const aiMatrix4x4& transform, const std::string& object, Scene& out);

/// import_objects.cpp: the nodes with meshes become objects (depth first, in file order), a
/// name seen twice in a row one object.
void import_objects(const aiScene& ai, const std::filesystem::path& file, bool is_obj, const ObjScan& scan,
                    const NotSimpleFaces& not_simple, const std::vector<std::int32_t>& material_map, Scene& out);

/// import_objects.cpp: `<OBJECT>_pins` helpers become pin points and leave the scene (their
/// vertices too).
void remove_pin_helpers(Scene& s);

}  // namespace b2o::conv
#endif
