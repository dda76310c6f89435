// libFuzzer target: the converter's whole path (import -> bake -> emit -> write) on one input.
//
// Input layout: byte 0 = option bits (see kMerge...), then the .obj text; an optional .mtl
// follows a line "%%MTL". The files are written to a private folder in /dev/shm because the
// importer reads from a path (it must also find the .mtl and textures next to the .obj).
// Accepted outcomes: success, or an InputError/UsageError (a clear message). Anything else
// (another exception, a crash, a sanitizer report, a broken invariant of the baked scene) is a
// finding.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

#include "converter.hpp"

namespace fs = std::filesystem;
namespace conv = b2o::conv;

namespace {

constexpr std::uint8_t kMerge = 1, kReverse = 2, kAllCloth = 4, kFirstCloth = 8, kPin = 16, kCombined = 32,
                       kWrite = 64, kParam = 128;

const fs::path& work_dir() {
  static const fs::path dir = [] {
    fs::path d = fs::path(fs::exists("/dev/shm") ? "/dev/shm" : fs::temp_directory_path()) /
                 ("clothsim-fuzz-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d / "out");
    // A texture the .mtl may name (map_Kd tex.png), so the texture path is reached too.
    std::ofstream(d / "tex.png", std::ios::binary) << "\x89PNG\r\n\x1a\n-not-really-";
    std::atexit([] { std::error_code ec; fs::remove_all(work_dir(), ec); });
    return d;
  }();
  return dir;
}

void write_file(const fs::path& p, std::string_view bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_converter: %s\n", what.c_str());
  std::abort();
}

// What the emitter relies on and the simulator trusts: every index in range, all numbers finite.
void check_scene(const conv::Scene& s) {
  const std::size_t nv = s.positions.size() / 3;
  if (s.positions.size() != 3 * nv || s.normals.size() != 3 * nv || s.texcoords.size() != 2 * nv)
    finding("vertex arrays of different lengths");
  for (float f : s.positions) if (!std::isfinite(f)) finding("non-finite position accepted");
  for (float f : s.normals) if (!std::isfinite(f)) finding("non-finite normal accepted");
  for (float f : s.texcoords) if (!std::isfinite(f)) finding("non-finite texcoord accepted");
  if (s.indices.size() % 3 != 0) finding("index count not a multiple of 3");
  for (auto i : s.indices) if (i >= nv) finding("index out of range");
  if (s.objects.empty()) finding("accepted a scene without objects");
  for (const auto& o : s.objects) {
    if (o.first_vertex + std::uint64_t{o.vertex_count} > nv) finding("object vertex range out of bounds");
    if (o.first_index + std::uint64_t{o.index_count} > s.indices.size()) finding("object index range out of bounds");
    if (o.first_submesh + std::uint64_t{o.submesh_count} > s.submeshes.size()) finding("object submesh range out of bounds");
    if (o.identifier.empty()) finding("object without identifier");
    if (o.cloth >= static_cast<std::int64_t>(s.cloths.size())) finding("object cloth index out of range");
    for (std::uint32_t k = o.first_index; k < o.first_index + o.index_count; ++k)
      if (s.indices[k] < o.first_vertex || s.indices[k] >= o.first_vertex + o.vertex_count)
        finding("object '" + o.name + "' indexes another object's vertex");
  }
  for (const auto& sm : s.submeshes) {
    if (sm.first_index % 3 != 0 || sm.index_count % 3 != 0) finding("submesh not made of triangles");
    if (sm.first_index + std::uint64_t{sm.index_count} > s.indices.size()) finding("submesh out of bounds");
    if (sm.material >= static_cast<std::int64_t>(s.materials.size())) finding("submesh material out of range");
  }
  for (const auto& m : s.materials)
    if (m.diffuse_texture >= static_cast<std::int64_t>(s.textures.size())) finding("material texture out of range");
  for (const auto& c : s.cloths) {
    const std::uint32_t n = c.mass_count();
    if (c.object >= s.objects.size()) finding("cloth object out of range");
    for (float f : c.rest_positions) if (!std::isfinite(f)) finding("non-finite rest position");
    if (c.mass_vertex_offsets.size() != n + std::size_t{1} || c.mass_vertex_offsets.back() != c.mass_vertices.size())
      finding("mass_vertex_offsets is not a CSR of mass_vertices");
    for (std::size_t k = 1; k < c.mass_vertex_offsets.size(); ++k)
      if (c.mass_vertex_offsets[k] <= c.mass_vertex_offsets[k - 1]) finding("a mass without vertices");
    for (auto v : c.mass_vertices) if (v >= nv) finding("mass vertex out of range");
    if (c.structural_count > c.springs.size()) finding("structural_count > spring_count");
    for (std::size_t k = 0; k < c.springs.size(); ++k) {
      const auto& sp = c.springs[k];
      if (sp.a >= n || sp.b >= n || sp.a == sp.b) finding("bad spring endpoints");
      if (!std::isfinite(sp.rest_length) || sp.rest_length < 0) finding("bad spring rest length");
      if (sp.kind != (k < c.structural_count ? 0u : 1u)) finding("spring kinds not structural-then-bend");
    }
    if (c.triangles.size() % 3 != 0) finding("cloth triangles not a multiple of 3");
    for (auto t : c.triangles) if (t >= n) finding("cloth triangle mass out of range");
    for (std::size_t k = 0; k < c.pins.size(); ++k) {
      if (c.pins[k] >= n) finding("pin out of range");
      if (k > 0 && c.pins[k] <= c.pins[k - 1]) finding("pins not sorted and unique");
    }
    for (auto m : c.vertex_mass) if (m != 0xffffffffu && m >= n) finding("vertex_mass out of range");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1 || size > 256 * 1024) return 0;
  const fs::path& dir = work_dir();
  const std::uint8_t flags = data[0];
  std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
  std::string_view obj = rest, mtl;
  const bool has_mtl = [&] {
    const auto at = rest.find("%%MTL\n");
    if (at == std::string_view::npos) return false;
    obj = rest.substr(0, at);
    mtl = rest.substr(at + 6);
    return true;
  }();
  const fs::path input = dir / "in.obj";
  write_file(input, obj);
  std::error_code ec;
  if (has_mtl) write_file(dir / "in.mtl", mtl); else fs::remove(dir / "in.mtl", ec);

  conv::Options opt;
  opt.input = input;
  opt.target_dir = dir / "out";
  opt.merge = flags & kMerge;
  opt.reverse_map = flags & kReverse;
  opt.combined = flags & kCombined;
  if (flags & kParam) opt.params = {{"dt", "0.01"}, {"k_rep", "1e3"}};
  try {
    conv::Scene scene = conv::import_scene(input, opt.merge, /*allow_missing=*/true);  // more of the path than a refusal
    scene.name = conv::clean_identifier(input.stem().string());  // as run() does
    if (flags & kAllCloth)
      for (const auto& o : scene.objects) opt.cloth_objects.push_back(o.name);
    else if ((flags & kFirstCloth) && !scene.objects.empty())
      opt.cloth_objects.push_back(scene.objects.front().name);
    if ((flags & kPin) && !opt.cloth_objects.empty()) opt.pins.push_back({opt.cloth_objects.front(), {0.f, 0.f, 0.f}});
    conv::Stats stats;
    conv::bake_scene(scene, opt, stats);
    check_scene(scene);
    const auto files = conv::emit_scene(scene, opt);
    if (files.empty()) finding("emit produced no files");
    for (const auto& f : files)
      if (f.name.empty() || f.name.find('/') != std::string::npos) finding("emit produced a bad file name '" + f.name + "'");
    if (flags & kWrite) conv::write_outputs(opt.target_dir, files);
  } catch (const conv::InputError& e) {
    if (std::string_view(e.what()).find('\n') != std::string_view::npos) finding(std::string("multi-line error: ") + e.what());
  } catch (const conv::UsageError&) {
  } catch (const std::exception& e) {
    finding(std::string("unexpected exception: ") + e.what());
  }
  return 0;
}
