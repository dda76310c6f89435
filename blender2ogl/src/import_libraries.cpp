// The OBJ's material libraries: each pre-scanned (prescan_mtl_file) before assimp reads it, a
// missing one refused or warned, and the `usemtl` names none of them defines warned.
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "import_stages.hpp"

namespace b2o::conv {
namespace {

// A file's bytes (a material library the pre-scan read already).
std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(file.string() + ": cannot read");
  return text.str();
}

// Checks the libraries of one .obj, in the order its `mtllib` lines name them.
class LibraryCheck {
 public:
  LibraryCheck(const std::filesystem::path& file, bool allow_missing, ObjInput& obj, Scene& out)
      : file_(file), folder_(file.parent_path()), allow_missing_(allow_missing), obj_(obj), scan_(obj.scan), out_(out) {}

  // Every library, then the `usemtl` names they leave undefined.
  void run() {
    for (std::size_t i = 0; i < scan_.mtllibs.size(); ++i) library(i);
    if (!library_missing_) warn_undefined_materials();
  }

 private:
  // The i-th library named: checked, or (missing) refused or warned.
  void library(std::size_t i) {
    if (!scan_.mtllib_joined[i]) line_first_ = -1;
    const std::string& lib = scan_.mtllibs[i];
    const auto p = folder_ / lib;
    std::error_code ec;
    if (!std::filesystem::exists(p, ec)) return missing_library(i, p);
    // assimp would fail on it with a message that names no file
    if (!std::filesystem::is_regular_file(p, ec) || !std::ifstream(p, std::ios::binary))
      throw InputError(where(i) + "material library " + quote_input(lib) + " is not a readable file");
    check_mtl(i, p);
  }

  // "file:line: " of the i-th library's `mtllib` line.
  std::string where(std::size_t i) const { return file_.string() + ":" + std::to_string(scan_.mtllib_lines[i]) + ": "; }

  // A library that is not there: an error, or with --allow-missing a warning (and the
  // <model>.mtl assimp reads in its place checked, when there is one).
  void missing_library(std::size_t i, const std::filesystem::path& p) {
    const std::string& lib = scan_.mtllibs[i];
    if (!allow_missing_)
      throw InputError(where(i) + "material library " + quote_input(lib) + " not found (" + p.string() +
                       "); --allow-missing converts without it");
    library_missing_ = true;
    if (scan_.mtllib_joined[i]) {  // (not the line's first: assimp does not look for it)
      out_.warnings.push_back(where(i) + "material library " + quote_input(lib) +
                              " not found; the materials it would define get a default material");
      return;
    }
    const auto fallback = folder_ / (file_.stem().string() + ".mtl");
    std::error_code ec;
    if (std::filesystem::is_regular_file(fallback, ec)) {
      out_.warnings.push_back(where(i) + "material library " + quote_input(lib) + " not found; assimp reads '" +
                              fallback.filename().string() + "' instead");
      check_mtl(i, fallback);
    } else {
      out_.warnings.push_back(where(i) + "material library " + quote_input(lib) +
                              " not found; its objects get a default material");
    }
  }

  // Pre-scans the .mtl read for the i-th library: its map_Kd lines, materials and warnings.
  void check_mtl(std::size_t i, const std::filesystem::path& mtl) {
    MtlScan m;
    try {
      m = prescan_mtl_file(mtl, folder_.empty() ? std::filesystem::path(".") : folder_);
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()) + " (material library of " + file_.filename().string() + ")");
    }
    for (MapKd& k : m.maps) obj_.map_kd.push_back({std::move(k), mtl});
    defined_.insert(m.materials.begin(), m.materials.end());
    out_.warnings.insert(out_.warnings.end(), m.warnings.begin(), m.warnings.end());
    give_to_assimp(i, mtl, m);
    out_.inputs_read.push_back(std::filesystem::absolute(mtl));
  }

  // The text assimp reads for the library: its cleaned text, and on a line of several
  // libraries the first one's text carries the others' (each once). One entry per file:
  // CheckedIO serves the first that matches, so a library named on several lines gathers
  // what each of its lines joins to it.
  void give_to_assimp(std::size_t i, const std::filesystem::path& mtl, MtlScan& m) {
    ReplacedFiles& replaced = obj_.replaced;
    std::error_code ec;
    const bool joined = scan_.mtllib_joined[i];
    const bool leads = !joined && i + 1 < scan_.mtllibs.size() && scan_.mtllib_joined[i + 1];
    const std::string id = std::filesystem::weakly_canonical(std::filesystem::absolute(mtl), ec).string();
    if (joined) {
      if (line_first_ >= 0 && joined_to_[line_first_].insert(id).second)
        replaced[static_cast<std::size_t>(line_first_)].second.append("\n").append(m.cleaned ? m.clean_text
                                                                                             : read_text(mtl));
      return;
    }
    std::ptrdiff_t entry = -1;
    for (std::size_t k = 0; k < replaced.size() && entry < 0; ++k)
      if (std::filesystem::equivalent(replaced[k].first, mtl, ec)) entry = static_cast<std::ptrdiff_t>(k);
    if (entry < 0 && (m.cleaned || leads)) {
      replaced.emplace_back(mtl, m.cleaned ? std::move(m.clean_text) : read_text(mtl));
      entry = static_cast<std::ptrdiff_t>(replaced.size()) - 1;
      joined_to_[entry].insert(id);
    }
    line_first_ = leads ? entry : -1;
  }

  // A `usemtl` no library defines: assimp invents a material of that name (grey); the file's
  // author meant another. (Not repeated when a library is missing: that is warned.) Once per
  // name, at its first use, with how many more there are (Blender's legacy exporter writes
  // `usemtl (null)` before every object without a material).
  void warn_undefined_materials() {
    std::map<std::string, std::pair<std::size_t, std::size_t>> undefined;  // name -> first line, uses
    std::vector<std::string> order;
    for (const auto& [name, line] : scan_.usemtl)
      if (defined_.count(name) == 0) {
        auto [it, added] = undefined.try_emplace(name, line, 0);
        if (added) order.push_back(name);
        ++it->second.second;
      }
    for (const std::string& name : order) {
      const auto [line, uses] = undefined[name];
      out_.warnings.push_back(file_.string() + ":" + std::to_string(line) + ": material " + quote_input(name) +
                              (scan_.mtllibs.empty() ? " used but no 'mtllib' is given"
                                                     : " is defined in no material library") +
                              "; its faces get a default (grey) material" +
                              (uses > 1 ? " (used " + std::to_string(uses) + " times)" : std::string()));
    }
  }

  const std::filesystem::path& file_;
  const std::filesystem::path folder_;
  const bool allow_missing_;
  ObjInput& obj_;
  const ObjScan& scan_;
  Scene& out_;
  std::set<std::string> defined_;  // materials of the libraries read
  bool library_missing_ = false;
  // the `replaced` entry of the first library of an mtllib line of several (-1: none), and
  // per entry the libraries whose text it holds
  std::ptrdiff_t line_first_ = -1;
  std::map<std::ptrdiff_t, std::set<std::string>> joined_to_;
};

}  // namespace

void check_material_libraries(const std::filesystem::path& file, bool allow_missing, ObjInput& obj, Scene& out) {
  LibraryCheck(file, allow_missing, obj, out).run();
}

}  // namespace b2o::conv
