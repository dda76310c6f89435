// bake: cloth data for the `-a` objects: weld by exact position, springs, triangles, pins.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <unordered_map>

#include <blender2ogl/solid_parts.hpp>

#include "converter.hpp"
#include "prescan.hpp"

namespace b2o::conv {
namespace {

struct Key {
  std::uint32_t x, y, z;
  bool operator==(const Key&) const = default;
};
struct KeyHash {
  std::size_t operator()(const Key& k) const noexcept {
    std::uint64_t h = 14695981039346656037ull;
    for (std::uint32_t v : {k.x, k.y, k.z}) h = (h ^ v) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};
std::uint32_t bits(float f) {
  if (f == 0.0f) f = 0.0f;  // -0 and +0 are one position
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

double dist2(const float* a, const float* b) {
  const double dx = double(a[0]) - b[0], dy = double(a[1]) - b[1], dz = double(a[2]) - b[2];
  return dx * dx + dy * dy + dz * dz;
}

// The squared diagonal of a cloth's rest bounding box (0 without masses).
double diagonal2(const Cloth& c) {
  if (c.rest_positions.size() < 3) return 0.0;
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = c.rest_positions[static_cast<std::size_t>(k)];
  for (std::size_t m = 0; m < c.rest_positions.size(); ++m) {
    lo[m % 3] = std::min(lo[m % 3], c.rest_positions[m]);
    hi[m % 3] = std::max(hi[m % 3], c.rest_positions[m]);
  }
  return dist2(lo, hi);
}

std::uint32_t nearest_mass(const Cloth& c, const float* p, double& d2) {
  std::uint32_t best = 0;
  d2 = std::numeric_limits<double>::infinity();
  for (std::uint32_t m = 0; m < c.mass_count(); ++m) {
    const double d = dist2(&c.rest_positions[3 * m], p);
    if (d < d2) d2 = d, best = m;
  }
  return best;
}

const Object* find_object(const Scene& s, const std::string& want, const std::string& stem) {
  for (const Object& o : s.objects)
    if (o.name == want) return &o;
  // the 2016 tool's `<file>_<Object>` form
  const std::string prefix = stem + "_";
  if (want.size() > prefix.size() && want.compare(0, prefix.size(), prefix) == 0) {
    const std::string rest = want.substr(prefix.size());
    for (const Object& o : s.objects)
      if (o.name == rest || o.identifier == rest) return &o;
  }
  for (const Object& o : s.objects)
    if (o.identifier == want) return &o;
  return nullptr;
}

std::string object_list(const Scene& s) {
  std::string list;
  std::size_t n = 0;
  for (const Object& o : s.objects) {
    if (++n > 20) return list + ", ... (" + std::to_string(s.objects.size()) + " in all)";  // one readable line
    list += (list.empty() ? "" : ", ") + quote_input(o.name);
  }
  return list;
}

Cloth build_cloth(Scene& s, std::uint32_t object_index, bool reverse, Stats& stats, const std::string& file) {
  const Object& o = s.objects[object_index];
  Cloth c;
  c.object = object_index;
  std::vector<char> in_face(o.vertex_count, 0);
  for (std::uint32_t i = o.first_index; i < o.first_index + o.index_count; ++i) in_face[s.indices[i] - o.first_vertex] = 1;

  // Weld by exact position, in order of first appearance.
  std::unordered_map<Key, std::uint32_t, KeyHash> weld;
  weld.reserve(o.vertex_count);
  std::vector<std::uint32_t> vmass(o.vertex_count, std::numeric_limits<std::uint32_t>::max());
  std::uint32_t loose = 0;
  for (std::uint32_t v = 0; v < o.vertex_count; ++v) {
    if (!in_face[v]) {
      ++loose;
      continue;
    }
    const float* p = &s.positions[3 * (o.first_vertex + v)];
    const Key k{bits(p[0]), bits(p[1]), bits(p[2])};
    auto [it, added] = weld.try_emplace(k, static_cast<std::uint32_t>(c.rest_positions.size() / 3));
    if (added) c.rest_positions.insert(c.rest_positions.end(), {p[0], p[1], p[2]});
    vmass[v] = it->second;
  }
  if (loose > 0) {
    stats.loose_vertices += loose;
    s.warnings.push_back(file + ": cloth " + quote_input(o.name) + ": " + std::to_string(loose) +
                         " vertices in no face get no mass (vertex_mass = 0xffffffff)");
  }
  // mass -> render vertices (CSR, vertices ascending within a mass)
  const std::uint32_t masses = c.mass_count();
  c.mass_vertex_offsets.assign(masses + 1u, 0);
  for (std::uint32_t m : vmass)
    if (m != std::numeric_limits<std::uint32_t>::max()) ++c.mass_vertex_offsets[m + 1];
  for (std::uint32_t m = 0; m < masses; ++m) c.mass_vertex_offsets[m + 1] += c.mass_vertex_offsets[m];
  c.mass_vertices.resize(c.mass_vertex_offsets[masses]);
  {
    std::vector<std::uint32_t> fill(c.mass_vertex_offsets.begin(), c.mass_vertex_offsets.end() - 1);
    for (std::uint32_t v = 0; v < o.vertex_count; ++v)
      if (vmass[v] != std::numeric_limits<std::uint32_t>::max()) c.mass_vertices[fill[vmass[v]]++] = o.first_vertex + v;
  }
  if (reverse) c.vertex_mass = vmass;

  // Triangles in mass indices; degenerate ones (repeated mass, zero area) left out.
  struct HalfEdge {
    std::uint64_t key;  // (min << 32) | max
    std::uint32_t opposite;
  };
  std::vector<HalfEdge> half;
  half.reserve(o.index_count);
  std::uint32_t degenerate = 0;
  for (std::uint32_t i = o.first_index; i < o.first_index + o.index_count; i += 3) {
    const std::uint32_t t[3] = {vmass[s.indices[i] - o.first_vertex], vmass[s.indices[i + 1] - o.first_vertex],
                                vmass[s.indices[i + 2] - o.first_vertex]};
    bool bad = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    if (!bad) {
      const float* a = &c.rest_positions[3 * t[0]];
      const float* b = &c.rest_positions[3 * t[1]];
      const float* d = &c.rest_positions[3 * t[2]];
      const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
      const double e2[3] = {double(d[0]) - a[0], double(d[1]) - a[1], double(d[2]) - a[2]};
      const double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
                   cz = e1[0] * e2[1] - e1[1] * e2[0];
      bad = cx == 0.0 && cy == 0.0 && cz == 0.0;
    }
    if (bad) {
      ++degenerate;
      continue;
    }
    c.triangles.insert(c.triangles.end(), t, t + 3);
    for (int e = 0; e < 3; ++e) {
      const std::uint64_t a = t[e], b = t[(e + 1) % 3];
      half.push_back({(std::min(a, b) << 32) | std::max(a, b), t[(e + 2) % 3]});
    }
  }
  // A cloth without a triangle has no springs: nothing the simulator could move.
  if (c.triangles.empty())
    throw InputError(file + ": cloth " + quote_input(o.name) + ": no usable triangle (all " +
                     std::to_string(degenerate) + " are degenerate: a repeated vertex or no area); it would get no springs");
  if (degenerate > 0) {
    stats.degenerate_triangles += degenerate;
    s.warnings.push_back(file + ": cloth " + quote_input(o.name) + ": " + std::to_string(degenerate) +
                         " degenerate triangles left out of the cloth");
  }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.key != y.key ? x.key < y.key : x.opposite < y.opposite;
  });

  auto rest = [&](std::uint32_t a, std::uint32_t b) {
    return static_cast<float>(std::sqrt(dist2(&c.rest_positions[3 * a], &c.rest_positions[3 * b])));
  };
  // Structural: every unique edge, sorted by (a, b). Bend: across each edge of exactly two
  // triangles, joining the opposite masses unless they coincide or are already joined.
  std::vector<std::uint64_t> structural, bend;
  std::uint32_t nonmanifold = 0;
  for (std::size_t i = 0; i < half.size();) {
    std::size_t j = i;
    while (j < half.size() && half[j].key == half[i].key) ++j;
    structural.push_back(half[i].key);
    if (j - i > 2) ++nonmanifold;
    if (j - i == 2) {
      const std::uint64_t p = half[i].opposite, q = half[i + 1].opposite;
      if (p != q) bend.push_back((std::min(p, q) << 32) | std::max(p, q));
    }
    i = j;
  }
  std::sort(bend.begin(), bend.end());
  bend.erase(std::unique(bend.begin(), bend.end()), bend.end());
  for (std::uint64_t k : structural)
    c.springs.push_back({static_cast<std::uint32_t>(k >> 32), static_cast<std::uint32_t>(k), 0.0f, 0});
  c.structural_count = static_cast<std::uint32_t>(c.springs.size());
  for (std::uint64_t k : bend)
    if (!std::binary_search(structural.begin(), structural.end(), k))
      c.springs.push_back({static_cast<std::uint32_t>(k >> 32), static_cast<std::uint32_t>(k), 0.0f, 1});
  for (Spring& sp : c.springs) {
    sp.rest_length = rest(sp.a, sp.b);
    // finite floats up to 3.4e38 can be farther apart than the largest float
    if (!std::isfinite(sp.rest_length))
      throw InputError(file + ": cloth " + quote_input(o.name) +
                       ": coordinates too large: spring rest length overflows");
  }
  if (nonmanifold > 0) {
    stats.nonmanifold_edges += nonmanifold;
    s.warnings.push_back(file + ": cloth " + quote_input(o.name) + ": " + std::to_string(nonmanifold) +
                         " non-manifold edges (3+ triangles) get no bend springs");
  }
  return c;
}

// A collider pushes the cloth out along its faces' normals: a closed mesh whose faces point
// inwards (negative signed volume) pushes the cloth into it. Warned for closed meshes (every
// edge of exactly two triangles), per connected part: an open mesh (a floor plane) has no
// inside. A closed part with an edge used twice in the same direction has faces pointing
// both ways: warned too. Vertices are welded by exact position (split normals and UVs).
void check_collider_orientation(Scene& s, const Object& o, const std::string& file) {
  std::vector<double> corners;  // the object's triangles, 9 numbers each (exact: float to double)
  corners.reserve(3 * static_cast<std::size_t>(o.index_count));
  for (std::uint32_t i = o.first_index; i < o.first_index + o.index_count; ++i) {
    const float* p = &s.positions[3 * static_cast<std::size_t>(s.indices[i])];
    corners.insert(corners.end(), {double(p[0]), double(p[1]), double(p[2])});
  }
  const std::vector<b2o::SolidPart> parts = b2o::solid_parts(corners.data(), o.index_count / 3);
  std::string where = file;
  if (auto it = s.object_lines.find(o.name); it != s.object_lines.end() && !it->second.empty())
    where += ":" + std::to_string(it->second.front());
  const std::string fix = "; fix it in Blender: Edit Mode, select all, Mesh > Normals > Recalculate Outside";
  std::size_t inconsistent = 0, inward = 0, closed = 0;
  double volume = 0.0;
  for (const b2o::SolidPart& part : parts) {
    if (!part.closed) continue;
    ++closed;
    if (part.inconsistent()) {
      inconsistent += part.same_direction;
    } else if (part.inward()) {
      ++inward;
      volume += part.volume;
    }
  }
  const std::string of = closed > 1 ? " of " + std::to_string(closed) + " closed parts" : "";
  if (inconsistent > 0)
    s.warnings.push_back(where + ": collider " + quote_input(o.name) + ": closed mesh with inconsistently oriented faces (" +
                         std::to_string(inconsistent) + " edges used twice in the same direction): the cloth is pushed " +
                         "into it where its faces point inwards" + fix);
  if (inward > 0) {
    char vol[64];
    std::snprintf(vol, sizeof vol, "%.6g", volume);
    s.warnings.push_back(where + ": collider " + quote_input(o.name) + ": closed mesh with negative volume (" + vol +
                         " m^3" + (closed > 1 ? ", " + std::to_string(inward) + of : "") +
                         "): its faces point inwards, so the cloth is pushed into it" + fix);
  }
}

}  // namespace

void bake_scene(Scene& s, const Options& opt, Stats& stats) {
  const std::string file = opt.input.string();
  const std::string stem = opt.input.stem().string();
  assign_identifiers(s);

  std::vector<std::uint32_t> chosen;
  for (const std::string& want : opt.cloth_objects) {
    const Object* o = find_object(s, want, stem);
    if (o == nullptr) {
      // `CLOTH My Flag` unquoted in CMake gives `-a My`: say which name it was cut from
      std::string hint;
      for (const Object& other : s.objects)
        if (other.name.size() > want.size() + 1 && other.name.compare(0, want.size() + 1, want + " ") == 0) {
          hint = " (did you mean " + quote_input(other.name) + "? a name with spaces must be quoted: -a \"" +
                 other.name + "\", CLOTH \"" + other.name + "\")";
          break;
        }
      throw InputError(file + ": no object " + quote_input(want) + " to give masses (-a)" + hint + "; objects: " +
                       object_list(s));
    }
    // a name two objects share (a repeated `g`): only its identifier tells them apart
    if (want != o->identifier || want == o->name) {
      std::size_t same = 0;
      std::string ids;
      for (const Object& x : s.objects)
        if (x.name == o->name) ++same, ids += (ids.empty() ? "" : ", ") + x.identifier;
      if (same > 1) {
        std::string lines;
        if (auto it = s.object_lines.find(o->name); it != s.object_lines.end())
          for (std::size_t line : it->second) lines += (lines.empty() ? " (" : ", ") + file + ":" + std::to_string(line);
        throw InputError(file + ": -a " + quote_input(want) + ": " + std::to_string(same) + " objects are named " +
                         quote_input(o->name) + (lines.empty() ? "" : lines + ")") + "; select one by its identifier (" +
                         ids + ") or rename them in the model");
      }
    }
    const auto idx = static_cast<std::uint32_t>(o - s.objects.data());
    if (std::find(chosen.begin(), chosen.end(), idx) == chosen.end()) chosen.push_back(idx);
  }
  std::sort(chosen.begin(), chosen.end());  // cloths in object order
  for (std::uint32_t idx : chosen) {
    s.objects[idx].cloth = static_cast<std::int32_t>(s.cloths.size());
    s.cloths.push_back(build_cloth(s, idx, opt.reverse_map, stats, file));
  }

  for (const Object& o : s.objects)
    if (o.cloth < 0 && o.index_count > 0) check_collider_orientation(s, o, file);

  auto cloth_of = [&](const std::string& name) -> Cloth* {
    const Object* o = find_object(s, name, stem);
    if (o == nullptr || o->cloth < 0) return nullptr;
    return &s.cloths[static_cast<std::size_t>(o->cloth)];
  };
  // Pins from the model: every vertex of `<OBJECT>_pins` pins the nearest mass of OBJECT.
  for (const auto& [helper, pts] : s.pin_points) {
    const std::string target = pin_target_name(helper);
    std::string where = file;  // the helper's line when known
    if (auto it = s.object_lines.find(helper); it != s.object_lines.end() && !it->second.empty())
      where += ":" + std::to_string(it->second.front());
    if (opt.merge && find_object(s, target, stem) == nullptr) {  // (-m merged its object into one)
      s.warnings.push_back(where + ": pin object " + quote_input(helper) + " ignored: -m merges the objects (a pin "
                           "needs its object, with -a, unmerged)");
      continue;
    }
    if (find_object(s, target, stem) == nullptr)
      throw InputError(where + ": pin object " + quote_input(helper) + " names no object " + quote_input(target) +
                       " (the name before _pins/.pins must be an object's, as written); objects: " + object_list(s));
    if (pts.size() < 3)
      throw InputError(where + ": pin object " + quote_input(helper) + " has no vertices: it would pin nothing");
    Cloth* c = cloth_of(target);
    if (c == nullptr) {
      s.warnings.push_back(file + ": pin object " + quote_input(helper) + " ignored: " + quote_input(target) + " has no masses (-a)");
      continue;
    }
    if (c->mass_count() == 0) continue;
    const double diag2 = diagonal2(*c);
    for (std::size_t p = 0; p + 2 < pts.size(); p += 3) {
      double d2 = 0;
      const std::uint32_t m = nearest_mass(*c, &pts[p], d2);
      if (d2 > 1e-4 * diag2)
        throw InputError(file + ": pin object " + quote_input(helper) + ": vertex " + std::to_string(p / 3 + 1) +
                         " is " + std::to_string(std::sqrt(d2)) + " from the nearest mass of " + quote_input(target) +
                         " (more than 1 % of its size)");
      c->pins.push_back(m);
    }
  }
  for (const PinSpec& pin : opt.pins) {
    if (find_object(s, pin.object, stem) == nullptr)
      throw InputError(file + ": no object " + quote_input(pin.object) + " to pin (-p); objects: " + object_list(s));
    Cloth* c = cloth_of(pin.object);
    if (c == nullptr) throw UsageError("-p " + pin.object + ": the object has no masses; give it -a " + pin.object);
    double d2 = 0;
    if (c->mass_count() == 0) continue;
    c->pins.push_back(nearest_mass(*c, pin.point.data(), d2));
    // pinned anyway (a coordinate typed by hand is seldom on a mass), but a point a quarter of
    // the cloth's size or more from every mass is likely a typo
    if (d2 > 0.0625 * diagonal2(*c)) {
      char at[96];
      std::snprintf(at, sizeof at, "%g,%g,%g", double(pin.point[0]), double(pin.point[1]), double(pin.point[2]));
      s.warnings.push_back(file + ": -p " + pin.object + ":" + at + " is " + std::to_string(std::sqrt(d2)) +
                           " from the nearest mass of " + quote_input(pin.object) +
                           " (more than a quarter of its size); that mass is pinned");
    }
  }
  for (Cloth& c : s.cloths) {
    std::sort(c.pins.begin(), c.pins.end());
    c.pins.erase(std::unique(c.pins.begin(), c.pins.end()), c.pins.end());
  }
  s.params = opt.params;
}

}  // namespace b2o::conv
