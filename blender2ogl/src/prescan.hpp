#ifndef BLENDER2OGL_PRESCAN_HPP
#define BLENDER2OGL_PRESCAN_HPP
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace b2o::conv {

struct ObjScan {
  std::size_t positions = 0, texcoords = 0, normals = 0, faces = 0, lines_points = 0, groups = 0;
  std::vector<std::string> mtllibs;
  std::vector<std::size_t> mtllib_lines;
  /// Per mtllib: true when it is not the first library of its line (`mtllib a.mtl b.mtl`,
  /// when no file has the whole name): assimp reads one name per line, so it is given the
  /// first one, whose text then carries the others' after its own.
  std::vector<bool> mtllib_joined;
  /// Vertices written under an `o`/`g` named `<OBJECT>_pins` or `<OBJECT>.pins` (x y z ...):
  /// assimp drops objects without faces, so pin helpers made of loose vertices are read here.
  std::map<std::string, std::vector<float>> pin_points;
  /// The lines where an object of each name starts (a name on several lines: repeated `g`).
  std::map<std::string, std::vector<std::size_t>> object_lines;
  /// "file:line: what" (reported as warnings)
  std::vector<std::string> warnings;
  /// `usemtl` statements: the name as assimp reads it (the rest of the line) and the line.
  std::vector<std::pair<std::string, std::size_t>> usemtl;
  /// The bytes assimp is given instead of the file's when they differ (a UTF-8 byte-order
  /// mark removed); empty: the file as it is.
  std::string clean_text;
  bool cleaned = false;
};

/// Throws InputError ("file:line: what") on text assimp would misread.
ObjScan prescan_obj_file(const std::filesystem::path& file);

/// Checks a .mtl the same way (assimp 5.2.5 crashes on a statement before the first
/// `newmtl`). Throws InputError ("file:line: what").
/// Returns its `map_Kd` lines (argument as written, line number) so a missing texture can be
/// reported at its line.
struct MapKd {
  std::string argument;
  std::size_t line = 0;
};
struct MtlScan {
  std::vector<MapKd> maps;
  std::vector<std::string> materials;  ///< `newmtl` names as assimp reads them
  std::vector<std::string> warnings;   ///< "file:line: what"
  /// The bytes assimp is given instead of the file's when they differ (a byte-order mark
  /// removed, a one-number color `Kd 1` written out as `Kd 1 1 1`).
  std::string clean_text;
  bool cleaned = false;
};
/// `model_folder`: the .obj's folder; a relative texture name of a .mtl in another folder is
/// given (and returned) relative to it.
MtlScan prescan_mtl_file(const std::filesystem::path& file, const std::filesystem::path& model_folder = {});

/// An `o`/`g` name as assimp is given it: ' ', tab, form feed, vertical tab, '#' and '%' as
/// %XX (upper-case hex), so that assimp keeps the whole name; every other byte as it is.
std::string encode_object_name(const std::string& name);
/// The inverse, applied to every object name assimp reports for an OBJ file.
std::string decode_object_name(const std::string& name);

bool is_pin_object_name(const std::string& name);
/// "Cloth_pins" -> "Cloth"
std::string pin_target_name(const std::string& name);

}  // namespace b2o::conv
#endif
