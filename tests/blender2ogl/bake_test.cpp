// bake: weld by exact position, springs (structural then bend), triangles, pins, warnings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "support.hpp"

namespace {

using namespace b2o::test;
namespace conv = b2o::conv;

conv::Options opts(const std::string& file, std::vector<std::string> cloths) {
  conv::Options o;
  o.input = fixture(file);
  o.cloth_objects = std::move(cloths);
  o.reverse_map = true;
  return o;
}

void check_cloth_invariants(const conv::Scene& s, const conv::Cloth& c) {
  const auto& obj = s.objects[c.object];
  const std::uint32_t m = c.mass_count();
  ASSERT_EQ(c.mass_vertex_offsets.size(), m + 1u);
  EXPECT_EQ(c.mass_vertex_offsets.back(), c.mass_vertices.size());
  for (std::uint32_t k = 0; k < m; ++k)
    for (std::uint32_t j = c.mass_vertex_offsets[k]; j < c.mass_vertex_offsets[k + 1]; ++j) {
      const std::uint32_t v = c.mass_vertices[j];
      ASSERT_GE(v, obj.first_vertex);
      ASSERT_LT(v, obj.first_vertex + obj.vertex_count);
      for (int a = 0; a < 3; ++a) EXPECT_EQ(s.positions[3 * v + a], c.rest_positions[3 * k + a]);  // exact weld
      if (!c.vertex_mass.empty()) {
        EXPECT_EQ(c.vertex_mass[v - obj.first_vertex], k);
      }
    }
  // distinct positions per mass
  std::set<std::array<float, 3>> distinct;
  for (std::uint32_t k = 0; k < m; ++k)
    distinct.insert({c.rest_positions[3 * k], c.rest_positions[3 * k + 1], c.rest_positions[3 * k + 2]});
  EXPECT_EQ(distinct.size(), m);
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::size_t i = 0; i < c.springs.size(); ++i) {
    const auto& sp = c.springs[i];
    EXPECT_LT(sp.a, sp.b);
    EXPECT_LT(sp.b, m);
    EXPECT_EQ(sp.kind, i < c.structural_count ? 0u : 1u);
    EXPECT_TRUE(pairs.insert({sp.a, sp.b}).second) << "spring joined twice";
    const float* pa = &c.rest_positions[3 * sp.a];
    const float* pb = &c.rest_positions[3 * sp.b];
    const double d = std::sqrt(std::pow(double(pa[0]) - pb[0], 2) + std::pow(double(pa[1]) - pb[1], 2) +
                               std::pow(double(pa[2]) - pb[2], 2));
    EXPECT_EQ(sp.rest_length, static_cast<float>(d));
    if (i > 0 && (i < c.structural_count) == (i - 1 < c.structural_count)) {  // sorted within a kind
      const auto& prev = c.springs[i - 1];
      EXPECT_TRUE(prev.a < sp.a || (prev.a == sp.a && prev.b < sp.b));
    }
  }
  for (std::uint32_t t : c.triangles) EXPECT_LT(t, m);
  EXPECT_TRUE(std::is_sorted(c.pins.begin(), c.pins.end()));
  EXPECT_EQ(std::adjacent_find(c.pins.begin(), c.pins.end()), c.pins.end());
}

TEST(Bake, GridSpringsAndPinsFromTheModel) {
  const auto s = convert(opts("grid.obj", {"Cloth"}));
  ASSERT_EQ(s.cloths.size(), 1u);
  const auto& c = s.cloths[0];
  EXPECT_EQ(s.objects[0].cloth, 0);
  EXPECT_EQ(s.objects[1].cloth, -1);
  EXPECT_EQ(c.mass_count(), 9u);
  // 3x3 grid of 4 quads split into 8 triangles: 12 grid edges + 4 diagonals
  EXPECT_EQ(c.structural_count, 16u);
  EXPECT_EQ(c.springs.size() - c.structural_count, 8u);  // one across each interior edge
  EXPECT_EQ(c.triangles.size(), 24u);
  // the two corners at z = -0.5 (x = -0.5 and 0.5) are pinned by Cloth_pins
  ASSERT_EQ(c.pins.size(), 2u);
  for (std::uint32_t p : c.pins) {
    EXPECT_EQ(c.rest_positions[3 * p + 2], -0.5f);
    EXPECT_EQ(std::fabs(c.rest_positions[3 * p]), 0.5f);
  }
  check_cloth_invariants(s, c);
}

TEST(Bake, OldFileObjectFormAndCommandLinePins) {
  auto o = opts("grid.obj", {"grid_Cloth"});
  o.pins.push_back({"Cloth", {0.4f, 1.0f, 0.6f}});  // nearest: (0.5, 1, 0.5)
  const auto s = convert(o);
  ASSERT_EQ(s.cloths.size(), 1u);
  const auto& c = s.cloths[0];
  ASSERT_EQ(c.pins.size(), 3u);
  bool found = false;
  for (std::uint32_t p : c.pins)
    found |= c.rest_positions[3 * p] == 0.5f && c.rest_positions[3 * p + 2] == 0.5f;
  EXPECT_TRUE(found);
}

// A -p point far from the cloth (a typo: 20 for 2) still pins the nearest mass, with a warning;
// one near a mass (typed by hand, not on it) without.
TEST(Bake, CommandLinePinFarFromTheClothIsWarned) {
  auto o = opts("grid.obj", {"Cloth"});
  o.pins.push_back({"Cloth", {0.4f, 1.0f, 0.6f}});
  EXPECT_TRUE(convert(o).warnings.empty());
  o.pins.push_back({"Cloth", {0.5f, 20.0f, 0.5f}});
  const auto s = convert(o);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("-p Cloth:0.5,20,0.5 is 19"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("that mass is pinned"), std::string::npos) << s.warnings[0];
}

TEST(Bake, UnknownClothObjectIsAnInputError) {
  try {
    convert(opts("grid.obj", {"Nope"}));
    FAIL() << "no error";
  } catch (const conv::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("grid.obj"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("'Nope'"), std::string::npos);
  }
}

TEST(Bake, PinOnObjectWithoutMassesIsAUsageError) {
  auto o = opts("grid.obj", {"Cloth"});
  o.pins.push_back({"Floor", {0, 0, 0}});
  EXPECT_THROW(convert(o), conv::UsageError);
}

TEST(Bake, WeldSeamsDegenerateAndNonManifold) {
  // A cube whose faces have their own UVs (assimp keeps 24 vertices; 8 masses), plus a
  // degenerate triangle and a fin: an edge shared by three triangles.
  const auto dir = scratch("bake_weld");
  std::string obj = "o Box\n";
  const float P[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (auto& p : P) obj += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  obj += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  for (const char* f : {"1 4 3 2", "5 6 7 8", "1 2 6 5", "2 3 7 6", "3 4 8 7", "4 1 5 8"}) {
    int a, b, c, d;
    std::sscanf(f, "%d %d %d %d", &a, &b, &c, &d);
    obj += "f " + std::to_string(a) + "/1 " + std::to_string(b) + "/2 " + std::to_string(c) + "/3 " +
           std::to_string(d) + "/4\n";
  }
  write_file(dir / "box.obj", obj);
  auto s = convert(opts((dir / "box.obj").string(), {"Box"}));
  const auto& c = s.cloths[0];
  EXPECT_GT(s.objects[0].vertex_count, 8u);
  EXPECT_EQ(c.mass_count(), 8u);
  EXPECT_EQ(c.structural_count, 18u);  // 12 edges + 6 face diagonals
  EXPECT_EQ(c.triangles.size(), 36u);
  check_cloth_invariants(s, c);

  write_file(dir / "fin.obj",
             "o Fin\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 2 0 0\n"
             "f 1 2 3\nf 2 1 4\nf 1 2 5\nf 1 2 6\n");  // edge 1-2 in four triangles; 1 2 6 is flat
  conv::Stats stats;
  auto f = conv::import_scene(dir / "fin.obj", false);
  auto fo = opts((dir / "fin.obj").string(), {"Fin"});
  conv::bake_scene(f, fo, stats);
  EXPECT_EQ(stats.degenerate_triangles, 1u);
  EXPECT_EQ(stats.nonmanifold_edges, 1u);
  EXPECT_EQ(f.cloths[0].triangles.size(), 9u);
  EXPECT_EQ(f.cloths[0].springs.size(), f.cloths[0].structural_count);  // no bend across the fin
  EXPECT_GE(f.warnings.size(), 2u);
  check_cloth_invariants(f, f.cloths[0]);
}

TEST(Bake, PinHelperTooFarIsAnError) {
  const auto dir = scratch("bake_pin_far");
  write_file(dir / "far.obj", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no Cloth_pins\nv 5 5 5\n");
  try {
    convert(opts((dir / "far.obj").string(), {"Cloth"}));
    FAIL() << "no error";
  } catch (const conv::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("far.obj"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("Cloth_pins"), std::string::npos);
  }
}

// -m merges the objects into one: a pin helper whose object is merged away is ignored with
// a warning (the bake does not fail with "names no object 'Cloth'"); with one object
// (nothing merged) it still pins.
TEST(Bake, MergedModelIgnoresItsPinHelper) {
  const auto dir = scratch("bake_pin_merged");
  write_file(dir / "pins.obj", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no Floor\nv 0 -1 0\nv 1 -1 0\n"
                               "v 0 -1 1\nf 4 6 5\no Cloth_pins\nv 0 0 0\n");
  auto o = opts((dir / "pins.obj").string(), {});
  o.merge = true;
  const auto s = convert(o);
  ASSERT_EQ(s.objects.size(), 1u);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings.back().find("pin object 'Cloth_pins' ignored: -m merges the objects"),
            std::string::npos) << s.warnings.back();
  write_file(dir / "one.obj", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no Cloth_pins\nv 0 0 0\n");
  auto one = opts((dir / "one.obj").string(), {"Cloth"});
  one.merge = true;
  const auto p = convert(one);
  ASSERT_EQ(p.cloths.size(), 1u);
  EXPECT_EQ(p.cloths[0].pins.size(), 1u);
}

// A pin helper must pin something: one naming no object (a typo, or a name assimp cut short)
// or with no vertices is an error at its line, never "0 pins".
TEST(Bake, PinHelperNamingNoObjectOrEmptyIsAnError) {
  const auto dir = scratch("bake_pin_helper_errors");
  const std::string cloth = "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  write_file(dir / "typo.obj", cloth + "o Clth_pins\nv 0 0 0\n");
  write_file(dir / "empty.obj", cloth + "o Cloth_pins\no Floor\nv 0 -1 0\nv 1 -1 0\nv 0 -1 1\nf 4 6 5\n");
  struct Case {
    const char* file;
    std::vector<std::string> cloths;
    const char* want;
  };
  for (const Case& c : {Case{"typo.obj", {"Cloth"}, "typo.obj:6: pin object 'Clth_pins' names no object 'Clth'"},
                        Case{"typo.obj", {}, "typo.obj:6: pin object 'Clth_pins' names no object 'Clth'"},
                        Case{"empty.obj", {"Cloth"}, "empty.obj:6: pin object 'Cloth_pins' has no vertices"}}) {
    try {
      convert(opts((dir / c.file).string(), c.cloths));
      ADD_FAILURE() << c.file << ": no error";
    } catch (const conv::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.want), std::string::npos) << e.what();
      if (std::string(c.file) == "typo.obj") {
        EXPECT_NE(std::string(e.what()).find("objects: 'Cloth'"), std::string::npos) << e.what();
      }
    }
  }
}

// A unit cube as OBJ text: 6 quads, counter-clockwise seen from outside unless `flip` lists
// a face to reverse (all 6: the whole cube inside out); `drop` leaves a face out (open box).
std::string cube_obj(const std::string& name, float x0, std::vector<int> flip, int drop, int first_vertex) {
  std::string t = "o " + name + "\n";
  for (int i = 0; i < 8; ++i)
    t += "v " + std::to_string(x0 + float(i & 1)) + " " + std::to_string((i >> 1) & 1) + " " + std::to_string((i >> 2) & 1) + "\n";
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (int f = 0; f < 6; ++f) {
    if (f == drop) continue;
    int q[4] = {faces[f][0], faces[f][1], faces[f][2], faces[f][3]};
    if (std::find(flip.begin(), flip.end(), f) != flip.end()) std::swap(q[1], q[3]);
    t += "f";
    for (int k : q) t += " " + std::to_string(first_vertex + k);
    t += "\n";
  }
  return t;
}

// A closed collider whose faces point inwards pushes the cloth into it: a warning naming the
// file, line, object and volume, saying how to fix it; also for faces pointing both ways.
// Open meshes (a floor, an open box) have no inside: no warning; nor has the cloth.
TEST(Bake, InwardOrInconsistentClosedCollidersAreWarned) {
  const auto dir = scratch("bake_collider_orientation");
  const std::string cloth = "o Cloth\nv 0 3 0\nv 1 3 0\nv 0 3 1\nf 1 3 2\n";
  const std::vector<int> all = {0, 1, 2, 3, 4, 5};
  write_file(dir / "m.obj", cloth + cube_obj("Good", 0, {}, -1, 4) + cube_obj("Inside Out", 2, all, -1, 12) +
                                cube_obj("Mixed", 4, {3}, -1, 20) + cube_obj("OpenBox", 6, all, 1, 28) +
                                "o Floor\nv -9 0 -9\nv 9 0 -9\nv 9 0 9\nf 36 37 38\n");
  const auto s = convert(opts((dir / "m.obj").string(), {"Cloth"}));
  std::string all_warnings;
  for (const auto& w : s.warnings) all_warnings += w + "\n";
  ASSERT_EQ(s.warnings.size(), 2u) << all_warnings;
  EXPECT_NE(s.warnings[0].find("m.obj:21: collider 'Inside Out': closed mesh with negative volume (-1 m^3): its faces "
                               "point inwards, so the cloth is pushed into it; fix it in Blender: Edit Mode, select "
                               "all, Mesh > Normals > Recalculate Outside"),
            std::string::npos)
      << all_warnings;
  EXPECT_NE(s.warnings[1].find("m.obj:36: collider 'Mixed': closed mesh with inconsistently oriented faces (4 edges "
                               "used twice in the same direction)"),
            std::string::npos)
      << all_warnings;
  EXPECT_NE(s.warnings[1].find("Recalculate Outside"), std::string::npos);
  // the cube as the cloth: no collider, no warning
  const auto c = convert(opts((dir / "m.obj").string(), {"Cloth", "Inside Out", "Mixed"}));
  EXPECT_EQ(c.warnings.size(), 0u);
}

// Blender writes object names with spaces as they are (`o My Cloth`); assimp alone keeps an
// `o` name up to its first space, so "My Cloth" and "My Cloth_pins" would both become "My" and
// the pins would go nowhere. Names are kept as the file writes them.
TEST(Bake, ObjectNamesWithSpacesAreKeptWhole) {
  const auto dir = scratch("bake_space_names");
  write_file(dir / "m.obj",
             "# Blender 4.1.1\n"
             "o My Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n"
             "o My Cloth_pins\nv 0 1 0\nv 1 1 0\n"
             "o My  Box # a comment\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 7 8 9\n"
             "o My_Cloth\nv 0 0 2\nv 1 0 2\nv 0 1 2\nf 10 11 12\n"
             "g 100% wool\t \nv 0 0 3\nv 1 0 3\nv 0 1 3\nf 13 14 15\n"
             "o Tag#1\r\nv 0 0 4\nv 1 0 4\nv 0 1 4\nf 16 17 18\n");
  const auto s = convert(opts((dir / "m.obj").string(), {"My Cloth"}));
  ASSERT_EQ(s.objects.size(), 5u);  // the helper is not an object
  EXPECT_EQ(s.objects[0].name, "My Cloth");
  EXPECT_EQ(s.objects[1].name, "My  Box");  // as written, the comment left out
  EXPECT_EQ(s.objects[2].name, "My_Cloth");
  EXPECT_EQ(s.objects[3].name, "100% wool");
  EXPECT_EQ(s.objects[4].name, "Tag#1");  // '#' inside a name is no comment
  // identifiers: cleaned, and distinct in file order ("My Cloth" and "My_Cloth" clean alike)
  EXPECT_EQ(s.objects[0].identifier, "My_Cloth");
  EXPECT_EQ(s.objects[1].identifier, "My_Box");
  EXPECT_EQ(s.objects[2].identifier, "My_Cloth_2");
  EXPECT_EQ(s.objects[3].identifier, "o100_wool");
  ASSERT_EQ(s.cloths.size(), 1u);
  EXPECT_EQ(s.cloths[0].object, 0u);
  EXPECT_EQ(s.cloths[0].mass_count(), 4u);
  ASSERT_EQ(s.cloths[0].pins.size(), 2u);  // "My Cloth_pins" pins "My Cloth"
  // the comment cut from a name is said (Blender allows "Flag #1"; it would lose its pins)
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("m.obj:11: object name read as 'My  Box': '# a comment' is a comment in OBJ"),
            std::string::npos)
      << s.warnings[0];
  // the identifier selects the other one
  const auto t = convert(opts((dir / "m.obj").string(), {"My_Cloth_2"}));
  ASSERT_EQ(t.cloths.size(), 1u);
  EXPECT_EQ(t.cloths[0].object, 2u);
}

}  // namespace

// Every message quotes input through quote_input: short text whole, long text clipped to 60
// bytes + "..." without splitting a UTF-8 character.
TEST(Messages, QuoteInputClipsLongTextOnACharacterBoundary) {
  EXPECT_EQ(b2o::conv::quote_input("Cloth"), "'Cloth'");
  EXPECT_EQ(b2o::conv::quote_input(std::string(60, 'a')), "'" + std::string(60, 'a') + "'");
  EXPECT_EQ(b2o::conv::quote_input(std::string(61, 'a')), "'" + std::string(60, 'a') + "...'");
  // 59 ASCII bytes, then a 2-byte character across the 60-byte limit: cut before it
  const std::string text = std::string(59, 'a') + "\xC3\xA9" + std::string(1000, 'b');
  EXPECT_EQ(b2o::conv::quote_input(text), "'" + std::string(59, 'a') + "...'");
  EXPECT_EQ(b2o::conv::quote_input(std::string(1 << 20, 'x')).size(), 65u);
}

// `CLOTH My Flag` unquoted in CMake passes `-a My`: the error names the object it was cut from
// and says to quote it.
TEST(Bake, AClothNameCutAtItsSpaceIsNamedInTheError) {
  const auto dir = scratch("bake_unquoted");
  write_file(dir / "flag.obj", "o My Flag\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_input_error([&] { convert(opts((dir / "flag.obj").string(), {"My"})); },
                     "no object 'My' to give masses (-a) (did you mean 'My Flag'? a name with spaces must be quoted: "
                     "-a \"My Flag\", CLOTH \"My Flag\")");
}
