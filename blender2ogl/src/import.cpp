// import: the model file into a Scene, stage by stage (import_*.cpp). The only code that parses
// model files (through assimp, after a light text check of .obj).
#include <fstream>

#include "import_stages.hpp"

namespace b2o::conv {
namespace {

// Refuses what is no readable model file; returns its extension in lower case.
std::string check_model_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw InputError(file.string() + ": is a directory, not a model file");
  if (!std::filesystem::exists(file, ec)) throw InputError(file.string() + ": no such file");
  {
    std::ifstream probe(file, std::ios::binary);
    if (!probe) throw InputError(file.string() + ": cannot open (permission denied?)");
  }
  const std::string ext = lower(file.extension().string());
  // assimp reads a file by its content when its extension is none it knows: an OBJ named
  // `model` or `x.obj.bak` would pass by the pre-scan (a '.5' coordinate silently loses a vertex)
  if (ext != ".obj" && (ext.empty() || !Assimp::Importer().IsExtensionSupported(ext)))
    throw InputError(file.string() + ": " + (ext.empty() ? std::string("no extension") : "'" + ext + "' is no model format") +
                     ": name a Blender export *.obj (other formats assimp reads by their extension: .fbx, .gltf, ...)");
  return ext;
}

// What the OBJ pre-scan found that the scene keeps: the text assimp reads, warnings, pin
// helpers' points and where each object name stands.
void take_obj_scan(const std::filesystem::path& file, ObjInput& obj, Scene& out) {
  ObjScan& scan = obj.scan;
  if (scan.cleaned) obj.replaced.emplace_back(file, std::move(scan.clean_text));
  if (scan.lines_points > 0)
    out.warnings.push_back(file.string() + ": " + std::to_string(scan.lines_points) +
                           " line/point elements ignored (only faces are drawn)");
  out.pin_points = scan.pin_points;
  out.object_lines = scan.object_lines;
  out.warnings.insert(out.warnings.end(), scan.warnings.begin(), scan.warnings.end());
}

}  // namespace

Scene import_scene(const std::filesystem::path& file, bool merge, bool allow_missing) {
  Scene out;
  out.source = file.filename().string();
  const bool is_obj = check_model_file(file) == ".obj";
  out.inputs_read.push_back(std::filesystem::absolute(file));

  auto t0 = std::chrono::steady_clock::now();
  ObjInput obj;
  if (is_obj) {
    obj.scan = prescan_obj_file(file);
    out.timings_ms.emplace_back("pre-scan", lap_ms(t0));
    check_material_libraries(file, allow_missing, obj, out);
    take_obj_scan(file, obj, out);
  }
  Assimp::Importer importer;
  NotSimpleFaces not_simple;
  const aiScene& ai = read_model(importer, file, is_obj, std::move(obj.replaced), not_simple, out);
  out.timings_ms.emplace_back("assimp", lap_ms(t0));
  const std::vector<std::int32_t> material_map = import_materials(ai, file, obj, allow_missing, out);
  import_objects(ai, file, is_obj, obj.scan, not_simple, material_map, out);
  out.timings_ms.emplace_back("join", lap_ms(t0));
  importer.FreeScene();  // before the bake: big scenes need the memory
  if (out.objects.empty()) throw InputError(file.string() + ": no triangles (empty scene)");
  remove_pin_helpers(out);
  if (out.objects.empty()) throw InputError(file.string() + ": no triangles besides pin helpers");

  if (merge && out.objects.size() > 1) {
    Object all;
    all.name = file.stem().string();
    all.vertex_count = static_cast<std::uint32_t>(out.positions.size() / 3);
    all.index_count = static_cast<std::uint32_t>(out.indices.size());
    all.submesh_count = static_cast<std::uint32_t>(out.submeshes.size());
    out.objects.assign(1, all);
  }
  return out;
}

}  // namespace b2o::conv
