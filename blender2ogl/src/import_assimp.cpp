// The read with assimp: the importer, faces with more than 3 corners triangulated here
// (triangulate_polygon), the pre-scans' cleaned text given in place of the files, and
// assimp's own errors caught.
#include <assimp/DefaultIOSystem.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/postprocess.h>

#include <cstring>
#include <limits>
#include <memory>

#include "import_stages.hpp"

namespace b2o::conv {
namespace {

// What assimp reads: the model as the pre-scan cleaned it (when it did), and .obj/.mtl files
// without a UTF-8 byte-order mark (assimp 5.2.5 would take it as part of the first statement).
// Other files, and relative paths (mtllib, textures), go through the default file system.
class CheckedIO : public Assimp::DefaultIOSystem {
 public:
  /// `replaced`: files assimp reads from these bytes instead (the pre-scan's cleaned text).
  explicit CheckedIO(ReplacedFiles replaced) : replaced_(std::move(replaced)) {}
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
  ReplacedFiles replaced_;
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
// aiProcess_Triangulate would leave the mesh. Returns how many faces are not simple.
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

// Adds per node the faces of its meshes that are not simple (`per_mesh`: by mesh), below `node` too.
void count_not_simple(const aiNode* node, const std::vector<std::size_t>& per_mesh, NotSimpleFaces& not_simple) {
  std::size_t count = 0;
  for (unsigned k = 0; k < node->mNumMeshes; ++k)
    if (node->mMeshes[k] < per_mesh.size()) count += per_mesh[node->mMeshes[k]];
  if (count > 0) not_simple[node] += count;
  for (unsigned i = 0; i < node->mNumChildren; ++i) count_not_simple(node->mChildren[i], per_mesh, not_simple);
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
  if (not_simple != nullptr && scene->mRootNode != nullptr) count_not_simple(scene->mRootNode, per_mesh, *not_simple);
  // JoinIdenticalVertices is done exactly by import_scene. Not SplitLargeMeshes /
  // PreTransformVertices / OptimizeMeshes / OptimizeGraph: they split big cloths, move
  // vertices or merge objects.
  return importer.ApplyPostProcessing(aiProcess_GenSmoothNormals | aiProcess_SortByPType |
                                      aiProcess_ValidateDataStructure);
}

const aiScene& read_model(Assimp::Importer& importer, const std::filesystem::path& file, bool is_obj,
                          ReplacedFiles replaced, NotSimpleFaces& not_simple, Scene& out) {
  importer.SetIOHandler(new CheckedIO(std::move(replaced)));
  const aiScene* ai = nullptr;
  {
    AssimpErrors errors;
    ai = read_with_assimp(importer, file.string(), &not_simple);
    if (ai == nullptr) {
      std::string why = importer.GetErrorString();
      while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
      throw InputError(file.string() + ": cannot import: " + (why.empty() ? std::string("unknown error") : why));
    }
    // (OBJ input has been through the pre-scan, which warns of or refuses what assimp logs there.)
    // Other formats: an index out of range that assimp "repaired" would be a silently wrong
    // mesh: refused; assimp's other errors (a default material, an extra layer) are warnings.
    if (!is_obj)
      for (const std::string& m : errors.messages) {
        if (m.find("out of range") != std::string::npos)
          throw InputError(file.string() + ": cannot import: " + m + " (assimp would change the index; refused)");
        out.warnings.push_back(file.string() + ": assimp: " + m);
      }
  }
  if ((ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || ai->mNumMeshes == 0 || ai->mRootNode == nullptr)
    throw InputError(file.string() + ": no triangles (empty scene)");
  return *ai;
}

}  // namespace b2o::conv
