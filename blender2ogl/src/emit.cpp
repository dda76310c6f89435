// emit: the generated C++. -s (default): <name>.h holds everything but the bulk bytes (small
// tables as text, and the .incbin directives of the bulk arrays for the assembler, so bulk data
// never goes through the C++ parser); <name>.cpp and <name>.S are fixed stubs including it;
// <name>.<hash>.bin holds the bulk bytes. -c: one header with everything as text (exact
// hex-float literals), for small scenes.
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "converter.hpp"

#include <blender2ogl/scene_types.h>

namespace b2o::conv {
namespace {

std::string hexf(float f) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%af", static_cast<double>(f));
  return buf;
}
std::string u32(std::uint32_t v) { return std::to_string(v) + "u"; }
std::string i32(std::int32_t v) { return v < 0 ? "::b2o::kNone" : std::to_string(v); }

// A C++ string literal; octal escapes (never greedy like \x) for anything not plain ASCII.
std::string quote(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c == '?') {
      out += "\\?";  // no trigraphs
    } else if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\%03o", c);
      out += buf;
    }
  }
  return out + "\"";
}

// Text safe inside // and /* */ comments: printable ASCII, no backslash, no "*/", no "??"
// (a trigraph such as ??/ is a warning, an error under -Werror: `o bar??/`). A UTF-8 sequence
// (`o Würfel`) becomes one '?'.
std::string comment_safe(const std::string& s) {
  std::string out;
  for (unsigned char c : s) {
    if (c >= 0x80 && c < 0xc0 && !out.empty() && out.back() == '?') continue;  // (a continuation byte)
    out += (c >= 0x20 && c < 0x7f && c != '\\') ? static_cast<char>(c) : '?';
  }
  for (std::size_t p; (p = out.find("*/")) != std::string::npos;) out[p] = '?';
  for (std::size_t p; (p = out.find("??")) != std::string::npos;) out.insert(p + 1, " ");
  return out;
}

std::string upper(std::string s) {
  for (char& c : s)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  return s;
}

std::string sym_prefix(const Scene& s) { return "b2o_" + s.name + (s.name.back() == '_' ? "" : "_"); }

// One bulk array: a symbol, its C++ element type and its bytes.
struct Array {
  std::string symbol, type;
  const void* data = nullptr;  // the scene's own vector (not copied: big scenes)
  std::size_t size = 0;        // bytes
  std::size_t count = 0;       // elements
  std::string text;            // -c: the initializer list
};

template <class T>
Array make_array(std::string symbol, std::string type, const std::vector<T>& v) {
  return Array{std::move(symbol), std::move(type), v.data(), v.size() * sizeof(T), v.size(), {}};
}

std::string text_of(const std::vector<float>& v) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) out += (i % 6 == 0 ? "\n    " : " ") + hexf(v[i]) + ",";
  return out;
}
std::string text_of(const std::vector<std::uint32_t>& v) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) out += (i % 12 == 0 ? "\n    " : " ") + u32(v[i]) + ",";
  return out;
}
std::string text_of(const std::vector<unsigned char>& v) {
  std::string out;
  char buf[8];
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::snprintf(buf, sizeof buf, "0x%02x,", v[i]);
    out += (i % 16 == 0 ? "\n    " : " ") + std::string(buf);
  }
  return out;
}
std::string text_of(const std::vector<Spring>& v) {
  std::string out;
  for (const Spring& s : v)
    out += "\n    {" + u32(s.a) + ", " + u32(s.b) + ", " + hexf(s.rest_length) + ", ::b2o::SpringKind::" +
           (s.kind == 0 ? "Structural" : "Bend") + "},";
  return out;
}

struct Layout {
  // Pointer expressions for every array (symbol name, or nullptr when empty).
  std::string positions, normals, texcoords, indices;
  std::vector<std::string> textures;
  struct ClothPtrs {
    std::string rest, offsets, mass_vertices, vertex_mass, springs, triangles, pins;
  };
  std::vector<ClothPtrs> cloths;
  std::vector<Array> arrays;
};

Layout collect(const Scene& s, bool combined) {
  Layout L;
  auto add = [&](Array a, std::string text) -> std::string {
    if (a.count == 0) return "nullptr";
    a.text = std::move(text);
    const std::string ref = combined ? "detail::" + a.symbol : a.symbol;
    L.arrays.push_back(std::move(a));
    return ref;
  };
  const std::string base = combined ? std::string() : sym_prefix(s);
  L.positions = add(make_array(base + "positions", "float", s.positions), combined ? text_of(s.positions) : "");
  L.normals = add(make_array(base + "normals", "float", s.normals), combined ? text_of(s.normals) : "");
  L.texcoords = add(make_array(base + "texcoords", "float", s.texcoords), combined ? text_of(s.texcoords) : "");
  L.indices = add(make_array(base + "indices", "std::uint32_t", s.indices), combined ? text_of(s.indices) : "");
  for (std::size_t t = 0; t < s.textures.size(); ++t)
    L.textures.push_back(add(make_array(base + "texture" + std::to_string(t), "unsigned char", s.textures[t].bytes),
                             combined ? text_of(s.textures[t].bytes) : ""));
  for (std::size_t c = 0; c < s.cloths.size(); ++c) {
    const Cloth& cl = s.cloths[c];
    const std::string cp = base + "cloth" + std::to_string(c) + "_";
    Layout::ClothPtrs ptr;
    ptr.rest = add(make_array(cp + "rest_positions", "float", cl.rest_positions), combined ? text_of(cl.rest_positions) : "");
    ptr.offsets = add(make_array(cp + "mass_vertex_offsets", "std::uint32_t", cl.mass_vertex_offsets),
                      combined ? text_of(cl.mass_vertex_offsets) : "");
    ptr.mass_vertices = add(make_array(cp + "mass_vertices", "std::uint32_t", cl.mass_vertices),
                            combined ? text_of(cl.mass_vertices) : "");
    ptr.vertex_mass = add(make_array(cp + "vertex_mass", "std::uint32_t", cl.vertex_mass),
                          combined ? text_of(cl.vertex_mass) : "");
    ptr.springs = add(make_array(cp + "springs", "::b2o::Spring", cl.springs), combined ? text_of(cl.springs) : "");
    ptr.triangles = add(make_array(cp + "triangles", "std::uint32_t", cl.triangles), combined ? text_of(cl.triangles) : "");
    ptr.pins = add(make_array(cp + "pins", "std::uint32_t", cl.pins), combined ? text_of(cl.pins) : "");
    L.cloths.push_back(ptr);
  }
  return L;
}

// The small tables and the Scene object, as C++ text (shared by -s and -c).
std::string tables(const Scene& s, const Layout& L, const std::string& indent, const std::string& storage) {
  std::ostringstream o;
  if (!s.textures.empty()) {
    o << indent << storage << "::b2o::Texture kTextures[] = {\n";
    for (std::size_t t = 0; t < s.textures.size(); ++t)
      o << indent << "    {" << quote(s.textures[t].name) << ", " << L.textures[t] << ", "
        << u32(static_cast<std::uint32_t>(s.textures[t].bytes.size())) << "},\n";
    o << indent << "};\n";
  }
  if (!s.materials.empty()) {
    o << indent << storage << "::b2o::Material kMaterials[] = {\n";
    for (const Material& m : s.materials) {
      auto v3 = [](const std::array<float, 3>& a) {
        std::string t("{");  // (not "{" + string: GCC 12 -Wrestrict false positive)
        t.append(hexf(a[0])).append(", ").append(hexf(a[1])).append(", ").append(hexf(a[2])).append("}");
        return t;
      };
      o << indent << "    {" << quote(m.name) << ", " << v3(m.ambient) << ", " << v3(m.diffuse) << ", " << v3(m.specular)
        << ", " << hexf(m.shininess) << ", " << hexf(m.opacity) << ", " << i32(m.diffuse_texture) << "},\n";
    }
    o << indent << "};\n";
  }
  if (!s.submeshes.empty()) {
    o << indent << storage << "::b2o::Submesh kSubmeshes[] = {\n";
    for (const Submesh& m : s.submeshes)
      o << indent << "    {" << u32(m.first_index) << ", " << u32(m.index_count) << ", " << i32(m.material) << "},\n";
    o << indent << "};\n";
  }
  o << indent << storage << "::b2o::Object kObjects[] = {\n";
  for (const Object& ob : s.objects)
    o << indent << "    {" << quote(ob.name) << ", " << quote(ob.identifier) << ", " << u32(ob.first_vertex) << ", "
      << u32(ob.vertex_count) << ", " << u32(ob.first_index) << ", " << u32(ob.index_count) << ", "
      << u32(ob.first_submesh) << ", " << u32(ob.submesh_count) << ", " << i32(ob.cloth) << "},\n";
  o << indent << "};\n";
  if (!s.cloths.empty()) {
    o << indent << storage << "::b2o::Cloth kCloths[] = {\n";
    for (std::size_t c = 0; c < s.cloths.size(); ++c) {
      const Cloth& cl = s.cloths[c];
      const auto& p = L.cloths[c];
      o << indent << "    {" << u32(cl.object) << ", " << u32(cl.mass_count()) << ", " << p.rest << ", " << p.offsets << ", "
        << p.mass_vertices << ", " << p.vertex_mass << ",\n"
        << indent << "     " << u32(static_cast<std::uint32_t>(cl.springs.size())) << ", " << p.springs << ", "
        << u32(cl.structural_count) << ", " << u32(static_cast<std::uint32_t>(cl.triangles.size() / 3)) << ", "
        << p.triangles << ", " << u32(static_cast<std::uint32_t>(cl.pins.size())) << ", " << p.pins << "},\n";
    }
    o << indent << "};\n";
  }
  if (!s.params.empty()) {
    o << indent << storage << "::b2o::Param kParams[] = {\n";
    for (const auto& [k, v] : s.params) o << indent << "    {" << quote(k) << ", " << quote(v) << "},\n";
    o << indent << "};\n";
  }
  return o.str();
}

std::string scene_init(const Scene& s, const Layout& L, const std::string& q) {
  auto n = [](std::size_t v) { return u32(static_cast<std::uint32_t>(v)); };
  std::ostringstream o;
  o << "{\n"
    << "    ::b2o::kFormatVersion, " << quote(s.name) << ", " << quote(s.source) << ",\n"
    << "    " << n(s.positions.size() / 3) << ", " << L.positions << ", " << L.normals << ", " << L.texcoords << ",\n"
    << "    " << n(s.indices.size()) << ", " << L.indices << ",\n"
    << "    " << n(s.objects.size()) << ", " << q << "kObjects,\n"
    << "    " << n(s.submeshes.size()) << ", " << (s.submeshes.empty() ? "nullptr" : q + "kSubmeshes") << ",\n"
    << "    " << n(s.materials.size()) << ", " << (s.materials.empty() ? "nullptr" : q + "kMaterials") << ",\n"
    << "    " << n(s.textures.size()) << ", " << (s.textures.empty() ? "nullptr" : q + "kTextures") << ",\n"
    << "    " << n(s.cloths.size()) << ", " << (s.cloths.empty() ? "nullptr" : q + "kCloths") << ",\n"
    << "    " << n(s.params.size()) << ", " << (s.params.empty() ? "nullptr" : q + "kParams") << ",\n"
    << "}";
  return o.str();
}

// -s: `asm_part` (the bulk arrays, read when the header is assembled through <name>.S) and
// `definition` (the tables and the Scene, compiled once through <name>.cpp) live in the header
// too, so the header alone says which bake is current: it is the commit point (docs/blender2ogl.md).
std::string header(const Scene& s, const Options& opt, const Layout* text_layout, const std::string& bake_id,
                   const std::string& asm_part = {}, const std::string& definition = {}) {
  // (the name as it is: scenes `ab` and `Ab` are two namespaces, and need two guards)
  const std::string guard = "B2O_GEN_" + s.name + "_H";
  const std::string ns = "b2o::gen::" + s.name;
  std::ostringstream h;
  h << "// " << comment_safe(s.name) << ".h: the scene baked by blender2ogl " << kVersion << " from "
    << comment_safe(s.source) << ".\n"
    << "// Generated: do not edit; change the model and re-run the bake.\n"
    << "//\n"
    << "//   #include \"" << comment_safe(s.name) << ".h\"\n"
    << "//   const b2o::Scene& s = " << ns << "::scene;  // fields: blender2ogl/scene_types.h\n"
    << "//   const b2o::Object& o = s.objects[" << ns << "::object::" << s.objects.front().identifier << "];\n"
    << "//\n"
    << "// Object and cloth indices below are named after the objects (cleaned into C++\n"
    << "// identifiers; Object::name keeps the name as written in the file).\n"
    << "#ifndef " << guard << "\n#define " << guard << "\n\n";
  if (!bake_id.empty())
    h << "#ifdef __ASSEMBLER__\n" << asm_part << "#else  // C++ from here on\n\n";
  h << "#include <blender2ogl/scene_types.h>\n\n#include <cstdint>\n#include <cstring>\n\n"
    << "static_assert(::b2o::kFormatVersion == " << ::b2o::kFormatVersion << ", \"" << s.name
    << ".h was baked for scene format " << ::b2o::kFormatVersion << "; re-run blender2ogl\");\n\n"
    << "namespace " << ns << " {\n\n";
  auto n = [](std::size_t v) { return std::to_string(v) + "u"; };
  h << "inline constexpr std::uint32_t vertex_count = " << n(s.positions.size() / 3) << ";\n"
    << "inline constexpr std::uint32_t index_count = " << n(s.indices.size()) << ";\n"
    << "inline constexpr std::uint32_t triangle_count = " << n(s.indices.size() / 3) << ";\n"
    << "inline constexpr std::uint32_t object_count = " << n(s.objects.size()) << ";\n"
    << "inline constexpr std::uint32_t material_count = " << n(s.materials.size()) << ";\n"
    << "inline constexpr std::uint32_t texture_count = " << n(s.textures.size()) << ";\n"
    << "inline constexpr std::uint32_t cloth_count = " << n(s.cloths.size()) << ";\n"
    << "inline constexpr std::uint32_t param_count = " << n(s.params.size()) << ";\n"
    << "inline constexpr bool has_vertex_mass = " << (opt.reverse_map ? "true" : "false") << ";\n";
  if (!bake_id.empty())
    h << "/// Identifies this bake (its tables and bulk bytes).\n"
      << "inline constexpr std::uint64_t bake_id = 0x" << bake_id << "ull;\n";
  h << "\n";
  h << "/// Indices into scene.objects.\nnamespace object {\n";
  for (std::size_t i = 0; i < s.objects.size(); ++i)
    h << "inline constexpr std::uint32_t " << s.objects[i].identifier << " = " << i << "u;  // "
      << comment_safe(s.objects[i].name) << "\n";
  h << "}  // namespace object\n\n";
  if (!s.cloths.empty()) {
    h << "/// Indices into scene.cloths (objects given masses and springs).\nnamespace cloth {\n";
    for (std::size_t c = 0; c < s.cloths.size(); ++c) {
      const Cloth& cl = s.cloths[c];
      h << "inline constexpr std::uint32_t " << s.objects[cl.object].identifier << " = " << c << "u;  // "
        << cl.mass_count() << " masses, " << cl.springs.size() << " springs, " << cl.pins.size() << " pins\n";
    }
    h << "}  // namespace cloth\n\n";
  }
  if (text_layout == nullptr) {
    h << "/// The baked scene; all of its arrays are read-only data linked into the program.\n"
      << "extern const ::b2o::Scene scene;\n\n";
  } else {
    h << "namespace detail {\n";
    for (const Array& a : text_layout->arrays)
      h << "inline constexpr " << a.type << " " << a.symbol << "[] = {" << a.text << "\n};\n";
    h << tables(s, *text_layout, "", "inline constexpr ");
    h << "}  // namespace detail\n\n"
      << "/// The baked scene; all of its arrays are read-only data in this header.\n"
      << "inline const ::b2o::Scene scene = " << scene_init(s, *text_layout, "detail::") << ";\n\n";
  }
  h << "/// The object named `name` as written in the file, or nullptr.\n"
    << "inline const ::b2o::Object* find_object(const char* name) noexcept {\n"
    << "  for (std::uint32_t i = 0; i < scene.object_count; ++i)\n"
    << "    if (std::strcmp(scene.objects[i].name, name) == 0) return &scene.objects[i];\n"
    << "  return nullptr;\n}\n\n"
    << "/// The value baked with `--param key=value` (its text), or `fallback` when the bake had none.\n"
    << "inline const char* param(const char* key, const char* fallback) noexcept {\n"
    << "  for (std::uint32_t i = 0; i < scene.param_count; ++i)\n"
    << "    if (std::strcmp(scene.params[i].key, key) == 0) return scene.params[i].value;\n"
    << "  return fallback;\n}\n\n"
    << "}  // namespace " << ns << "\n\n";
  if (!bake_id.empty()) h << definition << "#endif  // __ASSEMBLER__\n";
  h << "#endif  // " << guard << "\n";
  return h.str();
}

}  // namespace

std::string hash_hex(const std::string& bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

std::vector<OutputFile> emit_scene(const Scene& s, const Options& opt) {
  std::vector<OutputFile> files;
  if (opt.combined) {
    const Layout L = collect(s, true);
    files.push_back({s.name + ".h", header(s, opt, &L, "")});
    return files;
  }
  const Layout L = collect(s, false);

  std::size_t total = 0;
  for (const Array& a : L.arrays) total = (total + 15) / 16 * 16 + a.size;
  std::string bin;
  bin.reserve(total);
  std::vector<std::size_t> offsets;
  for (const Array& a : L.arrays) {
    bin.resize((bin.size() + 15) / 16 * 16, '\0');
    offsets.push_back(bin.size());
    bin.append(static_cast<const char*>(a.data), a.size);
  }
  // The .bin is named by its own hash: a new bake never overwrites the .bin an older header
  // refers to, so the header (renamed last) switches the whole set at once.
  const std::string bin_hash = hash_hex(bin);
  const std::string bin_name = s.name + "." + bin_hash + ".bin";
  const std::string table_defs = tables(s, L, "", "constexpr "), scene_def = scene_init(s, L, "");
  const std::string id = hash_hex(bin_hash + table_defs + scene_def + header(s, opt, nullptr, ""));
  const std::string check_symbol = sym_prefix(s) + "bake_" + id;

  std::ostringstream S;
  S << "/* Bulk arrays, assembled through " << s.name << ".S: the bytes of " << bin_name << "\n"
    << "   (" << bin.size() << " bytes, fnv1a64 " << bin_hash << "), found through -I<dir>. */\n"
    << "\t.section .rodata.b2o." << s.name << ",\"a\",@progbits\n";
  for (std::size_t i = 0; i < L.arrays.size(); ++i) {
    const Array& a = L.arrays[i];
    S << "\t.balign 16\n\t.globl " << a.symbol << "\n\t.type " << a.symbol << ", @object\n\t.size " << a.symbol
      << ", " << a.size << "\n"
      << a.symbol << ":\n\t.incbin \"" << bin_name << "\", " << offsets[i] << ", " << a.size << "\n";
  }
  S << "\t.globl " << check_symbol << "\n\t.type " << check_symbol << ", @object\n\t.size " << check_symbol
    << ", 1\n" << check_symbol << ":\n\t.byte 0\n"
    << "\t.section .note.GNU-stack,\"\",@progbits\n";

  const std::string define_macro = "B2O_" + upper(s.name) + "_DEFINE_SCENE";
  std::ostringstream d;
  d << "#ifdef " << define_macro << "\n"
    << "// Compiled once, in " << s.name << ".cpp: the small tables as text; the bulk arrays are the\n"
    << "// symbols of the assembler part above. The last symbol exists only in an object assembled\n"
    << "// from this very header (a stale " << s.name << ".S object fails to link).\n"
    << "extern \"C\" {\n";
  for (const Array& a : L.arrays) d << "extern const " << a.type << " " << a.symbol << "[];\n";
  d << "extern const unsigned char " << check_symbol << "[];\n}\n\n";
  d << "namespace b2o::gen::" << s.name << " {\nnamespace {\n" << table_defs
    << "}  // namespace\n\nconst ::b2o::Scene scene = " << scene_def << ";\n\n"
    << "extern const unsigned char* const bake_check;\nconst unsigned char* const bake_check = " << check_symbol
    << ";\n\n}  // namespace b2o::gen::" << s.name << "\n#endif  // " << define_macro << "\n";

  files.push_back({s.name + ".h", header(s, opt, nullptr, id, S.str(), d.str())});
  // Bake-independent stubs: their bytes depend on the name only, never on the bake.
  files.push_back({s.name + ".cpp", "// " + s.name + ".cpp: defines the scene of " + s.name +
                                        ".h (its tables are in the header). Generated: do not edit.\n#define " +
                                        define_macro + "\n#include \"" + s.name + ".h\"\n"});
  files.push_back({s.name + ".S", "/* " + s.name + ".S: the bulk arrays of " + s.name +
                                      ".h (the directives are in the header). Generated: do not edit. */\n#include \"" +
                                      s.name + ".h\"\n"});
  files.push_back({bin_name, std::move(bin)});
  return files;
}

}  // namespace b2o::conv
