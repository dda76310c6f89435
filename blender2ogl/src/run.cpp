// run: import -> bake -> emit -> write, with warnings, statistics and the depfile.
#include <chrono>
#include <fstream>
#include <ostream>

#include "converter.hpp"

namespace b2o::conv {
namespace {

std::string depfile_escape(const std::string& p) {
  std::string out;
  for (char c : p) {
    if (c == ' ' || c == '#' || c == '\\') out += '\\';
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}

// Refuses an output that is one of the inputs (`--depfile m.obj`, `mtllib m.h` in the target
// folder): by identity (same file, through links) when it exists, else by canonical path.
void check_outputs_are_not_inputs(const std::vector<std::filesystem::path>& outputs,
                                  const std::vector<std::filesystem::path>& inputs) {
  namespace fs = std::filesystem;
  for (const fs::path& out : outputs) {
    std::error_code ec;
    const bool exists = fs::exists(out, ec);
    const fs::path canon = fs::weakly_canonical(fs::absolute(out, ec), ec);
    for (const fs::path& in : inputs) {
      std::error_code ec2;
      const bool same = exists ? fs::equivalent(out, in, ec2) : canon == fs::weakly_canonical(in, ec2);
      if (same)
        throw UsageError(out.string() + ": an output would overwrite the input " + in.string() +
                         "; choose another target folder (-t), name (-n) or --depfile");
    }
  }
}

// Refuses a --depfile that is one of the generated files (it would replace it: a header
// holding Makefile text), by identity when both exist, else by canonical path.
void check_depfile_is_no_output(const std::filesystem::path& depfile,
                                const std::vector<std::filesystem::path>& generated) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path canon = fs::weakly_canonical(fs::absolute(depfile, ec), ec);
  for (const fs::path& out : generated) {
    std::error_code ec2;
    const bool same = fs::exists(depfile, ec2) && fs::exists(out, ec2) ? fs::equivalent(depfile, out, ec2)
                                                                        : canon == fs::weakly_canonical(fs::absolute(out, ec2), ec2);
    if (same)
      throw UsageError(depfile.string() + ": --depfile names a file the bake writes (" + out.filename().string() +
                       "); give it another name, e.g. " + out.filename().string() + ".d");
  }
}

}  // namespace

int run(const Options& opt, std::ostream& log) {
  const auto t0 = std::chrono::steady_clock::now();
  Scene scene = import_scene(opt.input, opt.merge, opt.allow_missing);
  scene.name = clean_identifier(opt.name.empty() ? opt.input.stem().string() : opt.name);
  Stats stats;
  auto t1 = std::chrono::steady_clock::now();
  bake_scene(scene, opt, stats);
  scene.timings_ms.emplace_back("bake", lap_ms(t1));
  const auto files = emit_scene(scene, opt);
  scene.timings_ms.emplace_back("emit", lap_ms(t1));
  const std::filesystem::path dir = opt.target_dir.empty() ? opt.input.parent_path() : opt.target_dir;
  const std::filesystem::path out_dir = dir.empty() ? std::filesystem::path(".") : dir;
  // The depfile is part of the commit: written to a temp file with the others and renamed
  // before the header, so a depfile that cannot be written changes nothing.
  std::vector<std::pair<std::filesystem::path, std::string>> extra;
  if (!opt.depfile.empty()) {
    // Makefile syntax for the build tool: the header depends on every file read.
    std::string text =
        depfile_escape((std::filesystem::absolute(out_dir) / files.front().name).lexically_normal().string()) + ":";
    for (const auto& p : scene.inputs_read) text += " \\\n  " + depfile_escape(p.string());
    text += "\n";
    extra.emplace_back(opt.depfile, std::move(text));
  }
  {
    std::vector<std::filesystem::path> outputs;
    for (const OutputFile& f : files) outputs.push_back(out_dir / f.name);
    if (!opt.depfile.empty()) {
      check_depfile_is_no_output(opt.depfile, outputs);
      outputs.push_back(opt.depfile);
    }
    check_outputs_are_not_inputs(outputs, scene.inputs_read);
  }
  const int changed = write_outputs(out_dir, files, extra);
  remove_stale_bins(out_dir, scene.name, files, scene.inputs_read);
  scene.timings_ms.emplace_back("write", lap_ms(t1));

  if (opt.combined && scene.positions.size() / 3 > 100000)
    scene.warnings.push_back(opt.input.string() + ": " + std::to_string(scene.positions.size() / 3) +
                             " vertices as text (-c) compile slowly; the default (-s) links them as bytes");
  for (const std::string& w : scene.warnings) log << "blender2ogl: warning: " << w << "\n";

  if (opt.verbose) {
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::size_t masses = 0, structural = 0, bend = 0, pins = 0, bytes = 0;
    for (const Cloth& c : scene.cloths) {
      masses += c.mass_count();
      structural += c.structural_count;
      bend += c.springs.size() - c.structural_count;
      pins += c.pins.size();
    }
    for (const auto& f : files) bytes += f.bytes.size();
    log << "blender2ogl: " << scene.source << " -> " << (dir / files.front().name).string() << "\n"
        << "  objects    " << scene.objects.size() << "\n"
        << "  vertices   " << scene.positions.size() / 3 << "\n"
        << "  triangles  " << scene.indices.size() / 3 << "\n"
        << "  materials  " << scene.materials.size() << " (" << scene.textures.size() << " textures)\n"
        << "  cloths     " << scene.cloths.size() << "\n"
        << "  masses     " << masses << "\n"
        << "  springs    " << structural + bend << " (" << structural << " structural, " << bend << " bend)\n"
        << "  pins       " << pins << "\n"
        << "  warnings   " << scene.warnings.size() << "\n"
        << "  files      " << files.size() + extra.size() << " (" << changed << " changed, " << bytes << " bytes)\n"
        << "  time       " << ms << " ms (";
    for (std::size_t i = 0; i < scene.timings_ms.size(); ++i)
      log << (i ? ", " : "") << scene.timings_ms[i].first << " " << static_cast<long>(scene.timings_ms[i].second);
    log << ")\n";
    for (const Cloth& c : scene.cloths)
      log << "  cloth " << scene.objects[c.object].name << ": " << c.mass_count() << " masses, " << c.springs.size()
          << " springs (" << c.structural_count << " structural, " << c.springs.size() - c.structural_count
          << " bend), " << c.triangles.size() / 3 << " triangles, " << c.pins.size() << " pins\n";
  }
  return 0;
}

}  // namespace b2o::conv
