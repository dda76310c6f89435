// Helpers shared by the blender2ogl tests.
#ifndef B2O_TESTS_SUPPORT_HPP
#define B2O_TESTS_SUPPORT_HPP

#include <blender2ogl/scene_types.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "converter.hpp"

namespace b2o::test {

namespace fs = std::filesystem;

// Runs f, which must throw an InputError whose message holds `part`.
template <class F>
inline void expect_input_error(F f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one with: " << part;
  } catch (const b2o::conv::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

inline fs::path fixture(const std::string& name) { return fs::path(B2O_FIXTURES) / name; }

inline std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void write_file(const fs::path& p, const std::string& bytes) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << bytes;
}

/// A fresh, empty folder under the test's build dir, named after the test.
inline fs::path scratch(const std::string& name) {
  const fs::path p = fs::path(B2O_SCRATCH) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

/// Every file under `dir` (relative path -> bytes).
inline std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = read_file(e.path());
  return out;
}

struct ProcessResult {
  int exit_code = -1;
  std::string output;  // stdout + stderr
};

/// Runs a shell command, capturing stdout and stderr together.
inline ProcessResult run_command(const std::string& command) {
  ProcessResult r;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = ::pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// Runs the converter executable with the given arguments.
inline ProcessResult run_converter(const std::vector<std::string>& args) {
  std::string cmd = shell_quote(B2O_CONVERTER);
  for (const auto& a : args) cmd += " " + shell_quote(a);
  return run_command(cmd);
}

/// Imports and bakes in process, as the executable would.
inline conv::Scene convert(const conv::Options& opt) {
  conv::Scene s = conv::import_scene(opt.input, opt.merge);
  s.name = conv::clean_identifier(opt.name.empty() ? opt.input.stem().string() : opt.name);
  conv::Stats stats;
  conv::bake_scene(s, opt, stats);
  return s;
}

/// A b2o::Scene whose pointers refer into a converter scene (what generated code should equal).
struct View {
  std::vector<b2o::Object> objects;
  std::vector<b2o::Submesh> submeshes;
  std::vector<b2o::Material> materials;
  std::vector<b2o::Texture> textures;
  std::vector<b2o::Cloth> cloths;
  std::vector<std::vector<b2o::Spring>> springs;
  std::vector<b2o::Param> params;
  b2o::Scene scene{};
};

inline void make_view(const conv::Scene& s, View& v) {
  auto ptr = [](const auto& vec) { return vec.empty() ? nullptr : vec.data(); };
  for (const auto& o : s.objects)
    v.objects.push_back({o.name.c_str(), o.identifier.c_str(), o.first_vertex, o.vertex_count, o.first_index,
                         o.index_count, o.first_submesh, o.submesh_count, o.cloth});
  for (const auto& m : s.submeshes) v.submeshes.push_back({m.first_index, m.index_count, m.material});
  for (const auto& m : s.materials)
    v.materials.push_back({m.name.c_str(),
                           {m.ambient[0], m.ambient[1], m.ambient[2]},
                           {m.diffuse[0], m.diffuse[1], m.diffuse[2]},
                           {m.specular[0], m.specular[1], m.specular[2]},
                           m.shininess,
                           m.opacity,
                           m.diffuse_texture});
  for (const auto& t : s.textures)
    v.textures.push_back({t.name.c_str(), ptr(t.bytes), static_cast<std::uint32_t>(t.bytes.size())});
  for (const auto& c : s.cloths) {
    auto& sp = v.springs.emplace_back();
    for (const auto& x : c.springs) sp.push_back({x.a, x.b, x.rest_length, static_cast<b2o::SpringKind>(x.kind)});
  }
  for (std::size_t i = 0; i < s.cloths.size(); ++i) {
    const auto& c = s.cloths[i];
    v.cloths.push_back({c.object, c.mass_count(), ptr(c.rest_positions), ptr(c.mass_vertex_offsets),
                        ptr(c.mass_vertices), ptr(c.vertex_mass), static_cast<std::uint32_t>(c.springs.size()),
                        ptr(v.springs[i]), c.structural_count, static_cast<std::uint32_t>(c.triangles.size() / 3),
                        ptr(c.triangles), static_cast<std::uint32_t>(c.pins.size()), ptr(c.pins)});
  }
  for (const auto& [k, val] : s.params) v.params.push_back({k.c_str(), val.c_str()});
  auto n = [](std::size_t x) { return static_cast<std::uint32_t>(x); };
  v.scene = {b2o::kFormatVersion, s.name.c_str(), s.source.c_str(), n(s.positions.size() / 3), ptr(s.positions),
             ptr(s.normals), ptr(s.texcoords), n(s.indices.size()), ptr(s.indices), n(v.objects.size()),
             ptr(v.objects), n(v.submeshes.size()), ptr(v.submeshes), n(v.materials.size()), ptr(v.materials),
             n(v.textures.size()), ptr(v.textures), n(v.cloths.size()), ptr(v.cloths), n(v.params.size()),
             ptr(v.params)};
}

}  // namespace b2o::test

#endif
