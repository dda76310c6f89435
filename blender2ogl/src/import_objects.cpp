// assimp's nodes into the scene's objects: one object per node with meshes (named as the file
// names it), each mesh a range of one material; pin helpers taken out afterwards.
#include <limits>
#include <utility>

#include "import_stages.hpp"

namespace b2o::conv {
namespace {

using PlacedNode = std::pair<const aiNode*, aiMatrix4x4>;  // a node and its global transform

// Nodes with meshes below `n` (and `n`), depth first in file order.
void collect_nodes(const aiNode* n, const aiMatrix4x4& parent, std::vector<PlacedNode>& nodes) {
  const aiMatrix4x4 global = parent * n->mTransformation;
  if (n->mNumMeshes > 0) nodes.emplace_back(n, global);
  for (unsigned i = 0; i < n->mNumChildren; ++i) collect_nodes(n->mChildren[i], global, nodes);
}

// The object's name: the node's, as the OBJ file writes it.
std::string object_name(const aiNode& node, const std::filesystem::path& file, bool is_obj, const ObjScan& scan) {
  std::string name = node.mName.C_Str();
  // (the pre-scan gives assimp OBJ names encoded, spaces and all: see encode_object_name)
  if (is_obj) name = decode_object_name(name);
  // OBJ without `o`/`g`: assimp invents a name; the object is named after the file.
  // So are faces before the first `o`/`g`, or under a bare `o` (assimp: "defaultobject").
  // (unless an object has that name: the two would join into one, a following `o <stem>`)
  if (is_obj && (scan.groups == 0 || (name == "defaultobject" && scan.object_lines.count("defaultobject") == 0 &&
                                      scan.object_lines.count(file.stem().string()) == 0)))
    name = file.stem().string();
  while (!name.empty() && (name.back() == '\r' || name.back() == '\n')) name.pop_back();
  return name;
}

// Adds a submesh of `obj`; consecutive meshes with one material make one range.
void add_submesh(const Object& obj, const Submesh& sm, Scene& out) {
  if (out.submeshes.size() > obj.first_submesh && out.submeshes.back().material == sm.material &&
      out.submeshes.back().first_index + out.submeshes.back().index_count == sm.first_index)
    out.submeshes.back().index_count += sm.index_count;
  else
    out.submeshes.push_back(sm);
}

// One node's triangle meshes appended to `out` as the object `name` (not added to out.objects).
Object import_node(const aiScene& ai, const PlacedNode& placed, std::string name, const std::filesystem::path& file,
                   const std::vector<std::int32_t>& material_map, Scene& out) {
  const auto& [node, transform] = placed;
  const std::uint64_t limit = std::numeric_limits<std::uint32_t>::max() / 4;
  Object obj;
  obj.name = std::move(name);
  obj.first_vertex = static_cast<std::uint32_t>(out.positions.size() / 3);
  obj.first_index = static_cast<std::uint32_t>(out.indices.size());
  obj.first_submesh = static_cast<std::uint32_t>(out.submeshes.size());
  const std::string object = file.string() + ": object " + quote_input(obj.name);
  for (unsigned k = 0; k < node->mNumMeshes; ++k) {
    const aiMesh* mesh = ai.mMeshes[node->mMeshes[k]];
    if ((mesh->mPrimitiveTypes & ~static_cast<unsigned>(aiPrimitiveType_TRIANGLE | aiPrimitiveType_NGONEncodingFlag)) != 0 ||
        mesh->mNumFaces == 0)
      continue;  // points/lines are sorted out; nothing else is drawn
    if (out.positions.size() / 3 + static_cast<std::uint64_t>(mesh->mNumVertices) > limit ||
        out.indices.size() + 3ull * mesh->mNumFaces > limit)
      throw InputError(file.string() + ": too large (more than 2^30 vertices or indices)");
    Submesh sm;
    sm.first_index = static_cast<std::uint32_t>(out.indices.size());
    append_mesh(*mesh, transform, object, out);
    sm.index_count = static_cast<std::uint32_t>(out.indices.size()) - sm.first_index;
    sm.material = mesh->mMaterialIndex < material_map.size() ? material_map[mesh->mMaterialIndex] : -1;
    add_submesh(obj, sm, out);
  }
  obj.vertex_count = static_cast<std::uint32_t>(out.positions.size() / 3) - obj.first_vertex;
  obj.index_count = static_cast<std::uint32_t>(out.indices.size()) - obj.first_index;
  obj.submesh_count = static_cast<std::uint32_t>(out.submeshes.size()) - obj.first_submesh;
  return obj;
}

// Warns of the objects with faces that are not simple polygons (`fans`: per object, how many).
void warn_not_simple(const std::filesystem::path& file, const std::vector<std::size_t>& fans, Scene& out) {
  for (std::size_t i = 0; i < out.objects.size(); ++i)
    if (fans[i] > 0)
      out.warnings.push_back(file.string() + ": object " + quote_input(out.objects[i].name) + ": " +
                             std::to_string(fans[i]) +
                             (fans[i] == 1 ? " face is not a simple polygon" : " faces are not simple polygons") +
                             " (self-intersecting, or too many corners to cut into ears); triangulated as a fan");
}

}  // namespace

void import_objects(const aiScene& ai, const std::filesystem::path& file, bool is_obj, const ObjScan& scan,
                    const NotSimpleFaces& not_simple, const std::vector<std::int32_t>& material_map, Scene& out) {
  std::vector<PlacedNode> nodes;
  collect_nodes(ai.mRootNode, aiMatrix4x4(), nodes);
  std::vector<std::size_t> objects_not_simple;  // per out.objects: faces triangulated as a fan
  for (const PlacedNode& placed : nodes) {
    const auto not_simple_here = not_simple.find(placed.first);
    const std::size_t fans = not_simple_here == not_simple.end() ? 0 : not_simple_here->second;
    Object obj = import_node(ai, placed, object_name(*placed.first, file, is_obj, scan), file, material_map, out);
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
  warn_not_simple(file, objects_not_simple, out);
}

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

}  // namespace b2o::conv
