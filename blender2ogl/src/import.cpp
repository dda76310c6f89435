// import: the only code that parses model files (through assimp, after a light text check of .obj).
#include <assimp/DefaultIOSystem.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <stb/stb_image.h>

#include <algorithm>
#include <cstring>
#include <cmath>
#include <fstream>
#include <map>
#include <functional>
#include <limits>
#include <memory>
#include <set>
#include <sstream>

#include "converter.hpp"
#include "prescan.hpp"

namespace b2o::conv {
namespace {

std::string lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

// Empty when stb_image decodes the bytes (what the viewer uses), else stb's reason.
std::string undecodable_image(const std::string& bytes) {
  if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) return "larger than 2 GiB";
  int w = 0, h = 0, channels = 0;
  stbi_uc* pixels = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), static_cast<int>(bytes.size()),
                                          &w, &h, &channels, 4);
  if (pixels == nullptr) {
    const char* reason = stbi_failure_reason();
    return reason != nullptr ? reason : "unknown format";
  }
  stbi_image_free(pixels);
  return {};
}

bool finite3(const aiVector3D& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

bool is_identity(const aiMatrix4x4& m) { return m.IsIdentity(); }

// Reads a material's fields as assimp reports them (the OBJ importer maps Ka/Kd/Ks/Ns/d).
Material read_material(const aiMaterial& m) {
  Material out;
  aiString name;
  if (m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) out.name = name.C_Str();
  aiColor3D c;
  if (m.Get(AI_MATKEY_COLOR_AMBIENT, c) == AI_SUCCESS) out.ambient = {c.r, c.g, c.b};
  if (m.Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS) out.diffuse = {c.r, c.g, c.b};
  if (m.Get(AI_MATKEY_COLOR_SPECULAR, c) == AI_SUCCESS) out.specular = {c.r, c.g, c.b};
  float f = 0.0f;
  if (m.Get(AI_MATKEY_SHININESS, f) == AI_SUCCESS) out.shininess = f;
  if (m.Get(AI_MATKEY_OPACITY, f) == AI_SUCCESS) out.opacity = f;
  auto finite = [](float v) { return std::isfinite(v); };
  if (!std::all_of(out.ambient.begin(), out.ambient.end(), finite) ||
      !std::all_of(out.diffuse.begin(), out.diffuse.end(), finite) ||
      !std::all_of(out.specular.begin(), out.specular.end(), finite) || !finite(out.shininess) ||
      !finite(out.opacity))
    throw std::runtime_error("material " + quote_input(out.name) + " has a non-finite value");
  return out;
}

// A file's bytes (a material library the pre-scan read already).
std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(file.string() + ": cannot read");
  return text.str();
}

// What assimp reads: the model as the pre-scan cleaned it (when it did), and .obj/.mtl files
// without a UTF-8 byte-order mark (assimp 5.2.5 would take it as part of the first statement).
// Other files, and relative paths (mtllib, textures), go through the default file system.
class CheckedIO : public Assimp::DefaultIOSystem {
 public:
  /// `replaced`: files assimp reads from these bytes instead (the pre-scan's cleaned text).
  explicit CheckedIO(std::vector<std::pair<std::filesystem::path, std::string>> replaced)
      : replaced_(std::move(replaced)) {}
  Assimp::IOStream* Open(const char* path, const char* mode) override {
    const std::string m = mode == nullptr ? "rb" : mode;
    const bool reading = m.find_first_of("wa+") == std::string::npos;
    std::error_code ec;
    for (const auto& [file, text] : replaced_)
      if (reading && std::filesystem::equivalent(path, file, ec))
        return new Assimp::MemoryIOStream(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
    Assimp::IOStream* s = DefaultIOSystem::Open(path, mode);
    const std::string ext = lower(std::filesystem::path(path).extension().string());
    if (s == nullptr || !reading || (ext != ".obj" && ext != ".mtl")) return s;
    const std::size_t size = s->FileSize();
    char head[3] = {0, 0, 0};
    if (size < 3 || s->Read(head, 1, 3) != 3 || std::memcmp(head, "\xEF\xBB\xBF", 3) != 0) {
      s->Seek(0, aiOrigin_SET);
      return s;
    }
    auto* bytes = new std::uint8_t[size - 3 + 1];
    const std::size_t got = size > 3 ? s->Read(bytes, 1, size - 3) : 0;
    DefaultIOSystem::Close(s);
    return new Assimp::MemoryIOStream(bytes, got, true);
  }

 private:
  std::vector<std::pair<std::filesystem::path, std::string>> replaced_;
};

// The errors assimp's importers log while they go on: for formats without the pre-scan they
// mean repaired input (the OFF importer clamps a face index out of range to the last vertex).
class AssimpErrors {
 public:
  AssimpErrors() {
    Assimp::DefaultLogger::create(nullptr, Assimp::Logger::NORMAL, 0);
    Assimp::DefaultLogger::get()->attachStream(new Capture(messages), Assimp::Logger::Err);
  }
  ~AssimpErrors() { Assimp::DefaultLogger::kill(); }
  AssimpErrors(const AssimpErrors&) = delete;
  AssimpErrors& operator=(const AssimpErrors&) = delete;
  std::vector<std::string> messages;

 private:
  struct Capture : Assimp::LogStream {
    explicit Capture(std::vector<std::string>& to) : out(to) {}
    void write(const char* message) override {
      std::string m = message;
      if (m.rfind("Error, ", 0) == 0 && m.find(": ") != std::string::npos) m.erase(0, m.find(": ") + 2);
      while (!m.empty() && (m.back() == '\n' || m.back() == '\r')) m.pop_back();
      out.push_back(m);
    }
    std::vector<std::string>& out;
  };
};

// `<OBJECT>_pins` helpers become pin points and leave the scene (their vertices too).
void remove_pin_helpers(Scene& s) {
  std::vector<std::uint32_t> new_vertex(s.positions.size() / 3, 0);
  Scene kept;
  for (const Object& o : s.objects) {
    if (is_pin_object_name(o.name)) {
      auto& pts = s.pin_points[o.name];
      if (pts.empty())
        pts.assign(s.positions.begin() + 3 * o.first_vertex, s.positions.begin() + 3 * (o.first_vertex + o.vertex_count));
      continue;
    }
    Object n = o;
    n.first_vertex = static_cast<std::uint32_t>(kept.positions.size() / 3);
    n.first_index = static_cast<std::uint32_t>(kept.indices.size());
    n.first_submesh = static_cast<std::uint32_t>(kept.submeshes.size());
    for (std::uint32_t v = o.first_vertex; v < o.first_vertex + o.vertex_count; ++v) {
      new_vertex[v] = static_cast<std::uint32_t>(kept.positions.size() / 3);
      kept.positions.insert(kept.positions.end(), s.positions.begin() + 3 * v, s.positions.begin() + 3 * v + 3);
      kept.normals.insert(kept.normals.end(), s.normals.begin() + 3 * v, s.normals.begin() + 3 * v + 3);
      kept.texcoords.insert(kept.texcoords.end(), s.texcoords.begin() + 2 * v, s.texcoords.begin() + 2 * v + 2);
    }
    for (std::uint32_t k = 0; k < o.submesh_count; ++k) {
      Submesh sm = s.submeshes[o.first_submesh + k];
      const std::uint32_t first = sm.first_index;
      sm.first_index = static_cast<std::uint32_t>(kept.indices.size());
      for (std::uint32_t i = first; i < first + sm.index_count; ++i) kept.indices.push_back(new_vertex[s.indices[i]]);
      kept.submeshes.push_back(sm);
    }
    kept.objects.push_back(std::move(n));
  }
  if (kept.objects.size() == s.objects.size()) return;
  s.positions = std::move(kept.positions);
  s.normals = std::move(kept.normals);
  s.texcoords = std::move(kept.texcoords);
  s.indices = std::move(kept.indices);
  s.submeshes = std::move(kept.submeshes);
  s.objects = std::move(kept.objects);
}

}  // namespace

namespace {

// aiProcess_Triangulate marks its output NGON-encoded (aiPrimitiveType_NGONEncodingFlag):
// consecutive triangles with one first corner belong to one polygon, so a triangle whose
// first corner is the previous polygon's is rotated. The same here, so the corners come in
// assimp's order (and the output is unchanged where the triangles are).
struct NgonEncoder {
  unsigned last = std::numeric_limits<unsigned>::max();
  void triangle(unsigned* t) {
    if (t[0] == last) std::swap(t[0], t[2]), std::swap(t[1], t[2]);
    last = t[0];
  }
  void quad(unsigned* t1, unsigned* t2) {  // a fan of two: t1[0] == t2[0]
    if (t1[0] == last) {
      std::swap(t1[0], t1[2]), std::swap(t1[1], t1[2]);
      std::swap(t2[1], t2[2]), std::swap(t2[0], t2[2]);
    }
    last = t1[0];
  }
};

// Faces with more than 3 corners become triangles (triangulate_polygon), in place, as
// aiProcess_Triangulate would leave the mesh. Returns how many faces were not simple.
std::size_t triangulate_mesh(aiMesh& mesh) {
  std::size_t faces_out = 0;
  bool polygons = false;
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const unsigned n = mesh.mFaces[f].mNumIndices;
    polygons = polygons || n > 3;
    faces_out += n > 3 ? n - 2 : 1;
  }
  if (!polygons) return 0;
  std::unique_ptr<aiFace[]> out(new aiFace[faces_out]);
  aiFace* cur = out.get();
  NgonEncoder encoder;
  std::size_t not_simple = 0;
  std::vector<float> xyz;
  std::vector<std::uint32_t> tris;
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    aiFace& face = mesh.mFaces[f];
    const unsigned n = face.mNumIndices;
    if (n <= 3) {
      cur->mNumIndices = n;
      cur->mIndices = face.mIndices;
      face.mIndices = nullptr;
      if (n == 3) encoder.triangle(cur->mIndices);
      ++cur;
      continue;
    }
    xyz.resize(3 * static_cast<std::size_t>(n));
    for (unsigned c = 0; c < n; ++c) {
      // (ValidateDataStructure has refused indices out of range; kept safe anyway)
      const aiVector3D p = face.mIndices[c] < mesh.mNumVertices ? mesh.mVertices[face.mIndices[c]] : aiVector3D();
      xyz[3 * c] = p.x, xyz[3 * c + 1] = p.y, xyz[3 * c + 2] = p.z;
    }
    tris.clear();
    if (!triangulate_polygon(xyz, tris)) ++not_simple;
    aiFace* const first = cur;
    for (std::size_t t = 0; t < tris.size(); t += 3, ++cur) {
      cur->mNumIndices = 3;
      cur->mIndices = new unsigned[3];
      for (std::size_t c = 0; c < 3; ++c) cur->mIndices[c] = face.mIndices[tris[t + c]];
    }
    if (n == 4)
      encoder.quad(first[0].mIndices, first[1].mIndices);
    else
      for (aiFace* t = first; t != cur; ++t) encoder.triangle(t->mIndices);
  }
  delete[] mesh.mFaces;
  mesh.mNumFaces = static_cast<unsigned>(cur - out.get());
  mesh.mFaces = out.release();
  mesh.mPrimitiveTypes = (mesh.mPrimitiveTypes & ~static_cast<unsigned>(aiPrimitiveType_POLYGON)) |
                         aiPrimitiveType_TRIANGLE | aiPrimitiveType_NGONEncodingFlag;
  return not_simple;
}

}  // namespace

const aiScene* read_with_assimp(Assimp::Importer& importer, const std::string& file, NotSimpleFaces* not_simple) {
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* read = importer.ReadFile(file, aiProcess_ValidateDataStructure);
  if (read == nullptr) return nullptr;
  // (the scene is the importer's; assimp's own steps change it in place just so)
  auto* scene = const_cast<aiScene*>(read);
  std::vector<std::size_t> per_mesh(scene->mNumMeshes, 0);
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
    if (scene->mMeshes[m] != nullptr) per_mesh[m] = triangulate_mesh(*scene->mMeshes[m]);
  // per node: SortByPType renumbers the meshes, the nodes stay
  if (not_simple != nullptr) {
    std::function<void(const aiNode*)> walk = [&](const aiNode* node) {
      std::size_t count = 0;
      for (unsigned k = 0; k < node->mNumMeshes; ++k)
        if (node->mMeshes[k] < per_mesh.size()) count += per_mesh[node->mMeshes[k]];
      if (count > 0) (*not_simple)[node] += count;
      for (unsigned i = 0; i < node->mNumChildren; ++i) walk(node->mChildren[i]);
    };
    if (scene->mRootNode != nullptr) walk(scene->mRootNode);
  }
  // JoinIdenticalVertices is done exactly by import_scene. Not SplitLargeMeshes /
  // PreTransformVertices / OptimizeMeshes / OptimizeGraph: they split big cloths, move
  // vertices or merge objects.
  return importer.ApplyPostProcessing(aiProcess_GenSmoothNormals | aiProcess_SortByPType |
                                      aiProcess_ValidateDataStructure);
}

Scene import_scene(const std::filesystem::path& file, bool merge, bool allow_missing) {
  Scene out;
  out.source = file.filename().string();
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw InputError(file.string() + ": is a directory, not a model file");
  if (!std::filesystem::exists(file, ec)) throw InputError(file.string() + ": no such file");
  {
    std::ifstream probe(file, std::ios::binary);
    if (!probe) throw InputError(file.string() + ": cannot open (permission denied?)");
  }
  const std::string ext = lower(file.extension().string());
  const bool is_obj = ext == ".obj";
  // assimp reads a file by its content when its extension is none it knows: an OBJ named
  // `model` or `x.obj.bak` went past the pre-scan (a '.5' coordinate silently lost a vertex)
  if (!is_obj && (ext.empty() || !Assimp::Importer().IsExtensionSupported(ext)))
    throw InputError(file.string() + ": " + (ext.empty() ? std::string("no extension") : "'" + ext + "' is no model format") +
                     ": name a Blender export *.obj (other formats assimp reads by their extension: .fbx, .gltf, ...)");
  const std::filesystem::path folder = file.parent_path();
  out.inputs_read.push_back(std::filesystem::absolute(file));

  auto t0 = std::chrono::steady_clock::now();
  ObjScan scan;
  struct MapKdOf {
    MapKd map;
    std::filesystem::path mtl;
  };
  std::vector<MapKdOf> map_kd;  // to report a missing texture at its .mtl line
  std::vector<std::pair<std::filesystem::path, std::string>> replaced;  // what assimp reads instead
  if (is_obj) {
    scan = prescan_obj_file(file);
    out.timings_ms.emplace_back("pre-scan", lap_ms(t0));
    std::set<std::string> defined;  // materials of the libraries read
    bool library_missing = false;
    // the `replaced` entry of the first library of an mtllib line of several (-1: none), and
    // per entry the libraries whose text it holds
    std::ptrdiff_t line_first = -1;
    std::map<std::ptrdiff_t, std::set<std::string>> joined_to;
    for (std::size_t i = 0; i < scan.mtllibs.size(); ++i) {
      if (!scan.mtllib_joined[i]) line_first = -1;
      const std::string& lib = scan.mtllibs[i];
      const auto p = folder / lib;
      const std::string where = file.string() + ":" + std::to_string(scan.mtllib_lines[i]) + ": ";
      auto check_mtl = [&](const std::filesystem::path& mtl) {
        MtlScan m;
        try {
          m = prescan_mtl_file(mtl, folder.empty() ? std::filesystem::path(".") : folder);
        } catch (const InputError& e) {
          throw InputError(std::string(e.what()) + " (material library of " + file.filename().string() + ")");
        }
        for (MapKd& k : m.maps) map_kd.push_back({std::move(k), mtl});
        defined.insert(m.materials.begin(), m.materials.end());
        out.warnings.insert(out.warnings.end(), m.warnings.begin(), m.warnings.end());
        // A line of several libraries: assimp reads the first, whose text carries the others'
        // (each once). One entry per file: CheckedIO serves the first that matches, so a
        // library named on several lines gathers what each of its lines joins to it.
        const bool joined = scan.mtllib_joined[i];
        const bool leads = !joined && i + 1 < scan.mtllibs.size() && scan.mtllib_joined[i + 1];
        const std::string id = std::filesystem::weakly_canonical(std::filesystem::absolute(mtl), ec).string();
        if (joined) {
          if (line_first >= 0 && joined_to[line_first].insert(id).second)
            replaced[static_cast<std::size_t>(line_first)].second.append("\n").append(m.cleaned ? m.clean_text
                                                                                                : read_text(mtl));
        } else {
          std::ptrdiff_t entry = -1;
          for (std::size_t k = 0; k < replaced.size() && entry < 0; ++k)
            if (std::filesystem::equivalent(replaced[k].first, mtl, ec)) entry = static_cast<std::ptrdiff_t>(k);
          if (entry < 0 && (m.cleaned || leads)) {
            replaced.emplace_back(mtl, m.cleaned ? std::move(m.clean_text) : read_text(mtl));
            entry = static_cast<std::ptrdiff_t>(replaced.size()) - 1;
            joined_to[entry].insert(id);
          }
          line_first = leads ? entry : -1;
        }
        out.inputs_read.push_back(std::filesystem::absolute(mtl));
      };
      if (!std::filesystem::exists(p, ec)) {
        if (!allow_missing)
          throw InputError(where + "material library " + quote_input(lib) + " not found (" + p.string() +
                           "); --allow-missing converts without it");
        library_missing = true;
        if (scan.mtllib_joined[i]) {  // (not the line's first: assimp does not look for it)
          out.warnings.push_back(where + "material library " + quote_input(lib) +
                                 " not found; the materials it would define get a default material");
          continue;
        }
        // assimp then reads <model>.mtl instead, when there is one: check that one.
        const auto fallback = folder / (file.stem().string() + ".mtl");
        if (std::filesystem::is_regular_file(fallback, ec)) {
          out.warnings.push_back(where + "material library " + quote_input(lib) + " not found; assimp reads '" +
                                 fallback.filename().string() + "' instead");
          check_mtl(fallback);
        } else {
          out.warnings.push_back(where + "material library " + quote_input(lib) +
                                 " not found; its objects get a default material");
        }
        continue;
      }
      // assimp would fail on it with a message that names no file
      if (!std::filesystem::is_regular_file(p, ec) || !std::ifstream(p, std::ios::binary))
        throw InputError(where + "material library " + quote_input(lib) + " is not a readable file");
      check_mtl(p);
    }
    // A `usemtl` no library defines: assimp invents a material of that name (grey); the
    // file's author meant another. (Not repeated when a library was missing: that is warned.)
    // Once per name, at its first use, with how many more there are (Blender's legacy
    // exporter writes `usemtl (null)` before every object without a material).
    if (!library_missing) {
      std::map<std::string, std::pair<std::size_t, std::size_t>> undefined;  // name -> first line, uses
      std::vector<std::string> order;
      for (const auto& [name, line] : scan.usemtl)
        if (defined.count(name) == 0) {
          auto [it, added] = undefined.try_emplace(name, line, 0);
          if (added) order.push_back(name);
          ++it->second.second;
        }
      for (const std::string& name : order) {
        const auto [line, uses] = undefined[name];
        out.warnings.push_back(file.string() + ":" + std::to_string(line) + ": material " + quote_input(name) +
                               (scan.mtllibs.empty() ? " used but no 'mtllib' is given"
                                                     : " is defined in no material library") +
                               "; its faces get a default (grey) material" +
                               (uses > 1 ? " (used " + std::to_string(uses) + " times)" : std::string()));
      }
    }
    if (scan.cleaned) replaced.emplace_back(file, std::move(scan.clean_text));
    if (scan.lines_points > 0)
      out.warnings.push_back(file.string() + ": " + std::to_string(scan.lines_points) +
                             " line/point elements ignored (only faces are drawn)");
    out.pin_points = scan.pin_points;
    out.object_lines = scan.object_lines;
    out.warnings.insert(out.warnings.end(), scan.warnings.begin(), scan.warnings.end());
  }

  Assimp::Importer importer;
  importer.SetIOHandler(new CheckedIO(std::move(replaced)));
  const aiScene* ai = nullptr;
  NotSimpleFaces not_simple;
  {
    AssimpErrors errors;
    ai = read_with_assimp(importer, file.string(), &not_simple);
    if (ai == nullptr) {
      std::string why = importer.GetErrorString();
      while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
      throw InputError(file.string() + ": cannot import: " + (why.empty() ? "unknown error" : why));
    }
    // (OBJ input went through the pre-scan; assimp's errors there are warned or refused above.)
    // Other formats: an index out of range that assimp "repaired" would be a silently wrong
    // mesh: refused; assimp's other errors (a default material, an extra layer) are warnings.
    if (!is_obj)
      for (const std::string& m : errors.messages) {
        if (m.find("out of range") != std::string::npos)
          throw InputError(file.string() + ": cannot import: " + m + " (assimp would change the index; refused)");
        out.warnings.push_back(file.string() + ": assimp: " + m);
      }
  }
  out.timings_ms.emplace_back("assimp", lap_ms(t0));
  if ((ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || ai->mNumMeshes == 0 || ai->mRootNode == nullptr)
    throw InputError(file.string() + ": no triangles (empty scene)");

  // Materials: every material of the file; assimp's own default one only when a mesh uses it.
  std::vector<int> used(ai->mNumMaterials, 0);
  for (unsigned i = 0; i < ai->mNumMeshes; ++i)
    if (ai->mMeshes[i]->mMaterialIndex < ai->mNumMaterials) used[ai->mMeshes[i]->mMaterialIndex] = 1;
  std::vector<std::int32_t> material_map(ai->mNumMaterials, -1);
  std::map<std::string, std::int32_t> texture_index;       // by the name written
  std::map<std::string, std::int32_t> texture_file_index;  // by the file it resolves to
  for (unsigned i = 0; i < ai->mNumMaterials; ++i) {
    Material m;
    try {
      m = read_material(*ai->mMaterials[i]);
    } catch (const std::runtime_error& e) {
      throw InputError(file.string() + ": " + e.what());
    }
    if (!used[i] && m.name == AI_DEFAULT_MATERIAL_NAME) continue;
    aiString tex;
    if (ai->mMaterials[i]->GetTextureCount(aiTextureType_DIFFUSE) > 0 &&
        ai->mMaterials[i]->GetTexture(aiTextureType_DIFFUSE, 0, &tex) == AI_SUCCESS && tex.length > 0) {
      const std::string written = tex.C_Str();
      if (auto it = texture_index.find(written); it != texture_index.end()) {
        m.diffuse_texture = it->second;
      } else {
        std::string rel = written;
        std::replace(rel.begin(), rel.end(), '\\', '/');
        // relative to the .obj's folder, else to the folder of a .mtl that names it
        std::filesystem::path p = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : folder / rel;
        for (const auto& lib : scan.mtllibs) {
          if (std::filesystem::path(rel).is_absolute() || std::filesystem::is_regular_file(p, ec)) break;
          p = (folder / lib).parent_path() / rel;
        }
        if (!std::filesystem::is_regular_file(p, ec)) p = folder / rel;
        std::ifstream in(p, std::ios::binary);
        // named at its map_Kd line when the .mtl is known (the statement ends with the name)
        std::string where = file.string() + ": ";
        for (const MapKdOf& k : map_kd) {
          const std::string& a = k.map.argument;
          const std::size_t n = written.size();
          if (a == written || (a.size() > n && a.compare(a.size() - n, n, written) == 0 &&
                               (a[a.size() - n - 1] == ' ' || a[a.size() - n - 1] == '\t'))) {
            where = k.mtl.string() + ":" + std::to_string(k.map.line) + ": ";
            break;
          }
        }
        // the same file under another spelling (`./tex.png` and `tex.png`): baked once
        const std::string same_file = std::filesystem::weakly_canonical(p, ec).string();
        if (const auto known = texture_file_index.find(same_file); in && !same_file.empty() && known != texture_file_index.end()) {
          m.diffuse_texture = known->second;
          texture_index[written] = known->second;
        } else if (rel.empty() || rel[0] == '*' || !in || std::filesystem::is_directory(p, ec)) {
          const std::string what = "texture " + quote_input(written) + " of material " + quote_input(m.name);
          const bool exists = std::filesystem::exists(p, ec);
          if (!allow_missing)
            throw InputError(where + what + (exists ? " is not a readable file (" : " not found (") + p.string() +
                             "; material of " + file.filename().string() + "); --allow-missing converts without it");
          out.warnings.push_back(where + what + (exists ? " is not a readable file" : " not found") +
                                 "; the material gets no texture (" + file.filename().string() + ")");
        } else {
          std::ostringstream ss;
          ss << in.rdbuf();
          const std::string bytes = ss.str();
          if (bytes.size() > std::numeric_limits<std::uint32_t>::max())
            throw InputError(p.string() + ": texture larger than 4 GiB");
          // Decoded once here as the viewer will decode it (stb_image): a file that is no
          // image, or a format stb does not read (TIFF, EXR), stops the bake instead of the
          // program that shows the scene.
          if (const std::string why = undecodable_image(bytes); !why.empty()) {
            const std::string what = where + "texture " + quote_input(written) + " of material " +
                                     quote_input(m.name) + " (" + p.string() + ") cannot be decoded (" + why +
                                     "; readable: PNG, JPEG, BMP, TGA, GIF, PSD, HDR, PNM)";
            if (!allow_missing) throw InputError(what + "; --allow-missing converts without it");
            out.warnings.push_back(what + "; the material gets no texture");
          } else {
            Texture t;
            t.name = written;
            t.bytes.assign(bytes.begin(), bytes.end());
            m.diffuse_texture = static_cast<std::int32_t>(out.textures.size());
            texture_index[written] = m.diffuse_texture;
            if (!same_file.empty()) texture_file_index[same_file] = m.diffuse_texture;
            out.textures.push_back(std::move(t));
          }
          out.inputs_read.push_back(std::filesystem::absolute(p));  // a changed file re-bakes either way
        }
      }
    }
    material_map[i] = static_cast<std::int32_t>(out.materials.size());
    out.materials.push_back(std::move(m));
  }

  // Objects: nodes with meshes, depth first in file order.
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> nodes;
  std::function<void(const aiNode*, const aiMatrix4x4&)> walk = [&](const aiNode* n, const aiMatrix4x4& parent) {
    const aiMatrix4x4 global = parent * n->mTransformation;
    if (n->mNumMeshes > 0) nodes.emplace_back(n, global);
    for (unsigned i = 0; i < n->mNumChildren; ++i) walk(n->mChildren[i], global);
  };
  walk(ai->mRootNode, aiMatrix4x4());

  const std::uint64_t limit = std::numeric_limits<std::uint32_t>::max() / 4;
  std::vector<std::size_t> objects_not_simple;  // per out.objects: faces triangulated as a fan
  for (const auto& [node, transform] : nodes) {
    const auto not_simple_here = not_simple.find(node);
    const std::size_t fans = not_simple_here == not_simple.end() ? 0 : not_simple_here->second;
    Object obj;
    obj.name = node->mName.C_Str();
    // (the pre-scan gave assimp OBJ names encoded, spaces and all: see encode_object_name)
    if (is_obj) obj.name = decode_object_name(obj.name);
    // OBJ without `o`/`g`: assimp invents a name; the object is named after the file.
    // So are faces before the first `o`/`g`, or under a bare `o` (assimp: "defaultobject").
    // (unless an object has that name: the two would join into one, a following `o <stem>`)
    if (is_obj && (scan.groups == 0 || (obj.name == "defaultobject" && scan.object_lines.count("defaultobject") == 0 &&
                                        scan.object_lines.count(file.stem().string()) == 0)))
      obj.name = file.stem().string();
    while (!obj.name.empty() && (obj.name.back() == '\r' || obj.name.back() == '\n')) obj.name.pop_back();
    obj.first_vertex = static_cast<std::uint32_t>(out.positions.size() / 3);
    obj.first_index = static_cast<std::uint32_t>(out.indices.size());
    obj.first_submesh = static_cast<std::uint32_t>(out.submeshes.size());
    const bool moved = !is_identity(transform);
    aiMatrix3x3 normal_matrix(transform);
    normal_matrix.Inverse().Transpose();
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      const aiMesh* mesh = ai->mMeshes[node->mMeshes[k]];
      if ((mesh->mPrimitiveTypes & ~static_cast<unsigned>(aiPrimitiveType_TRIANGLE | aiPrimitiveType_NGONEncodingFlag)) != 0 ||
          mesh->mNumFaces == 0)
        continue;  // points/lines were sorted out; nothing else is drawn
      if (out.positions.size() / 3 + static_cast<std::uint64_t>(mesh->mNumVertices) > limit ||
          out.indices.size() + 3ull * mesh->mNumFaces > limit)
        throw InputError(file.string() + ": too large (more than 2^30 vertices or indices)");
      // Each face corner's attributes (transformed when the node is), then an exact join:
      // corners with bit-identical position, normal and texcoord become one vertex, in order
      // of first use. (assimp's JoinIdenticalVertices merges within 1e-5 and costs 1.7 s and
      // 300 MB on a 1M-triangle OBJ; see docs/blender2ogl.md.)
      std::vector<char> bad_normal(mesh->mNumVertices, 0);
      std::size_t bad_normals = 0;
      std::vector<float> corner(8 * static_cast<std::size_t>(mesh->mNumVertices));
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        aiVector3D p = mesh->mVertices[v];
        if (!finite3(p))
          throw InputError(file.string() + ": object " + quote_input(obj.name) + " has a non-finite vertex coordinate");
        if (moved) p = transform * p;
        aiVector3D n = mesh->mNormals != nullptr ? mesh->mNormals[v] : aiVector3D(0, 0, 0);
        if (moved) n = (normal_matrix * n).NormalizeSafe();
        // none (a face without `vn` among faces with), zero (`vn 0 0 0`) or non-finite (a
        // normal assimp generated for a degenerate face): computed from the faces below
        if (!finite3(n) || (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f)) {
          n = aiVector3D(0, 0, 0);
          bad_normal[v] = 1;
          ++bad_normals;
        }
        float u = 0.0f, w = 0.0f;
        if (mesh->HasTextureCoords(0)) {
          u = mesh->mTextureCoords[0][v].x;
          w = mesh->mTextureCoords[0][v].y;
          if (!std::isfinite(u) || !std::isfinite(w))
            throw InputError(file.string() + ": object " + quote_input(obj.name) + " has a non-finite texture coordinate");
        }
        const float attrs[8] = {p.x, p.y, p.z, n.x, n.y, n.z, u, w};
        std::memcpy(&corner[8 * static_cast<std::size_t>(v)], attrs, sizeof attrs);
      }
      if (bad_normals > 0) {
        // The normalized, area-weighted sum of the normals of the faces using the vertex (the
        // face's normal when only one does); (0, 0, 1) when those faces have no area.
        std::vector<double> sum(3 * static_cast<std::size_t>(mesh->mNumVertices), 0.0);
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
          const aiFace& face = mesh->mFaces[f];
          if (face.mNumIndices != 3) continue;
          bool any = false;
          for (unsigned c = 0; c < 3; ++c) any = any || (face.mIndices[c] < mesh->mNumVertices && bad_normal[face.mIndices[c]]);
          if (!any || face.mIndices[0] >= mesh->mNumVertices || face.mIndices[1] >= mesh->mNumVertices ||
              face.mIndices[2] >= mesh->mNumVertices)
            continue;
          const float* a = &corner[8 * static_cast<std::size_t>(face.mIndices[0])];
          const float* b = &corner[8 * static_cast<std::size_t>(face.mIndices[1])];
          const float* d = &corner[8 * static_cast<std::size_t>(face.mIndices[2])];
          const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
          const double e2[3] = {double(d[0]) - a[0], double(d[1]) - a[1], double(d[2]) - a[2]};
          const double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
          for (unsigned c = 0; c < 3; ++c)
            if (bad_normal[face.mIndices[c]])
              for (int j = 0; j < 3; ++j) sum[3 * static_cast<std::size_t>(face.mIndices[c]) + static_cast<std::size_t>(j)] += cr[j];
        }
        std::size_t undefined = 0;
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
          if (!bad_normal[v]) continue;
          const double* q = &sum[3 * static_cast<std::size_t>(v)];
          const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
          float nn[3] = {0.0f, 0.0f, 1.0f};
          if (len > 0.0 && std::isfinite(len))
            for (int j = 0; j < 3; ++j) nn[j] = static_cast<float>(q[j] / len);
          if (!(std::isfinite(nn[0]) && std::isfinite(nn[1]) && std::isfinite(nn[2])) ||
              (nn[0] == 0.0f && nn[1] == 0.0f && nn[2] == 0.0f) || !(len > 0.0 && std::isfinite(len))) {
            nn[0] = nn[1] = 0.0f, nn[2] = 1.0f;
            ++undefined;
          }
          std::memcpy(&corner[8 * static_cast<std::size_t>(v) + 3], nn, sizeof nn);
        }
        out.warnings.push_back(file.string() + ": object " + quote_input(obj.name) + ": " + std::to_string(bad_normals) +
                               " missing, zero or non-finite normals computed from the faces" +
                               (undefined > 0 ? " (" + std::to_string(undefined) + " on faces without area set to (0, 0, 1))" : ""));
      }
      std::size_t table_size = 16;
      while (table_size < 2ull * mesh->mNumVertices) table_size *= 2;
      constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
      std::vector<std::uint32_t> table(table_size, kEmpty);  // -> assimp vertex of the joined one
      std::vector<std::uint32_t> joined(mesh->mNumVertices, kEmpty);
      out.positions.reserve(out.positions.size() + 3ull * mesh->mNumVertices);
      out.normals.reserve(out.normals.size() + 3ull * mesh->mNumVertices);
      out.texcoords.reserve(out.texcoords.size() + 2ull * mesh->mNumVertices);
      out.indices.reserve(out.indices.size() + 3ull * mesh->mNumFaces);
      auto join = [&](unsigned v) -> std::uint32_t {
        if (joined[v] != kEmpty) return joined[v];
        const float* a = &corner[8 * static_cast<std::size_t>(v)];
        std::uint32_t w[8];
        std::memcpy(w, a, sizeof w);
        std::uint64_t h = 0x9E3779B97F4A7C15ull;
        for (std::uint32_t x : w) h = (h ^ x) * 0xff51afd7ed558ccdull, h ^= h >> 29;
        for (std::size_t slot = h & (table_size - 1);; slot = (slot + 1) & (table_size - 1)) {
          const std::uint32_t other = table[slot];
          if (other == kEmpty) {
            table[slot] = v;
            joined[v] = static_cast<std::uint32_t>(out.positions.size() / 3);
            out.positions.insert(out.positions.end(), a, a + 3);
            out.normals.insert(out.normals.end(), a + 3, a + 6);
            out.texcoords.insert(out.texcoords.end(), a + 6, a + 8);
            return joined[v];
          }
          if (std::memcmp(&corner[8 * static_cast<std::size_t>(other)], a, 32) == 0) return joined[v] = joined[other];
        }
      };
      Submesh sm;
      sm.first_index = static_cast<std::uint32_t>(out.indices.size());
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3)
          throw InputError(file.string() + ": object " + quote_input(obj.name) + " has a face with " +
                           std::to_string(face.mNumIndices) + " vertices");
        for (unsigned c = 0; c < 3; ++c) {
          if (face.mIndices[c] >= mesh->mNumVertices)
            throw InputError(file.string() + ": object " + quote_input(obj.name) + " has a vertex index out of range");
          out.indices.push_back(join(face.mIndices[c]));
        }
      }
      sm.index_count = static_cast<std::uint32_t>(out.indices.size()) - sm.first_index;
      sm.material = mesh->mMaterialIndex < material_map.size() ? material_map[mesh->mMaterialIndex] : -1;
      // Consecutive meshes with one material make one range.
      if (out.submeshes.size() > obj.first_submesh && out.submeshes.back().material == sm.material &&
          out.submeshes.back().first_index + out.submeshes.back().index_count == sm.first_index)
        out.submeshes.back().index_count += sm.index_count;
      else
        out.submeshes.push_back(sm);
    }
    obj.vertex_count = static_cast<std::uint32_t>(out.positions.size() / 3) - obj.first_vertex;
    obj.index_count = static_cast<std::uint32_t>(out.indices.size()) - obj.first_index;
    obj.submesh_count = static_cast<std::uint32_t>(out.submeshes.size()) - obj.first_submesh;
    if (obj.index_count == 0) continue;
    // assimp makes one node per `o` and per `g`; a name seen twice continues the object.
    if (!out.objects.empty() && out.objects.back().name == obj.name &&
        out.objects.back().first_vertex + out.objects.back().vertex_count == obj.first_vertex) {
      Object& prev = out.objects.back();
      prev.vertex_count += obj.vertex_count;
      prev.index_count += obj.index_count;
      prev.submesh_count += obj.submesh_count;
      objects_not_simple.back() += fans;
      continue;
    }
    out.objects.push_back(std::move(obj));
    objects_not_simple.push_back(fans);
  }
  for (std::size_t i = 0; i < out.objects.size(); ++i)
    if (objects_not_simple[i] > 0)
      out.warnings.push_back(file.string() + ": object " + quote_input(out.objects[i].name) + ": " +
                             std::to_string(objects_not_simple[i]) +
                             (objects_not_simple[i] == 1 ? " face is not a simple polygon"
                                                         : " faces are not simple polygons") +
                             " (self-intersecting, or too many corners to cut into ears); triangulated as a fan");
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
