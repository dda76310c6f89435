#include <clothsim/collision.hpp>
#include <clothsim/model_builder.hpp>
#include <clothsim/scene.hpp>

#include <blender2ogl/scene_types.h>

#include <algorithm>
#include <span>
#include <stdexcept>

namespace clothsim {

namespace {

[[noreturn]] void fail(const b2o::Scene& scene, const std::string& what) {
  throw std::runtime_error("scene '" + std::string(scene.name ? scene.name : "?") + "': " + what);
}

}  // namespace

BakedParams read_scene_params(const b2o::Scene& scene, Options base) {
  BakedParams out;
  out.options = base;
  for (std::uint32_t i = 0; i < scene.param_count; ++i) {
    const std::string key = scene.params[i].key ? scene.params[i].key : "";
    const OptionInfo* option = find_option(key);
    if (!option)
      out.unknown.push_back(key);
    else if (std::string why = option->set(out.options, scene.params[i].value ? scene.params[i].value : ""); !why.empty())
      out.refused.push_back({key, std::move(why)});
    else if (option->group == OptionGroup::Seed)
      out.seed_given = true;
    else if (key == "friction" || key == "static_friction")
      out.friction_key = key;
  }
  return out;
}

bool has_colliders(const b2o::Scene& scene) {
  for (std::uint32_t o = 0; o < scene.object_count; ++o)
    if (scene.objects[o].cloth == b2o::kNone && scene.objects[o].index_count > 0) return true;
  return false;
}

Options scene_options(const b2o::Scene& scene, Options base) {
  BakedParams p = read_scene_params(scene, base);
  if (!p.refused.empty()) fail(scene, "PARAMS " + p.refused[0].key + " " + p.refused[0].why);
  if (!p.friction_key.empty() && !has_colliders(scene))
    fail(scene, "PARAMS " + p.friction_key + ": the scene has no colliders, friction acts on nothing");
  try {
    return resolve_options(p.options, p.seed_given);
  } catch (const std::invalid_argument& e) {
    fail(scene, std::string("PARAMS: ") + e.what());
  }
}

Model build_model(const b2o::Scene& scene, const Options& options) {
  if (scene.format_version != b2o::kFormatVersion)
    fail(scene, "baked format " + std::to_string(scene.format_version) + ", this program reads " +
                    std::to_string(b2o::kFormatVersion) + " (rebuild the scene)");
  ModelBuilder builder(options, scene.name ? scene.name : "");
  std::vector<SpringSpec> springs;
  for (std::uint32_t c = 0; c < scene.cloth_count; ++c) {
    const b2o::Cloth& cloth = scene.cloths[c];
    Eigen::Matrix3Xd x(3, cloth.mass_count);
    for (std::uint32_t i = 0; i < cloth.mass_count; ++i)
      for (int k = 0; k < 3; ++k) x(k, i) = static_cast<double>(cloth.rest_positions[3 * i + static_cast<std::uint32_t>(k)]);
    springs.clear();
    for (std::uint32_t s = 0; s < cloth.spring_count; ++s) {
      const b2o::Spring& sp = cloth.springs[s];
      springs.push_back(SpringSpec{sp.a, sp.b, static_cast<std::uint8_t>(sp.kind == b2o::SpringKind::Bend), -1.0});
    }
    try {
      builder.add_cloth(x, springs, std::span(cloth.pins, cloth.pin_count),
                        std::span(cloth.triangles, 3 * std::size_t{cloth.triangle_count}), static_cast<std::int32_t>(c));
    } catch (const std::invalid_argument& e) {
      fail(scene, e.what());
    }
  }

  auto colliders = std::make_shared<ColliderSet>();
  std::vector<std::uint32_t> idx;
  for (std::uint32_t o = 0; o < scene.object_count; ++o) {
    const b2o::Object& obj = scene.objects[o];
    if (obj.cloth != b2o::kNone || obj.index_count == 0) continue;
    Eigen::Matrix3Xd v(3, obj.vertex_count);
    for (std::uint32_t i = 0; i < obj.vertex_count; ++i)
      for (int k = 0; k < 3; ++k)
        v(k, i) = static_cast<double>(scene.positions[3 * (obj.first_vertex + i) + static_cast<std::uint32_t>(k)]);
    idx.clear();
    for (std::uint32_t i = 0; i < obj.index_count; ++i) {
      const std::uint32_t g = scene.indices[obj.first_index + i];
      if (g < obj.first_vertex || g >= obj.first_vertex + obj.vertex_count)
        fail(scene, std::string("object '") + obj.name + "' has an index outside its vertices");
      idx.push_back(g - obj.first_vertex);
    }
    try {
      colliders->add_object(obj.name ? obj.name : "", v, idx);
    } catch (const std::exception& e) {
      fail(scene, e.what());
    }
  }
  if (colliders->object_count() > 0) {
    colliders->build();
    // Every clearance now rather than when the cloth first reaches each triangle: steady step
    // times from the first step (a few microseconds per triangle: milliseconds for the baked
    // scenes, ~0.75 s for 82k triangles). docs/collision.md, "When clearances are computed".
    colliders->prepare_clearances();
    builder.set_colliders(std::move(colliders));
  }
  return builder.build();
}

std::size_t collider_triangle_count(const Model& model) {
  return model.colliders ? model.colliders->triangle_count() : 0;
}

}  // namespace clothsim
