// blender2ogl's library: import (assimp) -> bake (weld, springs, pins, names) -> emit (C++).
// The converter's own in-memory scene lives here; what is written follows b2o::Scene
// (blender2ogl/scene_types.h) field by field.
#ifndef BLENDER2OGL_CONVERTER_HPP
#define BLENDER2OGL_CONVERTER_HPP

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace Assimp {
class Importer;
}
struct aiNode;
struct aiScene;

namespace b2o::conv {

inline constexpr const char* kVersion = "0.1.0";

/// Bad input: the message already names the file (and the line when known). Exit code 1.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// Bad command line. Exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct PinSpec {
  std::string object;
  std::array<float, 3> point{};
};

struct Options {
  std::filesystem::path input;
  std::filesystem::path target_dir;  ///< empty: the input's folder
  std::string name;                  ///< empty: the input's stem, cleaned
  bool combined = false;             ///< -c: one header with everything as text
  bool merge = false;                ///< -m: all objects into one
  bool reverse_map = false;          ///< -r
  bool object_metadata = false;      ///< -o (always emitted; kept for compatibility)
  bool verbose = false;              ///< -v
  std::vector<std::string> cloth_objects;  ///< -a
  std::vector<PinSpec> pins;               ///< -p
  std::vector<std::pair<std::string, std::string>> params;  ///< --param, in command-line order
  std::filesystem::path depfile;           ///< --depfile: Makefile-style list of inputs read
  bool allow_missing = false;  ///< --allow-missing: a missing .mtl or texture is a warning, not an error
};

struct Material {
  std::string name;
  std::array<float, 3> ambient{}, diffuse{}, specular{};
  float shininess = 0.0f, opacity = 1.0f;
  std::int32_t diffuse_texture = -1;
};

struct Texture {
  std::string name;  ///< as written in the .mtl (relative to the model's folder when the .mtl is in another)
  std::vector<unsigned char> bytes;
};

struct Submesh {
  std::uint32_t first_index = 0, index_count = 0;
  std::int32_t material = -1;
};

struct Object {
  std::string name, identifier;
  std::uint32_t first_vertex = 0, vertex_count = 0;
  std::uint32_t first_index = 0, index_count = 0;
  std::uint32_t first_submesh = 0, submesh_count = 0;
  std::int32_t cloth = -1;
};

struct Spring {
  std::uint32_t a = 0, b = 0;
  float rest_length = 0.0f;
  std::uint32_t kind = 0;  ///< b2o::SpringKind
};

struct Cloth {
  std::uint32_t object = 0;
  std::vector<float> rest_positions;            ///< (masses x 3)
  std::vector<std::uint32_t> mass_vertex_offsets;  ///< (masses + 1)
  std::vector<std::uint32_t> mass_vertices;     ///< scene-global render vertices
  std::vector<std::uint32_t> vertex_mass;       ///< (object vertices), empty without -r
  std::vector<Spring> springs;
  std::uint32_t structural_count = 0;
  std::vector<std::uint32_t> triangles;         ///< (n x 3) mass indices
  std::vector<std::uint32_t> pins;
  std::uint32_t mass_count() const { return static_cast<std::uint32_t>(rest_positions.size() / 3); }
};

struct Stats {
  std::uint32_t warnings = 0;
  std::uint32_t nonmanifold_edges = 0, degenerate_triangles = 0, loose_vertices = 0;
};

struct Scene {
  std::string name;    ///< the C++ identifier (namespace and file stem)
  std::string source;  ///< input file name without directories
  std::vector<float> positions, normals, texcoords;
  std::vector<std::uint32_t> indices;
  std::vector<Object> objects;
  std::vector<Submesh> submeshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Cloth> cloths;
  std::vector<std::pair<std::string, std::string>> params;
  std::vector<std::filesystem::path> inputs_read;  ///< .obj, .mtl, textures (for the depfile)
  std::vector<std::string> warnings;
  std::vector<std::pair<std::string, double>> timings_ms;  ///< phase -> milliseconds (-v)
  /// Points of `<OBJECT>_pins` helper objects (x y z ...), keyed by the helper's name;
  /// the helpers themselves are not emitted.
  std::map<std::string, std::vector<float>> pin_points;
  /// OBJ: the lines where an object of each name starts (to tell a name given twice).
  std::map<std::string, std::vector<std::size_t>> object_lines;
};

/// Milliseconds since `t0`, and resets `t0`.
inline double lap_ms(std::chrono::steady_clock::time_point& t0) {
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - t0).count();
  t0 = now;
  return ms;
}

/// Triangulates one polygon: `xyz` holds its corners' positions (x y z per corner, in face
/// order); appends (corners - 2) triangles of corner numbers (0 = the first corner) to
/// `triangles`, wound as the polygon. Projected along its (Newell) normal; a quad is a fan
/// from its reflex corner, else from corner 0 (as assimp for a planar quad; a non-planar one may
/// differ, the reflex corner being found in the projection); more corners are cut into ears
/// (strictly convex, no other corner in or on them), for a convex polygon exactly as assimp
/// 5.2 does. False when no ear was left (a self-intersecting or degenerate polygon), when a
/// quad is a bow-tie, or when the ear search ran past its budget (a face of thousands of
/// corners in a thin ring): the rest is then a fan.
bool triangulate_polygon(std::span<const float> xyz, std::vector<std::uint32_t>& triangles);

/// Faces that were not simple polygons (triangulate_polygon returned false), per node.
using NotSimpleFaces = std::map<const aiNode*, std::size_t>;

/// Reads `file` with assimp as the converter does (the tests and benchmarks read through this
/// too): the importer alone (ValidateDataStructure), faces with more than 3 corners
/// triangulated by triangulate_polygon (not aiProcess_Triangulate), then GenSmoothNormals |
/// SortByPType (points and lines removed) | ValidateDataStructure. Null when assimp fails
/// (importer.GetErrorString() says why). The scene belongs to `importer`.
const aiScene* read_with_assimp(Assimp::Importer& importer, const std::string& file, NotSimpleFaces* not_simple = nullptr);

/// Reads the model with assimp into a Scene (geometry, objects, materials, textures).
/// A missing or unreadable .mtl or texture is an InputError unless `allow_missing`
/// (then a warning: default material / no texture).
Scene import_scene(const std::filesystem::path& file, bool merge, bool allow_missing = false);

/// Input text quoted in a message: 'text', clipped to 60 bytes with "..." (a megabyte token
/// must not become a megabyte line).
inline std::string quote_input(std::string_view text) {
  constexpr std::size_t kMax = 60;
  std::size_t cut = text.size();
  if (cut > kMax) {
    cut = kMax;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8 characters
  }
  // (appended piece by piece: "'" + std::string + "'" trips g++ 12's -Wrestrict when inlined)
  std::string out;
  out.reserve(cut + 5);
  out.push_back('\'');
  out.append(text.substr(0, cut));
  if (cut < text.size()) out.append("...");
  out.push_back('\'');
  return out;
}

/// Cleans `name` into a C++ identifier (not a keyword, no reserved spelling).
std::string clean_identifier(const std::string& name);
/// Gives every object a distinct, stable identifier in file order.
void assign_identifiers(Scene& scene);

/// Turns `<OBJECT>_pins` objects into pin points, builds cloths for `-a` objects and pins.
void bake_scene(Scene& scene, const Options& options, Stats& stats);

/// One generated file: name (no directory) and bytes.
struct OutputFile {
  std::string name;
  std::string bytes;
};
std::vector<OutputFile> emit_scene(const Scene& scene, const Options& options);

/// Writes all files atomically into `dir` (temp files, then renames; unchanged files are
/// left alone), with `extra` files at their own paths (the depfile) in the same commit,
/// published before the header. A character device or FIFO in an output's place is written
/// into (never renamed over); any other non-regular file there is refused before anything is
/// written. Returns how many files were replaced.
int write_outputs(const std::filesystem::path& dir, const std::vector<OutputFile>& files,
                  const std::vector<std::pair<std::filesystem::path, std::string>>& extra = {});

/// Deletes `<name>.<hash>.bin` files in `dir` that are not in `keep` (older bakes' bulk data,
/// after the new header is in place) and temp files of `name`'s outputs left by a killed run.
/// Files in `protect` (the inputs) are never deleted.
void remove_stale_bins(const std::filesystem::path& dir, const std::string& name, const std::vector<OutputFile>& keep,
                       const std::vector<std::filesystem::path>& protect = {});

/// FNV-1a 64 of bytes, as 16 hex digits.
std::string hash_hex(const std::string& bytes);

/// The whole conversion (everything but argument parsing); prints warnings to `log`.
int run(const Options& options, std::ostream& log);

}  // namespace b2o::conv

#endif
