// A baked scene filled by hand for the viewer's tests: an n x n cloth (one cloth object with
// masses, structural and bend springs) held flat above a floor quad. Owns its arrays.
#pragma once

#include <blender2ogl/scene_types.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace clothsim::testing {

struct HandScene {
  std::vector<float> positions, normals, texcoords;
  std::vector<std::uint32_t> indices;
  std::vector<b2o::Object> objects;
  std::vector<b2o::Submesh> submeshes;
  std::vector<b2o::Material> materials;
  std::vector<float> rest;
  std::vector<std::uint32_t> mass_offsets, mass_vertices, vertex_mass, triangles, pins;
  std::vector<b2o::Spring> springs;
  std::uint32_t structural = 0;
  b2o::Cloth cloth{};
  b2o::Scene scene{};

  /// n x n masses over [-size/2, size/2]^2 at height y (x, z plane), floor at y = 0.
  explicit HandScene(std::uint32_t n = 12, float size = 1.6f, float y = 1.2f, bool pin_corner = false) {
    const float step = size / static_cast<float>(n - 1);
    for (std::uint32_t j = 0; j < n; ++j)
      for (std::uint32_t i = 0; i < n; ++i) {
        // A slight tilt so the cloth does not land perfectly flat.
        const float x = -0.5f * size + step * static_cast<float>(i);
        const float z = -0.5f * size + step * static_cast<float>(j);
        positions.insert(positions.end(), {x, y + 0.15f * x, z});
        normals.insert(normals.end(), {0.f, 1.f, 0.f});
        texcoords.insert(texcoords.end(), {static_cast<float>(i) / static_cast<float>(n - 1),
                                           static_cast<float>(j) / static_cast<float>(n - 1)});
      }
    for (std::uint32_t j = 0; j + 1 < n; ++j)
      for (std::uint32_t i = 0; i + 1 < n; ++i) {
        const std::uint32_t a = j * n + i, b = a + 1, c = a + n, d = c + 1;
        // Counter-clockwise seen from +Y, so the front face points up.
        indices.insert(indices.end(), {a, c, b, b, c, d});
      }
    const auto cloth_indices = static_cast<std::uint32_t>(indices.size());
    const auto floor_first = static_cast<std::uint32_t>(positions.size() / 3);
    const float f = 3.0f;
    for (float fz : {-f, f})
      for (float fx : {-f, f}) {
        positions.insert(positions.end(), {fx, 0.f, fz});
        normals.insert(normals.end(), {0.f, 1.f, 0.f});
        texcoords.insert(texcoords.end(), {0.f, 0.f});
      }
    indices.insert(indices.end(), {floor_first, floor_first + 2, floor_first + 1,
                                   floor_first + 1, floor_first + 2, floor_first + 3});

    materials.push_back({"Cloth", {0.2f, 0.2f, 0.2f}, {0.2f, 0.45f, 0.8f}, {0.3f, 0.3f, 0.3f}, 30.f, 1.f, b2o::kNone});
    materials.push_back({"Floor", {0.2f, 0.2f, 0.2f}, {0.55f, 0.55f, 0.5f}, {0.1f, 0.1f, 0.1f}, 10.f, 1.f, b2o::kNone});
    submeshes.push_back({0, cloth_indices, 0});
    submeshes.push_back({cloth_indices, 6, 1});
    objects.push_back({"Cloth", "Cloth", 0, n * n, 0, cloth_indices, 0, 1, 0});
    objects.push_back({"Floor", "Floor", floor_first, 4, cloth_indices, 6, 1, 1, b2o::kNone});

    // Masses = render vertices one to one (no seams in this grid).
    rest.assign(positions.begin(), positions.begin() + 3 * n * n);
    for (std::uint32_t m = 0; m <= n * n; ++m) mass_offsets.push_back(m);
    for (std::uint32_t m = 0; m < n * n; ++m) {
      mass_vertices.push_back(m);
      vertex_mass.push_back(m);
    }
    triangles.assign(indices.begin(), indices.begin() + cloth_indices);
    // Structural: unique triangle edges; bend: across each interior edge.
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> opposite;
    for (std::size_t t = 0; t < triangles.size(); t += 3)
      for (int e = 0; e < 3; ++e) {
        std::uint32_t a = triangles[t + e], b = triangles[t + (e + 1) % 3], o = triangles[t + (e + 2) % 3];
        opposite[{std::min(a, b), std::max(a, b)}].push_back(o);
      }
    auto len = [&](std::uint32_t a, std::uint32_t b) {
      float s = 0.f;
      for (int k = 0; k < 3; ++k) s += (rest[3 * a + k] - rest[3 * b + k]) * (rest[3 * a + k] - rest[3 * b + k]);
      return std::sqrt(s);
    };
    for (const auto& [edge, opp] : opposite)
      springs.push_back({edge.first, edge.second, len(edge.first, edge.second), b2o::SpringKind::Structural});
    structural = static_cast<std::uint32_t>(springs.size());
    for (const auto& [edge, opp] : opposite)
      if (opp.size() == 2) springs.push_back({opp[0], opp[1], len(opp[0], opp[1]), b2o::SpringKind::Bend});
    if (pin_corner) pins.push_back(0);

    cloth = {0, n * n, rest.data(), mass_offsets.data(), mass_vertices.data(), vertex_mass.data(),
             static_cast<std::uint32_t>(springs.size()), springs.data(), structural,
             static_cast<std::uint32_t>(triangles.size() / 3), triangles.data(),
             static_cast<std::uint32_t>(pins.size()), pins.empty() ? nullptr : pins.data()};
    scene = {b2o::kFormatVersion, "hand", "hand.obj",
             static_cast<std::uint32_t>(positions.size() / 3), positions.data(), normals.data(), texcoords.data(),
             static_cast<std::uint32_t>(indices.size()), indices.data(),
             static_cast<std::uint32_t>(objects.size()), objects.data(),
             static_cast<std::uint32_t>(submeshes.size()), submeshes.data(),
             static_cast<std::uint32_t>(materials.size()), materials.data(),
             0, nullptr, 1, &cloth, 0, nullptr};
  }
  HandScene(const HandScene&) = delete;
  HandScene& operator=(const HandScene&) = delete;
};

}  // namespace clothsim::testing
