// import: geometry, objects, materials and textures as assimp reads them.
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "support.hpp"

namespace {

using namespace b2o::test;
using b2o::conv::import_scene;

TEST(Import, GridObjectsMaterialsAndTexture) {
  const auto s = import_scene(fixture("grid.obj"), false);
  ASSERT_EQ(s.objects.size(), 2u);  // Cloth_pins is a helper, not an object
  EXPECT_EQ(s.objects[0].name, "Cloth");
  EXPECT_EQ(s.objects[1].name, "Floor");
  EXPECT_EQ(s.objects[0].vertex_count, 9u);   // welded per (position, uv, normal)
  EXPECT_EQ(s.objects[0].index_count, 24u);   // 4 quads -> 8 triangles
  EXPECT_EQ(s.objects[1].index_count, 6u);
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].name, "Checker");
  EXPECT_EQ(s.materials[0].shininess, 250.0f);
  EXPECT_EQ(s.materials[0].diffuse[1], 0.7f);
  EXPECT_EQ(s.materials[1].opacity, 0.5f);
  EXPECT_EQ(s.materials[1].diffuse_texture, -1);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.materials[0].diffuse_texture, 0);
  EXPECT_EQ(s.textures[0].name, "checker.png");
  const std::string png = read_file(fixture("checker.png"));
  EXPECT_EQ(std::string(s.textures[0].bytes.begin(), s.textures[0].bytes.end()), png);
  ASSERT_EQ(s.submeshes.size(), 2u);
  EXPECT_EQ(s.submeshes[1].material, 1);
  // the pin helper's loose vertices were read from the text
  ASSERT_EQ(s.pin_points.count("Cloth_pins"), 1u);
  EXPECT_EQ(s.pin_points.at("Cloth_pins").size(), 6u);
  for (std::uint32_t i : s.indices) EXPECT_LT(i, s.positions.size() / 3);
}

TEST(Import, NgonsNegativeIndicesGroupsAndCrlf) {
  const auto s = import_scene(fixture("ngons_crlf.obj"), false);
  ASSERT_EQ(s.objects.size(), 3u);
  EXPECT_EQ(s.objects[0].name, "Penta Gon");  // no '\r' left from CRLF
  EXPECT_EQ(s.objects[1].name, "class");
  EXPECT_EQ(s.objects[2].name, "Penta-Gon");
  EXPECT_EQ(s.objects[0].index_count, 9u);  // pentagon (negative indices) -> 3 triangles
  EXPECT_EQ(s.objects[1].index_count, 6u);
  EXPECT_EQ(s.objects[2].index_count, 3u);
  for (const auto& o : s.objects) EXPECT_EQ(o.name.find('\r'), std::string::npos);
  // no vt: zeros; no vn: generated unit normals (the faces lie in z = const planes)
  for (float t : s.texcoords) EXPECT_EQ(t, 0.0f);
  for (std::size_t v = 0; v < s.normals.size() / 3; ++v) {
    EXPECT_FLOAT_EQ(std::fabs(s.normals[3 * v + 2]), 1.0f) << "vertex " << v;
  }
}

TEST(Import, MissingMtlIsAnErrorAtItsLine) {
  try {
    (void)import_scene(fixture("plain.obj"), false);
    FAIL() << "a missing .mtl was accepted";
  } catch (const b2o::conv::InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(fixture("plain.obj").string() + ":1: material library 'missing.mtl' not found", 0), 0u) << msg;
    EXPECT_NE(msg.find((fixture("plain.obj").parent_path() / "missing.mtl").string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("--allow-missing"), std::string::npos) << msg;
  }
}

TEST(Import, MissingTextureIsAnErrorAtItsMtlLine) {
  try {
    (void)import_scene(fixture("missing_tex.obj"), false);
    FAIL() << "a missing texture was accepted";
  } catch (const b2o::conv::InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(fixture("missing_tex.mtl").string() + ":3: texture 'no_such_image.png' of material 'Painted' not found", 0), 0u) << msg;
    EXPECT_NE(msg.find((fixture("missing_tex.obj").parent_path() / "no_such_image.png").string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("missing_tex.obj"), std::string::npos) << msg;
  }
}

TEST(Import, NoObjectLinesNamedAfterFileAndAllowedMissingMtlWarns) {
  const auto s = import_scene(fixture("plain.obj"), false, /*allow_missing=*/true);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "plain");
  ASSERT_EQ(s.materials.size(), 1u);  // assimp's default material
  bool warned = false;
  for (const auto& w : s.warnings) warned |= w.find("missing.mtl") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(Import, AllowedMissingTextureWarnsAndGivesNoTexture) {
  const auto s = import_scene(fixture("missing_tex.obj"), false, /*allow_missing=*/true);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].diffuse_texture, -1);
  EXPECT_TRUE(s.textures.empty());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("no_such_image.png"), std::string::npos);
}

TEST(Import, MergeMakesOneObject) {
  const auto s = import_scene(fixture("ngons_crlf.obj"), true);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].index_count, 18u);
  EXPECT_EQ(s.objects[0].submesh_count, static_cast<std::uint32_t>(s.submeshes.size()));
}

// Floats are carried bit for bit from what assimp reads: every face corner assimp reports
// is, bit for bit, the vertex the converter's index points at (the exact join drops only
// bit-identical duplicates).
TEST(Import, EveryCornerBitExactToAssimp) {
  for (const char* name : {"grid.obj", "ngons_crlf.obj", "odd_names.obj", "plain.obj"}) {
    const auto s = import_scene(fixture(name), false, /*allow_missing=*/true);  // plain.obj's .mtl is missing
    Assimp::Importer imp;
    const aiScene* ai = b2o::conv::read_with_assimp(imp, fixture(name).string());
    ASSERT_NE(ai, nullptr);
    std::size_t k = 0;  // running index into s.indices
    std::function<void(const aiNode*)> walk = [&](const aiNode* n) {
      if (std::string(n->mName.C_Str()).find("_pins") == std::string::npos)
        for (unsigned m = 0; m < n->mNumMeshes; ++m) {
          const aiMesh* mesh = ai->mMeshes[n->mMeshes[m]];
          for (unsigned f = 0; f < mesh->mNumFaces; ++f)
            for (unsigned c = 0; c < 3; ++c, ++k) {
              ASSERT_LT(k, s.indices.size());
              const unsigned v = mesh->mFaces[f].mIndices[c];
              const std::uint32_t mine = s.indices[k];
              const bool uv = mesh->HasTextureCoords(0);
              const float want[8] = {mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z,
                                     mesh->mNormals[v].x,  mesh->mNormals[v].y,  mesh->mNormals[v].z,
                                     uv ? mesh->mTextureCoords[0][v].x : 0.0f, uv ? mesh->mTextureCoords[0][v].y : 0.0f};
              EXPECT_EQ(std::memcmp(want, &s.positions[3 * mine], 12), 0) << name << " corner " << k;
              EXPECT_EQ(std::memcmp(want + 3, &s.normals[3 * mine], 12), 0) << name << " corner " << k;
              EXPECT_EQ(std::memcmp(want + 6, &s.texcoords[2 * mine], 8), 0) << name << " corner " << k;
            }
        }
      for (unsigned i = 0; i < n->mNumChildren; ++i) walk(n->mChildren[i]);
    };
    walk(ai->mRootNode);
    EXPECT_EQ(k, s.indices.size()) << name;
    // joined: no two vertices are bit-identical in all attributes within an object
    for (const auto& o : s.objects) {
      std::set<std::vector<float>> seen;
      for (std::uint32_t v = o.first_vertex; v < o.first_vertex + o.vertex_count; ++v)
        seen.insert({s.positions[3 * v], s.positions[3 * v + 1], s.positions[3 * v + 2], s.normals[3 * v],
                     s.normals[3 * v + 1], s.normals[3 * v + 2], s.texcoords[2 * v], s.texcoords[2 * v + 1]});
      EXPECT_EQ(seen.size(), o.vertex_count) << name << " " << o.name;
    }
  }
}

// The L of the report (its reflex corner on a diagonal): assimp's own triangulation makes 4
// triangles of area 4, two facing down; the converter's covers the L once, facing up.
TEST(Import, ConcaveLFaceIsTriangulatedCorrectly) {
  const auto s = import_scene(fixture("lshape.obj"), false);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  ASSERT_EQ(s.objects.size(), 1u);
  ASSERT_EQ(s.indices.size(), 3u * 4u);
  double area = 0.0;
  for (std::size_t t = 0; t < s.indices.size(); t += 3) {
    const float* a = &s.positions[3 * s.indices[t]];
    const float* b = &s.positions[3 * s.indices[t + 1]];
    const float* c = &s.positions[3 * s.indices[t + 2]];
    // (b - a) x (c - a), y component: all in the y = 0 plane
    const double up = (double(c[0]) - a[0]) * (double(b[2]) - a[2]) - (double(b[0]) - a[0]) * (double(c[2]) - a[2]);
    EXPECT_GT(up, 0.0) << "triangle " << t / 3 << " faces down or has no area";
    area += 0.5 * std::fabs(up);
  }
  EXPECT_DOUBLE_EQ(area, 3.0);
  for (std::size_t v = 0; v < s.normals.size(); v += 3) EXPECT_EQ(s.normals[v + 1], 1.0f) << "normal " << v / 3;
}

// A self-intersecting face gets triangles for all its corners (a fan) and one warning per
// object, naming the file and the object.
TEST(Import, BowTieFacesWarnOncePerObject) {
  const auto s = import_scene(fixture("bowtie.obj"), false);
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.objects[0].index_count, 3u * (4u + 3u));
  EXPECT_EQ(s.objects[1].index_count, 6u);
  // (the fans' triangles without area also leave normals to compute: another warning)
  std::vector<std::string> fans;
  for (const std::string& w : s.warnings)
    if (w.find("simple polygon") != std::string::npos) fans.push_back(w);
  ASSERT_EQ(fans.size(), 1u);
  const std::string& w = fans[0];
  EXPECT_EQ(w.rfind(fixture("bowtie.obj").string() + ": ", 0), 0u) << w;
  EXPECT_NE(w.find("object 'Bowtie'"), std::string::npos) << w;
  EXPECT_NE(w.find("2 faces are not simple polygons"), std::string::npos) << w;
  EXPECT_EQ(w.find("Square"), std::string::npos) << w;
}

// Convex polygons, quads (convex and concave) and triangles: face for face and corner for
// corner what assimp's own aiProcess_Triangulate gives (with its NGON encoding's rotations),
// so the converter's output for them is assimp's.
TEST(Import, ConvexPolygonsAsAssimp) {
  Assimp::Importer mine, theirs;
  const std::string file = fixture("convex_ngons.obj").string();
  const aiScene* a = b2o::conv::read_with_assimp(mine, file);
  theirs.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* b = theirs.ReadFile(file, aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_SortByPType |
                                               aiProcess_ValidateDataStructure);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  ASSERT_EQ(a->mNumMeshes, b->mNumMeshes);
  std::size_t faces = 0;
  for (unsigned m = 0; m < a->mNumMeshes; ++m) {
    const aiMesh& x = *a->mMeshes[m];
    const aiMesh& y = *b->mMeshes[m];
    EXPECT_EQ(x.mPrimitiveTypes, y.mPrimitiveTypes);
    ASSERT_EQ(x.mNumVertices, y.mNumVertices);
    EXPECT_EQ(std::memcmp(x.mNormals, y.mNormals, sizeof(aiVector3D) * x.mNumVertices), 0);
    ASSERT_EQ(x.mNumFaces, y.mNumFaces);
    for (unsigned f = 0; f < x.mNumFaces; ++f, ++faces) {
      ASSERT_EQ(x.mFaces[f].mNumIndices, 3u);
      ASSERT_EQ(y.mFaces[f].mNumIndices, 3u);
      for (unsigned c = 0; c < 3; ++c) EXPECT_EQ(x.mFaces[f].mIndices[c], y.mFaces[f].mIndices[c]) << "face " << f;
    }
  }
  EXPECT_EQ(faces, 182u);
}

TEST(Identifiers, OddNamesGiveValidDistinctStableIdentifiers) {
  auto s = import_scene(fixture("odd_names.obj"), false);
  b2o::conv::assign_identifiers(s);
  ASSERT_EQ(s.objects.size(), 6u);
  EXPECT_EQ(s.objects[0].name, "Tischdecke_\xC3\xBC\xC3\xA9");  // kept as written (UTF-8)
  EXPECT_EQ(s.objects[1].name, "say\"hi\"\\there?");
  std::set<std::string> seen;
  for (const auto& o : s.objects) {
    const std::string& id = o.identifier;
    ASSERT_FALSE(id.empty());
    EXPECT_FALSE(id[0] >= '0' && id[0] <= '9') << id;
    EXPECT_NE(id[0], '_') << id;
    EXPECT_EQ(id.find("__"), std::string::npos) << id;
    for (char c : id) EXPECT_TRUE(std::isalnum(static_cast<unsigned char>(c)) || c == '_') << id;
    EXPECT_TRUE(seen.insert(id).second) << "duplicate " << id;
  }
  EXPECT_EQ(s.objects[2].identifier, "o3D_Cube");
  EXPECT_EQ(s.objects[3].identifier, "int_");
  EXPECT_EQ(s.objects[4].identifier, "My_Object");
  EXPECT_EQ(s.objects[5].identifier, "My_Object_2");  // collision once cleaned: file order decides
  EXPECT_EQ(b2o::conv::clean_identifier("class"), "class_");
  // macros in GCC's GNU dialects (CMake's default, and the scene's .S)
  EXPECT_EQ(b2o::conv::clean_identifier("linux"), "linux_");
  EXPECT_EQ(b2o::conv::clean_identifier("unix"), "unix_");
  // <cstdint>'s object-like macros; its function-like ones and look-alikes stay
  for (const char* m : {"SIZE_MAX", "INT32_MAX", "UINT64_MAX", "INT8_MIN", "INT_LEAST16_MIN", "UINT_FAST32_MAX",
                        "INTPTR_MIN", "UINTPTR_MAX", "INTMAX_MAX", "PTRDIFF_WIDTH", "SIG_ATOMIC_MIN", "WCHAR_MAX",
                        "WINT_MIN", "INT64_WIDTH"})
    EXPECT_EQ(b2o::conv::clean_identifier(m), std::string(m) + "_") << m;
  for (const char* m : {"INT8_C", "UINT64_C", "MAX", "SIZE", "MY_MAX", "INT_MAX_x", "INT128_MAX", "UINT_LEAST_MAX"})
    EXPECT_EQ(b2o::conv::clean_identifier(m), m) << m;
  EXPECT_EQ(b2o::conv::clean_identifier("__x__y"), "x_y");
  EXPECT_EQ(b2o::conv::clean_identifier("\xC3\xBC"), "unnamed");
}


TEST(Import, TextureNextToAMtlInASubfolder) {
  const auto dir = scratch("import_subfolder");
  write_file(dir / "m.obj", "mtllib looks/m.mtl\no Sheet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl P\nf 1 2 3\n");
  write_file(dir / "looks" / "m.mtl", "newmtl P\nKd 1 1 1\nmap_Kd tex.png\n");
  const std::string png = read_file(fixture("checker.png"));
  write_file(dir / "looks" / "tex.png", png);
  const auto s = b2o::conv::import_scene(dir / "m.obj", false);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(std::string(s.textures[0].bytes.begin(), s.textures[0].bytes.end()), png);  // the file's bytes
  EXPECT_EQ(s.materials[0].diffuse_texture, 0);
  EXPECT_TRUE(s.warnings.empty());
}

// A texture the viewer could not decode (no image, a truncated PNG, a format stb does not
// read) stops the bake naming the file; with --allow-missing the material has no texture
// and a warning says why.
TEST(Import, UndecodableTextureIsAnErrorOrWithAllowMissingAWarning) {
  const auto dir = scratch("import_bad_texture");
  write_file(dir / "m.obj", "mtllib m.mtl\no Sheet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl P\nf 1 2 3\n");
  write_file(dir / "m.mtl", "newmtl P\nKd 1 1 1\nmap_Kd tex.png\n");
  const std::string png = read_file(fixture("checker.png"));
  for (const std::string& bytes : {std::string("not an image"), png.substr(0, png.size() / 2),
                                   std::string("II*\0\x08\0\0\0", 8) /* a TIFF header */}) {
    write_file(dir / "tex.png", bytes);
    try {
      (void)b2o::conv::import_scene(dir / "m.obj", false);
      ADD_FAILURE() << "no error for " << bytes.size() << " bytes";
    } catch (const b2o::conv::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("m.mtl:3: texture 'tex.png' of material 'P' ("), std::string::npos) << what;
      EXPECT_NE(what.find("--allow-missing"), std::string::npos) << what;
      EXPECT_NE(what.find(") cannot be decoded"), std::string::npos) << what;
    }
    const auto s = b2o::conv::import_scene(dir / "m.obj", false, /*allow_missing=*/true);
    EXPECT_TRUE(s.textures.empty());
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].diffuse_texture, -1);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("the material gets no texture"), std::string::npos) << s.warnings[0];
  }
}


// Freeform curves and surfaces (Blender's "Curves as NURBS") have nothing to draw: their
// statements are left out with one warning at the first one's line, and the faces around them
// are all read (assimp loses a face after `cstype` and fails on `curv` without a line).
TEST(Import, FreeformStatementsAreIgnoredWithOneWarning) {
  const auto dir = scratch("import_freeform");
  write_file(dir / "m.obj",
             "o Cloth\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3\n"
             "cstype bspline\ndeg 3\ncurv 0 1 1 2 \\\n  3 4\nparm u 0 0 0 0 1 1 1 1\nend\nf 1 3 4\n");
  const auto s = b2o::conv::import_scene(dir / "m.obj", false);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].index_count, 6u);  // both faces
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("m.obj:7: 5 freeform curve/surface statements"), std::string::npos) << s.warnings[0];
}

// Faces assimp would misread or refuse without a line: a '+' index (read as a 4th corner) and
// more than 32767 corners.
TEST(Import, PlusIndexAndHugeFaceAreRefusedAtTheirLine) {
  const auto dir = scratch("import_face_limits");
  write_file(dir / "plus.obj", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 +3\n");
  write_file(dir / "slash.obj", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf /1 2 3\n");  // an empty index field
  std::string big = "o Cloth\n", face = "f";
  for (int k = 0; k < 32768; ++k) {
    const double a = 6.283185307179586 * k / 32768.0;
    big += "v " + std::to_string(std::cos(a)) + " 0 " + std::to_string(std::sin(a)) + "\n";
    face += " " + std::to_string(k + 1);
  }
  write_file(dir / "big.obj", big + face + "\n");
  const std::pair<const char*, const char*> cases[] = {{"plus.obj", "plus.obj:5: malformed vertex reference '+3'"},
                                                       {"slash.obj", "slash.obj:5: malformed vertex reference '/1'"},
                                                       {"big.obj", "big.obj:32770: a face with 32768 corners (at most 32767)"}};
  for (const auto& [name, want] : cases) {
    try {
      (void)b2o::conv::import_scene(dir / name, false);
      ADD_FAILURE() << name << ": no error";
    } catch (const b2o::conv::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
  }
}

// A UTF-8 byte-order mark at the start of the .obj or the .mtl is no part of the first
// statement: `o Cloth` keeps its name, `mtllib` its materials, `newmtl` its material
// (assimp is given the text without it).
TEST(Import, Utf8ByteOrderMarkInObjAndMtl) {
  const auto dir = scratch("import_bom");
  write_file(dir / "a.obj", "\xEF\xBB\xBFo Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  auto s = b2o::conv::import_scene(dir / "a.obj", false, true);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "Cloth");
  write_file(dir / "sub" / "b.obj", "\xEF\xBB\xBFmtllib b.mtl\no Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl Red\nf 1 2 3\n");
  write_file(dir / "sub" / "b.mtl", "\xEF\xBB\xBFnewmtl Red\nKd 1 0.5 0\n");
  s = b2o::conv::import_scene(dir / "sub" / "b.obj", false, false);
  EXPECT_TRUE(s.warnings.empty());
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].name, "Red");
  EXPECT_EQ(s.materials[0].diffuse[1], 0.5f);
  ASSERT_EQ(s.submeshes.size(), 1u);
  EXPECT_EQ(s.submeshes[0].material, 0);
}


// What Blender and other tools write that assimp 5.2.5 misreads: a number starting with '.',
// an mtllib line with trailing spaces or a comment, map_Kd options with fewer than 3 numbers
// or unknown to assimp, Blender 4's PBR keys.
TEST(Import, ExportsAssimpMisreadAreReadAsWritten) {
  const auto dir = scratch("import_misread");
  // '.5' is no number to assimp: it skips the vertex line and the indices shift
  // ('lod', a display attribute, it takes for a line element and fails without a line)
  write_file(dir / "dot.obj", "o A\nv 0 .5 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\nvt 0 .25\nlod 1\nf 1/1 2/1 3/1\n");
  auto s = import_scene(dir / "dot.obj", false);
  ASSERT_EQ(s.positions.size(), 9u);
  EXPECT_EQ(s.positions[1], 0.5f);  // the first corner is (0, .5, 0)
  EXPECT_EQ(s.positions[3], 1.0f);
  ASSERT_GE(s.texcoords.size(), 2u);
  EXPECT_EQ(s.texcoords[1], 0.25f);

  const std::string png = read_file(fixture("checker.png"));
  write_file(dir / "tex.png", png);
  write_file(dir / "m.mtl",
             "newmtl Red\nKd 1 0 0\nPr 0.5\nPm 0.0\nPcr 0.03\naniso 0.000000\nanisor 0.000000\n"
             "map_Kd -s 2 2 -type sphere -cc on tex.png  \n");
  for (const char* mtllib : {"mtllib m.mtl # the library\n", "mtllib m.mtl  \t\n"}) {
    write_file(dir / "lib.obj", std::string(mtllib) + "o A\nv 0 0 0\nv 1 0 0\nv 0 0 1\nusemtl Red\nf 1 2 3\n");
    s = import_scene(dir / "lib.obj", false);
    ASSERT_EQ(s.materials.size(), 1u) << mtllib;
    EXPECT_EQ(s.materials[0].diffuse[0], 1.0f) << mtllib;  // not assimp's default grey
    EXPECT_EQ(s.materials[0].diffuse[1], 0.0f) << mtllib;
    ASSERT_EQ(s.textures.size(), 1u) << mtllib;
    EXPECT_EQ(s.textures[0].name, "tex.png");
    EXPECT_EQ(s.materials[0].diffuse_texture, 0);
    // the scale is not drawn: said, at its line
    ASSERT_EQ(s.warnings.size(), 1u) << mtllib;
    EXPECT_NE(s.warnings[0].find("m.mtl:8: the texture's scale, offset or turbulence (-s, -o, -t) are not drawn"),
              std::string::npos)
        << s.warnings[0];
  }
  // an option nobody knows is refused at its line; a missing texture named at its line
  // whatever the case of map_Kd
  write_file(dir / "m.mtl", "newmtl Red\nKd 1 0 0\nmap_Kd -zoom 2 tex.png\n");
  expect_input_error([&] { import_scene(dir / "lib.obj", false); }, "m.mtl:3: unknown map_Kd option '-zoom'");
  write_file(dir / "m.mtl", "newmtl Red\nKd 1 0 0\nmap_kd lost.png\n");
  expect_input_error([&] { import_scene(dir / "lib.obj", false); }, "m.mtl:3: texture 'lost.png' of material 'Red' not found");
}

// What the pre-scan's rules for these must not break: lowercase kd / ns (assimp
// reads K and N in either case), a library named like a piece of the word "mtllib", a texture
// file name that starts with '-', Blender's Material Groups (faces under another name than
// their vertices: no "left out" warning), and a library under a symbolic link whose texture
// path goes up through it.
TEST(Import, WhatTheMisreadFixesKeep) {
  const auto dir = scratch("import_keep");
  const std::string png = read_file(fixture("checker.png"));
  write_file(dir / "lib", "newmtl Red\nkd 1 0 0\nns 50\nmap_Kd -tex.png\n");
  write_file(dir / "-tex.png", png);
  write_file(dir / "m.obj", "mtllib lib\no Cube\nv 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\n"
                            "g Cube_Cube_Material\nusemtl Red\nf 1 2 3\nf 2 4 3\n");
  auto s = import_scene(dir / "m.obj", false);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].diffuse[0], 1.0f);
  EXPECT_EQ(s.materials[0].diffuse[1], 0.0f);
  EXPECT_EQ(s.materials[0].shininess, 50.0f);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].name, "./-tex.png");
  // model/link -> ../shared/mats; the .mtl there names ../tex/b.png, next to the real folder
  const auto root = scratch("import_symlink");
  write_file(root / "shared" / "mats" / "s.mtl", "newmtl B\nKd 1 1 1\nmap_Kd ../tex/b.png\n");
  write_file(root / "shared" / "tex" / "b.png", png);
  std::filesystem::create_directories(root / "model");
  std::filesystem::create_directory_symlink("../shared/mats", root / "model" / "link");
  write_file(root / "model" / "m.obj", "mtllib link/s.mtl\no A\nv 0 0 0\nv 1 0 0\nv 0 0 1\nusemtl B\nf 1 2 3\n");
  s = import_scene(root / "model" / "m.obj", false);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].name, "link/../tex/b.png");
  EXPECT_EQ(s.textures[0].bytes.size(), png.size());
}

// A comment ending in '\' (a Windows folder) does not take the next face into the comment,
// for assimp either; Blender's legacy `usemtl (null)` before every object warns once.
TEST(Import, CommentBackslashAndRepeatedUndefinedMaterial) {
  const auto dir = scratch("import_comment_null");
  write_file(dir / "m.obj", "o A\nv 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\nusemtl (null)\n"
                            "# exported from C:\\models\\\nf 1 2 3\no B\nusemtl (null)\nf 2 4 3\n");
  const auto s = import_scene(dir / "m.obj", false);
  EXPECT_EQ(s.indices.size(), 6u);  // both faces
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("m.obj:6: material '(null)' used but no 'mtllib' is given"), std::string::npos)
      << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("(used 2 times)"), std::string::npos) << s.warnings[0];
}

// Two libraries in two folders naming a texture of the same name: each material gets the
// one next to its .mtl (not both the first folder's).
TEST(Import, TexturesAreRelativeToTheirOwnMtl) {
  const auto dir = scratch("import_two_libs");
  write_file(dir / "m.obj", "mtllib a/m.mtl\nmtllib b/n.mtl\no A\nv 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\n"
                            "usemtl MA\nf 1 2 3\nusemtl MB\nf 2 4 3\n");
  write_file(dir / "a" / "m.mtl", "newmtl MA\nKd 1 1 1\nmap_Kd tex.png\n");
  write_file(dir / "b" / "n.mtl", "newmtl MB\nKd 1 1 1\nmap_Kd tex.png\n");
  const std::string png = read_file(fixture("checker.png"));
  write_file(dir / "a" / "tex.png", png);
  write_file(dir / "b" / "tex.png", png + "more");  // (stb reads a PNG with bytes after its end)
  const auto s = import_scene(dir / "m.obj", false);
  ASSERT_EQ(s.textures.size(), 2u);
  EXPECT_EQ(s.textures[0].name, "a/tex.png");
  EXPECT_EQ(s.textures[1].name, "b/tex.png");
  EXPECT_EQ(s.textures[1].bytes.size(), png.size() + 4);
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].diffuse_texture, 0);
  EXPECT_EQ(s.materials[1].diffuse_texture, 1);
}

// Objects assimp drops or names otherwise are said: an object of loose vertices that is no
// pin helper (Blender's legacy exporter names a helper 'Cloth_pins_Plane.001'), and a name
// cut at ' #' (Blender allows "Flag #1").
TEST(Import, DroppedAndCutObjectsAreWarned) {
  const auto dir = scratch("import_dropped");
  write_file(dir / "m.obj", "o Cloth_Plane\nv 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n"
                            "o Cloth_pins_Plane.001\nv 0 0 0\nv 1 0 0\n"
                            "o Flag #1\nv 0 1 0\nv 1 1 0\nv 0 1 1\nf 6 7 8\n");
  const auto s = import_scene(dir / "m.obj", false);
  ASSERT_EQ(s.warnings.size(), 2u);
  const std::string all = s.warnings[0] + "\n" + s.warnings[1];
  EXPECT_NE(all.find("m.obj:6: object 'Cloth_pins_Plane.001' has 2 vertices and no face uses them: left out"),
            std::string::npos) << all;
  EXPECT_NE(all.find("a pin helper is found by the exact name '<cloth>_pins'"), std::string::npos) << all;
  EXPECT_NE(all.find("m.obj:9: object name read as 'Flag': '#1' is a comment in OBJ"), std::string::npos) << all;
}

// A loose vertex in an object that has faces (the 2016 skirt's 353rd) is said; a texture
// offset (Blender writes `-o` for a Mapping node) is warned and a neutral scale is not;
// `mtllib a.mtl b.mtl` reads both libraries.
TEST(Import, LooseVerticesOffsetsAndSeveralLibrariesOnALine) {
  const auto dir = scratch("import_loose_offsets");
  write_file(dir / "loose.obj", "o Cone\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 0.5\nf 1 2 3 4\n"
                                "o Whole\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 6 7 8\n");
  auto s = import_scene(dir / "loose.obj", false);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("loose.obj:1: object 'Cone': 1 of its 5 vertices is in no face (the first: vertex 5)"),
            std::string::npos) << s.warnings[0];
  // the same without any object name (the file is the object)
  write_file(dir / "plain.obj", "# a comment\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nv 6 6 6\nf 1 2 3\n");
  s = import_scene(dir / "plain.obj", false);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("plain.obj:2: 2 of the 5 vertices before any object name are in no face (the first: "
                               "vertex 4)"), std::string::npos) << s.warnings[0];

  write_file(dir / "tex.png", read_file(fixture("checker.png")));
  write_file(dir / "b.mtl", "newmtl Blue\nKd 0 0 1\n");
  write_file(dir / "m.obj", "mtllib a.mtl b.mtl\no A\nv 0 0 0\nv 1 0 0\nv 0 0 1\nvt 0 0\nusemtl Red\nf 1/1 2/1 3/1\n"
                            "o B\nv 0 1 0\nv 1 1 0\nv 0 1 1\nusemtl Blue\nf 4 5 6\n");
  for (const char* options : {"-o 0.5 0.5 0 ", "-o 0.25 ", "-t 0.1 0.1 0 ", "-s 2 2 1 ", "-s 1 1 1 ", "-s 1.000000 ",
                              "-o 0 0 0 -s 1 1 1 ", ""}) {
    write_file(dir / "a.mtl", std::string("newmtl Red\nKd 1 0 0\nmap_Kd ") + options + "tex.png\n");
    s = import_scene(dir / "m.obj", false);
    const std::string o = options;
    const bool neutral = o.empty() || o == "-s 1 1 1 " || o == "-s 1.000000 " || o == "-o 0 0 0 -s 1 1 1 ";
    EXPECT_EQ(s.warnings.size(), neutral ? 0u : 1u) << options;
    if (!neutral && !s.warnings.empty()) {
      EXPECT_NE(s.warnings[0].find("a.mtl:3: the texture's scale, offset or turbulence"), std::string::npos)
          << s.warnings[0];
    }
    ASSERT_EQ(s.materials.size(), 2u) << options;
    EXPECT_EQ(s.materials[0].name, "Red");
    EXPECT_EQ(s.materials[0].diffuse[0], 1.0f);
    EXPECT_EQ(s.materials[0].diffuse_texture, 0);
    EXPECT_EQ(s.materials[1].name, "Blue");
    EXPECT_EQ(s.materials[1].diffuse[2], 1.0f);
    ASSERT_EQ(s.submeshes.size(), 2u);
    EXPECT_NE(s.submeshes[0].material, s.submeshes[1].material);
  }
  // a file whose name has a space is still one library
  write_file(dir / "a b.mtl", "newmtl Red\nKd 0 1 0\n");
  write_file(dir / "one.obj", "mtllib a b.mtl\no A\nv 0 0 0\nv 1 0 0\nv 0 0 1\nusemtl Red\nf 1 2 3\n");
  s = import_scene(dir / "one.obj", false);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].diffuse[1], 1.0f);
  EXPECT_TRUE(s.warnings.empty());
  // a library on two lines, each joining another to it (assimp is served one text per file)
  write_file(dir / "a.mtl", "newmtl Red\nKd 1 0 0\nillum 2\n");
  write_file(dir / "c.mtl", "newmtl Green\nKd 0 1 0\n");
  const std::string three = "o A\nv 0 0 0\nv 1 0 0\nv 0 0 1\nusemtl Red\nf 1 2 3\no B\nv 0 1 0\nv 1 1 0\nv 0 1 1\n"
                            "usemtl Blue\nf 4 5 6\no C\nv 0 2 0\nv 1 2 0\nv 0 2 1\nusemtl Green\nf 7 8 9\n";
  for (const char* lines : {"mtllib a.mtl b.mtl\nmtllib a.mtl c.mtl\n", "mtllib a.mtl\nmtllib a.mtl b.mtl c.mtl\n"}) {
    write_file(dir / "two.obj", lines + three);
    s = import_scene(dir / "two.obj", false);
    ASSERT_EQ(s.materials.size(), 3u) << lines;
    for (const auto& mat : s.materials)  // not assimp's default grey
      EXPECT_EQ(mat.diffuse[mat.name == "Red" ? 0 : mat.name == "Green" ? 1 : 2], 1.0f) << lines << mat.name;
    EXPECT_TRUE(s.warnings.empty()) << lines << s.warnings[0];
  }
  // a missing one of several is named by itself; with --allow-missing the others are read
  fs::remove(dir / "b.mtl");
  expect_input_error([&] { import_scene(dir / "m.obj", false); }, "m.obj:1: material library 'b.mtl' not found");
  s = import_scene(dir / "m.obj", false, true);
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].diffuse[0], 1.0f);  // Red, from a.mtl
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("m.obj:1: material library 'b.mtl' not found"), std::string::npos) << s.warnings[0];
  // a pin helper's vertices are pins, face or not: no loose-vertex warning
  write_file(dir / "pins.obj", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n"
                               "o Cloth_pins\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 5 6 7\n");
  s = import_scene(dir / "pins.obj", false);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

// Faces before the first `o` line, or under a bare `o`, form an object named after the file,
// as a file without `o`/`g` does (assimp names it "defaultobject", so `-a <stem>` would fail); a
// file that names an object "defaultobject" keeps it.
TEST(Import, FacesBeforeTheFirstObjectAreNamedAfterTheFile) {
  const auto dir = scratch("import_default_object");
  const struct {
    const char* file;
    const char* text;
    std::vector<std::string> names;
  } cases[] = {
      {"pre.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no A\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\n", {"pre", "A"}},
      {"bare.obj", "o\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", {"bare"}},
      // an object named like the file would join them: the first keeps assimp's name
      {"pre2.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no pre2\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\n",
       {"defaultobject", "pre2"}},
      {"named.obj", "o defaultobject\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", {"defaultobject"}}};
  for (const auto& c : cases) {
    write_file(dir / c.file, c.text);
    const auto s = import_scene(dir / c.file, false);
    std::vector<std::string> names;
    for (const auto& o : s.objects) names.push_back(o.name);
    EXPECT_EQ(names, c.names) << c.file;
  }
}

// No zero or non-finite normal reaches the scene: a face without `vn` among faces with, a
// `vn 0 0 0`, and a degenerate face get normals from their faces (a warning), (0, 0, 1) when
// the faces have no area.
TEST(Import, MissingZeroAndDegenerateNormalsAreComputed) {
  const auto dir = scratch("import_zero_normals");
  const std::vector<std::string> files = {
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2 4 3\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n",
      "v 0 0 0\nv 0 1 0\nv 1 0 0\nvn 0 0 0\nf 1//1 2//1 3//1\n",  // clockwise: -z
      "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n",
  };
  const float expect_z[] = {1.0f, 1.0f, -1.0f, 1.0f};
  for (std::size_t i = 0; i < files.size(); ++i) {
    write_file(dir / "m.obj", files[i]);
    const auto s = b2o::conv::import_scene(dir / "m.obj", false);
    ASSERT_FALSE(s.normals.empty());
    for (std::size_t v = 0; v < s.normals.size(); v += 3) {
      EXPECT_EQ(s.normals[v], 0.0f) << files[i] << v;
      EXPECT_EQ(s.normals[v + 1], 0.0f) << files[i] << v;
      EXPECT_EQ(s.normals[v + 2], expect_z[i]) << files[i] << v;
    }
    ASSERT_EQ(s.warnings.size(), 1u) << files[i];
    EXPECT_NE(s.warnings[0].find("normals computed from the faces"), std::string::npos) << s.warnings[0];
  }
}

}  // namespace

// Exports that assimp misreads without a word: a face mixing reference forms (its texture
// coordinates go to the wrong corners), indices with leading zeros, and statements assimp
// reads by their first letter. Each is refused at its line.
TEST(Import, MisreadLinesAreRefusedAtTheirLine) {
  const auto dir = scratch("import_misread");
  const char* three = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nvt 0 0\nvt 1 1\nvn 0 0 1\n";
  const struct {
    const char* name;
    std::string text;
    const char* error;
  } cases[] = {
      {"mixed.obj", std::string(three) + "f 1/2 2 3/1\n", "mixed.obj:8: a 'f' statement mixes vertex reference forms ('1/2' and '2')"},
      {"mixed_vn.obj", std::string(three) + "f 1//1 2 3//1\n", "mixes vertex reference forms"},
      {"mixed_all.obj", std::string(three) + "f 1/2/1 2//1 3/1/1\n", "('1/2/1' and '2//1')"},
      {"zero.obj", std::string(three) + "f 01 02 03\n", "zero.obj:8: vertex reference '01' has a leading zero"},
      {"zero_neg.obj", std::string(three) + "f -1 -02 -3\n", "write '-2'"},
      {"fx.obj", std::string(three) + "fx 1 2 3\n", "fx.obj:8: unknown statement 'fx' (assimp would read it as 'f')"},
      {"f1.obj", std::string(three) + "f1 2 3\nf 1 2 3\n", "f1.obj:8: unknown statement 'f1'"},
      {"vtx.obj", std::string(three) + "vtx 1 1\nf 1 2 3\n", "vtx.obj:8: unknown statement 'vtx'"},
      {"ox.obj", std::string(three) + "ox name\nf 1 2 3\n", "ox.obj:8: unknown statement 'ox' (assimp would read it as 'o')"},
      {"msvc.obj", std::string(three) + "v 1.#INF 0 0\nf 1 2 3\n", "msvc.obj:8: non-finite number '1.#INF' (MSVC's"},
      {"msvc_nan.obj", std::string(three) + "vn 0 -1.#IND 0\nf 1 2 3\n", "non-finite number '-1.#IND'"},
  };
  for (const auto& c : cases) {
    write_file(dir / c.name, c.text);
    expect_input_error([&] { import_scene(dir / c.name, false); }, c.error);
  }
  // still read: the same forms throughout, a '\' at the very end (a continuation), '\' before
  // spaces in a comment (cut, as a comment's final '\' is), unknown statements of other letters
  write_file(dir / "ok.obj", std::string(three) + "# C:\\models\\  \nf 1/1 2/2 3/1\nf 2//1 3//1 4//1\n"
                                                  "f 1 2 \\\n4\nshadow_obj x.obj\nvD 1 2\n");
  const auto s = import_scene(dir / "ok.obj", false);
  EXPECT_EQ(s.indices.size(), 9u);
  // an object name ending in '\' before spaces: the name is kept and the next line is not
  // taken into it (assimp given `o foo\` would continue the line: a vertex lost)
  write_file(dir / "bs.obj", "v 0 0 0\nv 1 0 0\no foo\\ \nv 0 1 0\nv 1 1 1\nf 1 2 3\ng bar\\\t\r\nf 2 4 3\n");
  const auto b = import_scene(dir / "bs.obj", false);
  ASSERT_EQ(b.objects.size(), 2u);
  EXPECT_EQ(b.objects[0].name, "foo\\");
  EXPECT_EQ(b.objects[1].name, "bar\\");
  ASSERT_EQ(b.positions.size(), 18u);  // the two objects' three corners each
  EXPECT_EQ(b.positions[7], 1.0f);     // (0 1 0), the one a continued line loses
}

// Faces with no `usemtl` (Blender 4 writes none for an object without materials) get the
// default material (assimp gives them another object's, or the library's first).
// A `g` keeps the material before it, as OBJ reads.
TEST(Import, FacesWithoutAMaterialGetTheDefaultOne) {
  const auto dir = scratch("import_no_usemtl");
  write_file(dir / "ab.mtl", "newmtl A\nKd 1 0 0\nnewmtl B\nKd 0 1 0\n");
  const std::string tri1 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n", tri2 = "v 0 0 1\nv 1 0 1\nv 0 1 1\n";
  const struct {
    const char* name;
    std::string text;
    std::vector<std::string> materials;  // per submesh, in order
  } cases[] = {
      {"first.obj", "mtllib ab.mtl\no Cloth\n" + tri1 + "f 1 2 3\no Floor\n" + tri2 + "usemtl B\nf 4 5 6\n",
       {"DefaultMaterial", "B"}},
      {"last.obj", "mtllib ab.mtl\no Floor\n" + tri2 + "usemtl B\nf 1 2 3\no Cloth\n" + tri1 + "f 4 5 6\n",
       {"B", "DefaultMaterial"}},
      {"none.obj", "mtllib ab.mtl\n" + tri1 + "f 1 2 3\n", {"DefaultMaterial"}},
      {"inside.obj", "mtllib ab.mtl\no C\n" + tri1 + "v 1 1 1\nf 1 2 3\nusemtl A\nf 2 4 3\n", {"DefaultMaterial", "A"}},
      {"groups.obj", "mtllib ab.mtl\ng a\n" + tri2 + "usemtl B\nf 1 2 3\ng b\n" + tri1 + "f 4 5 6\n", {"B", "B"}},
      // Blender 4: an empty material slot writes `usemtl ` with no name
      {"empty_slot.obj", "mtllib ab.mtl\no First\n" + tri1 + "usemtl A\nf 1 2 3\no Second\n" + tri2 + "usemtl \nf 4 5 6\n",
       {"A", "DefaultMaterial"}},
      // Blender 4's "Object Groups": `g Obj_Mesh` for each object (vertices follow it)
      {"object_groups.obj", "# Blender 4.1.0\nmtllib ab.mtl\ng First_Mesh\n" + tri1 + "usemtl A\nf 1 2 3\ng Second_Mesh\n" +
       tri2 + "f 4 5 6\n", {"A", "DefaultMaterial"}},
      // ... and its vertex groups, `g` among an object's faces: the material holds
      {"vertex_groups.obj", "# Blender 4.1.0\nmtllib ab.mtl\no C\n" + tri1 + "v 1 1 1\nusemtl A\ng top\nf 1 2 3\ng side\nf 2 4 3\n",
       {"A", "A"}},  // (two groups: two objects)
      // an `o` repeating the current object is no new object: its material holds
      {"repeated_o.obj", "mtllib ab.mtl\no C\n" + tri1 + "v 1 1 1\nusemtl A\nf 1 2 3\no C\nf 2 4 3\n", {"A"}},
  };
  for (const auto& c : cases) {
    write_file(dir / c.name, c.text);
    const auto s = import_scene(dir / c.name, false);
    std::vector<std::string> got;
    for (const auto& sm : s.submeshes)
      got.push_back(sm.material >= 0 ? s.materials[static_cast<std::size_t>(sm.material)].name : "-");
    EXPECT_EQ(got, c.materials) << c.name;
    EXPECT_TRUE(s.warnings.empty()) << c.name << ": " << s.warnings.front();
  }
}

// A model file is read by its extension: without one assimp would guess OBJ from the content
// past the pre-scan (a '.5' coordinate would lose a vertex without a word).
TEST(Import, AModelWithoutAKnownExtensionIsRefused) {
  const auto dir = scratch("import_extension");
  const std::string obj = "v 0 0 0\nv .5 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\n";
  write_file(dir / "model", obj);
  expect_input_error([&] { import_scene(dir / "model", false); }, "model: no extension: name a Blender export *.obj");
  write_file(dir / "x.obj.bak", obj);
  expect_input_error([&] { import_scene(dir / "x.obj.bak", false); }, "x.obj.bak: '.bak' is no model format");
  write_file(dir / "UP.OBJ", obj);  // (the case does not matter)
  const auto s = import_scene(dir / "UP.OBJ", false);
  ASSERT_EQ(s.positions.size(), 9u);
  EXPECT_EQ(s.positions[3], 0.5f);  // the '.5' read, through the pre-scan
}

// One image named two ways (`./tex.png` and `tex.png`, or through another folder) is baked
// once, and both materials use it (not baked twice).
TEST(Import, OneTextureFileNamedTwoWaysIsBakedOnce) {
  const auto dir = scratch("import_same_texture");
  write_file(dir / "m.obj", "mtllib m.mtl\no A\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl P\nf 1 2 3\nusemtl Q\nf 2 4 3\n");
  write_file(dir / "m.mtl", "newmtl P\nKd 1 1 1\nmap_Kd tex.png\nnewmtl Q\nKd 1 1 1\nmap_Kd ./sub/../tex.png\n");
  fs::create_directories(dir / "sub");
  write_file(dir / "tex.png", read_file(fixture("checker.png")));
  const auto s = b2o::conv::import_scene(dir / "m.obj", false);
  ASSERT_EQ(s.textures.size(), 1u);
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].diffuse_texture, 0);
  EXPECT_EQ(s.materials[1].diffuse_texture, 0);
}
