// Materials and their textures: every material assimp reports (its own default one only when
// a mesh uses it), each diffuse texture read once and decoded as the viewer will decode it.
#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "import_stages.hpp"

namespace b2o::conv {
namespace {

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

// The textures of a scene's materials: each file read and decoded once, into out.textures.
class Textures {
 public:
  Textures(const std::filesystem::path& file, const ObjInput& obj, bool allow_missing, Scene& out)
      : file_(file), folder_(file.parent_path()), obj_(obj), allow_missing_(allow_missing), out_(out) {}

  // The texture `written` (as the material names it) of `material`: its index in
  // out.textures; -1 when it is missing or unreadable and --allow-missing lets that pass.
  std::int32_t index_of(const std::string& written, const std::string& material) {
    if (auto it = by_name_.find(written); it != by_name_.end()) return it->second;
    std::string rel = written;
    std::replace(rel.begin(), rel.end(), '\\', '/');
    const std::filesystem::path p = find_file(rel);
    std::ifstream in(p, std::ios::binary);
    const std::string where = map_kd_line(written);
    // the same file under another spelling (`./tex.png` and `tex.png`): baked once
    std::error_code ec;
    const std::string same_file = std::filesystem::weakly_canonical(p, ec).string();
    if (const auto known = by_file_.find(same_file); in && !same_file.empty() && known != by_file_.end())
      return by_name_[written] = known->second;
    if (rel.empty() || rel[0] == '*' || !in || std::filesystem::is_directory(p, ec)) {
      missing(written, material, p, where);
      return -1;
    }
    return load(in, p, written, material, where, same_file);
  }

 private:
  // The texture's file: relative to the .obj's folder, else to the folder of a .mtl that names it.
  std::filesystem::path find_file(const std::string& rel) const {
    std::error_code ec;
    std::filesystem::path p = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : folder_ / rel;
    for (const auto& lib : obj_.scan.mtllibs) {
      if (std::filesystem::path(rel).is_absolute() || std::filesystem::is_regular_file(p, ec)) break;
      p = (folder_ / lib).parent_path() / rel;
    }
    if (!std::filesystem::is_regular_file(p, ec)) p = folder_ / rel;
    return p;
  }

  // "file:line: " of the map_Kd line that names the texture when the .mtl is known (the
  // statement ends with the name), else "file: " of the model.
  std::string map_kd_line(const std::string& written) const {
    for (const MapKdOf& k : obj_.map_kd) {
      const std::string& a = k.map.argument;
      const std::size_t n = written.size();
      if (a == written || (a.size() > n && a.compare(a.size() - n, n, written) == 0 &&
                           (a[a.size() - n - 1] == ' ' || a[a.size() - n - 1] == '\t')))
        return k.mtl.string() + ":" + std::to_string(k.map.line) + ": ";
    }
    return file_.string() + ": ";
  }

  // A texture that is not there or not a readable file: an error, or a warning with --allow-missing.
  void missing(const std::string& written, const std::string& material, const std::filesystem::path& p,
               const std::string& where) {
    const std::string what = "texture " + quote_input(written) + " of material " + quote_input(material);
    std::error_code ec;
    const bool exists = std::filesystem::exists(p, ec);
    if (!allow_missing_)
      throw InputError(where + what + (exists ? " is not a readable file (" : " not found (") + p.string() +
                       "; material of " + file_.filename().string() + "); --allow-missing converts without it");
    out_.warnings.push_back(where + what + (exists ? " is not a readable file" : " not found") +
                            "; the material gets no texture (" + file_.filename().string() + ")");
  }

  // Reads the texture's bytes and decodes them once, as the viewer will (stb_image): a file
  // that is no image, or a format stb does not read (TIFF, EXR), stops the bake instead of the
  // program that shows the scene. Returns its index, or -1 (undecodable, --allow-missing).
  std::int32_t load(std::ifstream& in, const std::filesystem::path& p, const std::string& written,
                    const std::string& material, const std::string& where, const std::string& same_file) {
    std::ostringstream ss;
    ss << in.rdbuf();
    const std::string bytes = ss.str();
    if (bytes.size() > std::numeric_limits<std::uint32_t>::max()) throw InputError(p.string() + ": texture larger than 4 GiB");
    std::int32_t index = -1;
    if (const std::string why = undecodable_image(bytes); !why.empty()) {
      const std::string what = where + "texture " + quote_input(written) + " of material " + quote_input(material) +
                               " (" + p.string() + ") cannot be decoded (" + why +
                               "; readable: PNG, JPEG, BMP, TGA, GIF, PSD, HDR, PNM)";
      if (!allow_missing_) throw InputError(what + "; --allow-missing converts without it");
      out_.warnings.push_back(what + "; the material gets no texture");
    } else {
      Texture t;
      t.name = written;
      t.bytes.assign(bytes.begin(), bytes.end());
      index = static_cast<std::int32_t>(out_.textures.size());
      by_name_[written] = index;
      if (!same_file.empty()) by_file_[same_file] = index;
      out_.textures.push_back(std::move(t));
    }
    out_.inputs_read.push_back(std::filesystem::absolute(p));  // a changed file re-bakes either way
    return index;
  }

  const std::filesystem::path& file_;
  const std::filesystem::path folder_;
  const ObjInput& obj_;
  const bool allow_missing_;
  Scene& out_;
  std::map<std::string, std::int32_t> by_name_;  // by the name written
  std::map<std::string, std::int32_t> by_file_;  // by the file it resolves to
};

}  // namespace

std::vector<std::int32_t> import_materials(const aiScene& ai, const std::filesystem::path& file, const ObjInput& obj,
                                           bool allow_missing, Scene& out) {
  std::vector<int> used(ai.mNumMaterials, 0);
  for (unsigned i = 0; i < ai.mNumMeshes; ++i)
    if (ai.mMeshes[i]->mMaterialIndex < ai.mNumMaterials) used[ai.mMeshes[i]->mMaterialIndex] = 1;
  std::vector<std::int32_t> material_map(ai.mNumMaterials, -1);
  Textures textures(file, obj, allow_missing, out);
  for (unsigned i = 0; i < ai.mNumMaterials; ++i) {
    Material m;
    try {
      m = read_material(*ai.mMaterials[i]);
    } catch (const std::runtime_error& e) {
      throw InputError(file.string() + ": " + e.what());
    }
    if (!used[i] && m.name == AI_DEFAULT_MATERIAL_NAME) continue;
    aiString tex;
    if (ai.mMaterials[i]->GetTextureCount(aiTextureType_DIFFUSE) > 0 &&
        ai.mMaterials[i]->GetTexture(aiTextureType_DIFFUSE, 0, &tex) == AI_SUCCESS && tex.length > 0)
      m.diffuse_texture = textures.index_of(tex.C_Str(), m.name);
    material_map[i] = static_cast<std::int32_t>(out.materials.size());
    out.materials.push_back(std::move(m));
  }
  return material_map;
}

}  // namespace b2o::conv
