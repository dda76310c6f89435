// One assimp mesh into the scene's arrays: each face corner's attributes (transformed when its
// node is), missing normals computed from the faces, then an exact join of identical corners.
#include <cmath>
#include <cstring>
#include <limits>

#include "import_stages.hpp"

namespace b2o::conv {
namespace {

bool finite3(const aiVector3D& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// A mesh's vertices as assimp gives them: position, normal and texcoord, 8 floats each.
struct Corners {
  std::vector<float> attrs;
  std::vector<char> bad_normal;  // per vertex: its normal is to be computed from the faces
  std::size_t bad_normals = 0;
};

// Reads the mesh's vertex attributes, `transform`ed; refuses non-finite positions and texcoords.
Corners read_corners(const aiMesh& mesh, const aiMatrix4x4& transform, const std::string& object) {
  const bool moved = !transform.IsIdentity();
  aiMatrix3x3 normal_matrix(transform);
  normal_matrix.Inverse().Transpose();
  Corners c;
  c.bad_normal.assign(mesh.mNumVertices, 0);
  c.attrs.resize(8 * static_cast<std::size_t>(mesh.mNumVertices));
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    aiVector3D p = mesh.mVertices[v];
    if (!finite3(p)) throw InputError(object + " has a non-finite vertex coordinate");
    if (moved) p = transform * p;
    aiVector3D n = mesh.mNormals != nullptr ? mesh.mNormals[v] : aiVector3D(0, 0, 0);
    if (moved) n = (normal_matrix * n).NormalizeSafe();
    // none (a face without `vn` among faces with), zero (`vn 0 0 0`) or non-finite (a normal
    // assimp generated for a degenerate face): computed from the faces
    if (!finite3(n) || (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f)) {
      n = aiVector3D(0, 0, 0);
      c.bad_normal[v] = 1;
      ++c.bad_normals;
    }
    float u = 0.0f, w = 0.0f;
    if (mesh.HasTextureCoords(0)) {
      u = mesh.mTextureCoords[0][v].x;
      w = mesh.mTextureCoords[0][v].y;
      if (!std::isfinite(u) || !std::isfinite(w)) throw InputError(object + " has a non-finite texture coordinate");
    }
    const float attrs[8] = {p.x, p.y, p.z, n.x, n.y, n.z, u, w};
    std::memcpy(&c.attrs[8 * static_cast<std::size_t>(v)], attrs, sizeof attrs);
  }
  return c;
}

// Per vertex with a bad normal: the area-weighted sum of the normals of the faces using it.
std::vector<double> face_normal_sums(const aiMesh& mesh, const Corners& c) {
  std::vector<double> sum(3 * static_cast<std::size_t>(mesh.mNumVertices), 0.0);
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;
    bool any = false;
    for (unsigned k = 0; k < 3; ++k) any = any || (face.mIndices[k] < mesh.mNumVertices && c.bad_normal[face.mIndices[k]]);
    if (!any || face.mIndices[0] >= mesh.mNumVertices || face.mIndices[1] >= mesh.mNumVertices ||
        face.mIndices[2] >= mesh.mNumVertices)
      continue;
    const float* a = &c.attrs[8 * static_cast<std::size_t>(face.mIndices[0])];
    const float* b = &c.attrs[8 * static_cast<std::size_t>(face.mIndices[1])];
    const float* d = &c.attrs[8 * static_cast<std::size_t>(face.mIndices[2])];
    const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double e2[3] = {double(d[0]) - a[0], double(d[1]) - a[1], double(d[2]) - a[2]};
    const double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (unsigned k = 0; k < 3; ++k)
      if (c.bad_normal[face.mIndices[k]])
        for (int j = 0; j < 3; ++j) sum[3 * static_cast<std::size_t>(face.mIndices[k]) + static_cast<std::size_t>(j)] += cr[j];
  }
  return sum;
}

// Bad normals become the normalized, area-weighted sum of the normals of the faces using the
// vertex (the face's normal when only one does); (0, 0, 1) when those faces have no area.
void repair_normals(const aiMesh& mesh, Corners& c, const std::string& object, std::vector<std::string>& warnings) {
  const std::vector<double> sum = face_normal_sums(mesh, c);
  std::size_t undefined = 0;
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    if (!c.bad_normal[v]) continue;
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
    std::memcpy(&c.attrs[8 * static_cast<std::size_t>(v) + 3], nn, sizeof nn);
  }
  warnings.push_back(object + ": " + std::to_string(c.bad_normals) +
                     " missing, zero or non-finite normals computed from the faces" +
                     (undefined > 0 ? " (" + std::to_string(undefined) + " on faces without area set to (0, 0, 1))" : ""));
}

// The faces' corners into out.indices: corners with bit-identical position, normal and
// texcoord become one vertex, in order of first use. (assimp's JoinIdenticalVertices merges
// within 1e-5 and costs 1.7 s and 300 MB on a 1M-triangle OBJ; see docs/blender2ogl.md.)
void join_corners(const aiMesh& mesh, const std::vector<float>& corner, const std::string& object, Scene& out) {
  std::size_t table_size = 16;
  while (table_size < 2ull * mesh.mNumVertices) table_size *= 2;
  constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> table(table_size, kEmpty);  // -> assimp vertex of the joined one
  std::vector<std::uint32_t> joined(mesh.mNumVertices, kEmpty);
  out.positions.reserve(out.positions.size() + 3ull * mesh.mNumVertices);
  out.normals.reserve(out.normals.size() + 3ull * mesh.mNumVertices);
  out.texcoords.reserve(out.texcoords.size() + 2ull * mesh.mNumVertices);
  out.indices.reserve(out.indices.size() + 3ull * mesh.mNumFaces);
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
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3)
      throw InputError(object + " has a face with " + std::to_string(face.mNumIndices) + " vertices");
    for (unsigned k = 0; k < 3; ++k) {
      if (face.mIndices[k] >= mesh.mNumVertices) throw InputError(object + " has a vertex index out of range");
      out.indices.push_back(join(face.mIndices[k]));
    }
  }
}

}  // namespace

void append_mesh(const aiMesh& mesh, const aiMatrix4x4& transform, const std::string& object, Scene& out) {
  Corners c = read_corners(mesh, transform, object);
  if (c.bad_normals > 0) repair_normals(mesh, c, object, out.warnings);
  join_corners(mesh, c.attrs, object, out);
}

}  // namespace b2o::conv
