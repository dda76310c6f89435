// A canonical text dump of a b2o::Scene (floats as exact hex): the same function runs in
// the test on the converter's in-memory scene and in a program compiled from generated code,
// so equal dumps mean every value was carried bit for bit.
#ifndef B2O_TESTS_SCENE_DUMP_HPP
#define B2O_TESTS_SCENE_DUMP_HPP

#include <blender2ogl/scene_types.h>

#include <cstdio>
#include <string>

namespace b2o::test {

inline void put_f(std::string& out, float f) {
  char buf[48];
  std::snprintf(buf, sizeof buf, " %a", static_cast<double>(f));
  out += buf;
}
inline void put_u(std::string& out, unsigned long long v) { out += " " + std::to_string(v); }
inline void put_i(std::string& out, long long v) { out += " " + std::to_string(v); }
inline void put_s(std::string& out, const char* s) {
  out += " [";
  out += s == nullptr ? "(null)" : s;
  out += "]";
}
template <class T, class F>
void put_array(std::string& out, const char* label, const T* p, std::size_t n, F put) {
  out += label;
  put_u(out, n);
  if (n > 0 && p == nullptr) out += " NULL-POINTER";
  for (std::size_t i = 0; p != nullptr && i < n; ++i) put(out, p[i]);
  out += "\n";
}

inline std::string dump_scene(const ::b2o::Scene& s) {
  std::string o;
  auto f = [](std::string& out, float v) { put_f(out, v); };
  auto u = [](std::string& out, std::uint32_t v) { put_u(out, v); };
  o += "format";
  put_u(o, s.format_version);
  put_s(o, s.name);
  put_s(o, s.source);
  o += "\n";
  put_array(o, "positions", s.positions, 3ull * s.vertex_count, f);
  put_array(o, "normals", s.normals, 3ull * s.vertex_count, f);
  put_array(o, "texcoords", s.texcoords, 2ull * s.vertex_count, f);
  put_array(o, "indices", s.indices, s.index_count, u);
  for (std::uint32_t i = 0; i < s.object_count; ++i) {
    const auto& b = s.objects[i];
    o += "object";
    put_s(o, b.name);
    put_s(o, b.identifier);
    for (auto v : {b.first_vertex, b.vertex_count, b.first_index, b.index_count, b.first_submesh, b.submesh_count})
      put_u(o, v);
    put_i(o, b.cloth);
    o += "\n";
  }
  for (std::uint32_t i = 0; i < s.submesh_count; ++i) {
    o += "submesh";
    put_u(o, s.submeshes[i].first_index);
    put_u(o, s.submeshes[i].index_count);
    put_i(o, s.submeshes[i].material);
    o += "\n";
  }
  for (std::uint32_t i = 0; i < s.material_count; ++i) {
    const auto& m = s.materials[i];
    o += "material";
    put_s(o, m.name);
    for (int k = 0; k < 3; ++k) put_f(o, m.ambient[k]);
    for (int k = 0; k < 3; ++k) put_f(o, m.diffuse[k]);
    for (int k = 0; k < 3; ++k) put_f(o, m.specular[k]);
    put_f(o, m.shininess);
    put_f(o, m.opacity);
    put_i(o, m.diffuse_texture);
    o += "\n";
  }
  for (std::uint32_t i = 0; i < s.texture_count; ++i) {
    o += "texture";
    put_s(o, s.textures[i].name);
    put_array(o, " bytes", s.textures[i].bytes, s.textures[i].size,
              [](std::string& out, unsigned char c) { put_u(out, c); });
  }
  for (std::uint32_t i = 0; i < s.cloth_count; ++i) {
    const auto& c = s.cloths[i];
    o += "cloth";
    put_u(o, c.object);
    put_u(o, c.mass_count);
    put_u(o, c.structural_count);
    o += "\n";
    put_array(o, "rest", c.rest_positions, 3ull * c.mass_count, f);
    put_array(o, "offsets", c.mass_vertex_offsets, c.mass_count + 1ull, u);
    put_array(o, "mass_vertices", c.mass_vertices, c.mass_vertex_offsets[c.mass_count], u);
    if (c.vertex_mass != nullptr)
      put_array(o, "vertex_mass", c.vertex_mass, s.objects[c.object].vertex_count, u);
    else
      o += "vertex_mass none\n";
    put_array(o, "springs", c.springs, c.spring_count, [](std::string& out, const ::b2o::Spring& sp) {
      put_u(out, sp.a);
      put_u(out, sp.b);
      put_f(out, sp.rest_length);
      put_u(out, static_cast<std::uint32_t>(sp.kind));
    });
    put_array(o, "triangles", c.triangles, 3ull * c.triangle_count, u);
    put_array(o, "pins", c.pins, c.pin_count, u);
  }
  for (std::uint32_t i = 0; i < s.param_count; ++i) {
    o += "param";
    put_s(o, s.params[i].key);
    put_s(o, s.params[i].value);
    o += "\n";
  }
  return o;
}

}  // namespace b2o::test

#endif
