// OBJ frames of a headless run (--export-obj): each cloth as its object's render mesh.
#include "run.hpp"

#include <clothsim/output_file.hpp>

#include <blender2ogl/scene_types.h>

#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <vector>

#ifndef CLOTHSIM_VERSION
#define CLOTHSIM_VERSION "0.0.0"
#endif

namespace clothsim::app {

std::string export_obj(const std::string& dir, const b2o::Scene& scene, const Model& model, const State& s,
                       std::uint64_t step, double dt) {
  char name[64];
  std::snprintf(name, sizeof name, "%s_%06llu.obj", model.scene_name.c_str(),
                static_cast<unsigned long long>(step));
  std::ostringstream out;
  out << "# clothsim " << CLOTHSIM_VERSION << ", t = " << s.t << " s, step " << step << " of dt " << dt << " s\n";
  // Positions exactly (17 digits read back the same double). A baked cloth is written as its
  // object's render mesh: its vertices in the scene's order (each at its mass), its texture
  // coordinates and triangles, so the frames map onto the model and keep its UV seams.
  out.precision(std::numeric_limits<double>::max_digits10);
  std::size_t base = 1;  // OBJ indices are 1-based and file-global
  for (const ClothRange& r : model.cloths) {
    const b2o::Cloth* cloth = r.scene_cloth >= 0 ? &scene.cloths[r.scene_cloth] : nullptr;
    if (cloth == nullptr) {  // a cloth made in code: its masses and no faces
      out << "o cloth\n";
      for (std::uint32_t i = 0; i < r.mass_count; ++i) {
        const auto c = s.x.col(r.first_mass + i);
        out << "v " << c.x() << ' ' << c.y() << ' ' << c.z() << "\n";
      }
      base += r.mass_count;
      continue;
    }
    const b2o::Object& obj = scene.objects[cloth->object];
    out << "o " << obj.name << "\n";
    std::vector<std::uint32_t> mass_of(obj.vertex_count, std::numeric_limits<std::uint32_t>::max());
    for (std::uint32_t m = 0; m < cloth->mass_count; ++m)
      for (std::uint32_t k = cloth->mass_vertex_offsets[m]; k < cloth->mass_vertex_offsets[m + 1]; ++k)
        if (const std::uint32_t v = cloth->mass_vertices[k] - obj.first_vertex; v < obj.vertex_count) mass_of[v] = m;
    for (std::uint32_t v = 0; v < obj.vertex_count; ++v) {
      if (mass_of[v] < cloth->mass_count) {
        const auto c = s.x.col(r.first_mass + mass_of[v]);
        out << "v " << c.x() << ' ' << c.y() << ' ' << c.z() << "\n";
      } else {  // a render vertex of no mass: where the model has it
        const float* c = scene.positions + 3 * (std::size_t{obj.first_vertex} + v);
        out << "v " << double(c[0]) << ' ' << double(c[1]) << ' ' << double(c[2]) << "\n";
      }
    }
    for (std::uint32_t v = 0; v < obj.vertex_count; ++v) {
      const float* t = scene.texcoords + 2 * (std::size_t{obj.first_vertex} + v);
      out << "vt " << double(t[0]) << ' ' << double(t[1]) << "\n";
    }
    for (std::uint32_t i = obj.first_index; i + 2 < obj.first_index + obj.index_count; i += 3) {
      out << 'f';
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::size_t idx = base + (scene.indices[i + k] - obj.first_vertex);
        out << ' ' << idx << '/' << idx;
      }
      out << '\n';
    }
    base += obj.vertex_count;
  }
  return io::write_output_file((std::filesystem::path(dir) / name).string(), out.str());
}

}  // namespace clothsim::app
