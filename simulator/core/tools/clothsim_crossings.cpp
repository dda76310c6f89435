// clothsim_crossings: counts the self-crossings of OBJ meshes (clothsim/self_crossings.hpp),
// such as the frames `clothsim --export-obj` writes.
//
//   clothsim_crossings [--quiet] FILE.obj...
//       one line per file: "FILE: N self-crossings (P triangle pairs), T triangles";
//       exit 0 when no file has any, 1 when one has, 2 on bad input (one message naming the
//       file and line; nothing else written)
//
// It reads `v` and `f` lines only (f with v, v/vt, v/vt/vn or v//vn, negative indices
// relative to the vertices so far; polygons as fans from their first corner); every face of
// the file counts, whatever its object or group.
#include <clothsim/self_crossings.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace {

constexpr int kExitClean = 0, kExitCrossings = 1, kExitBadInput = 2;

const char* const kUsage =
    "usage: clothsim_crossings [--quiet] FILE.obj...\n"
    "Counts the self-crossings of each OBJ mesh: edges that pass through a triangle of the same\n"
    "mesh with which they share no vertex (vertices at one position count as one, so UV seams\n"
    "do not count). Reads v and f lines (v, v/vt, v/vt/vn, v//vn, negative indices; polygons\n"
    "are split into fans); every face of a file counts together.\n"
    "Prints one line per file: FILE: N self-crossings (P triangle pairs), T triangles\n"
    "  --quiet   print only the files that have crossings\n"
    "  --help    this text\n"
    "Exit codes: 0 no file has crossings, 1 some file has, 2 bad input (a missing or unreadable\n"
    "file, a malformed number, an index out of range; the message names the file and line).\n";

struct Mesh {
  Eigen::Matrix3Xd x;
  std::vector<std::uint32_t> triangles;
};

struct BadInput {
  std::string message;
};

// The fields of a line after its keyword, split at blanks.
std::vector<std::string_view> fields(std::string_view rest) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < rest.size()) {
    while (i < rest.size() && (rest[i] == ' ' || rest[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < rest.size() && rest[j] != ' ' && rest[j] != '\t') ++j;
    if (j > i) out.push_back(rest.substr(i, j - i));
    i = j;
  }
  return out;
}

double parse_coordinate(std::string_view text, const std::string& where) {
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc{} || ptr != text.data() + text.size() || !std::isfinite(v))
    throw BadInput{where + ": '" + std::string(text) + "' is not a finite number"};
  return v;
}

// A face corner's vertex (the part before any '/'), 0-based; `count` vertices so far.
std::uint32_t parse_corner(std::string_view text, std::size_t count, const std::string& where) {
  const std::string_view index = text.substr(0, text.find('/'));
  long long i = 0;
  const auto [ptr, ec] = std::from_chars(index.data(), index.data() + index.size(), i);
  if (ec != std::errc{} || ptr != index.data() + index.size() || index.empty())
    throw BadInput{where + ": '" + std::string(text) + "' is not a vertex index"};
  const auto n = static_cast<long long>(count);
  const long long resolved = i > 0 ? i - 1 : n + i;  // (negative: counted back from the last vertex)
  if (i == 0 || resolved < 0 || resolved >= n)
    throw BadInput{where + ": vertex index " + std::string(index) + " is out of range (" + std::to_string(count) +
                   " vertices before this line)"};
  return static_cast<std::uint32_t>(resolved);
}

Mesh read_obj(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw BadInput{path + ": is a directory, not an OBJ file"};
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BadInput{path + ": cannot open the file"};
  std::vector<double> coords;
  Mesh mesh;
  std::string line;
  std::vector<std::uint32_t> corners;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string_view> f = fields(line);
    if (f.empty() || (f[0] != "v" && f[0] != "f")) continue;  // (comments, vt, vn, o, g, usemtl, ...)
    const std::string where = path + ":" + std::to_string(number);
    if (f[0] == "v") {  // x y z, and optionally w or a colour
      if (f.size() < 4 || f.size() > 7) throw BadInput{where + ": a vertex needs 3 coordinates"};
      for (std::size_t k = 1; k < f.size(); ++k) {
        const double v = parse_coordinate(f[k], where);
        if (k <= 3) coords.push_back(v);
      }
      continue;
    }
    if (f.size() < 4) throw BadInput{where + ": a face needs at least 3 corners"};
    corners.clear();
    for (std::size_t k = 1; k < f.size(); ++k) corners.push_back(parse_corner(f[k], coords.size() / 3, where));
    for (std::size_t k = 2; k < corners.size(); ++k)
      mesh.triangles.insert(mesh.triangles.end(), {corners[0], corners[k - 1], corners[k]});
  }
  if (in.bad()) throw BadInput{path + ": read error"};
  mesh.x = Eigen::Map<const Eigen::Matrix3Xd>(coords.data(), 3, static_cast<Eigen::Index>(coords.size() / 3));
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  bool quiet = false;
  std::vector<std::string> files;
  bool options_done = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (!options_done && a == "--help") {
      std::fputs(kUsage, stdout);
      return kExitClean;
    }
    if (!options_done && a == "--quiet") quiet = true;
    else if (!options_done && a == "--") options_done = true;
    else if (!options_done && a.size() > 1 && a[0] == '-') {
      std::fprintf(stderr, "clothsim_crossings: error: unknown option '%s'\n%s", argv[i], kUsage);
      return kExitBadInput;
    } else files.emplace_back(a);
  }
  if (files.empty()) {
    std::fprintf(stderr, "clothsim_crossings: error: no OBJ file given\n%s", kUsage);
    return kExitBadInput;
  }
  // Every file is read before anything is printed: bad input writes its message alone.
  std::string report;
  bool any = false;
  for (const std::string& path : files) {
    Mesh mesh;
    try {
      mesh = read_obj(path);
    } catch (const BadInput& e) {
      std::fprintf(stderr, "clothsim_crossings: error: %s\n", e.message.c_str());
      return kExitBadInput;
    }
    const clothsim::CrossingCount c = clothsim::count_self_crossings(mesh.x, mesh.triangles);
    any |= c.crossings > 0;
    if (quiet && c.crossings == 0) continue;
    report += path + ": " + std::to_string(c.crossings) + " self-crossings (" + std::to_string(c.triangle_pairs) +
              " triangle pairs), " + std::to_string(mesh.triangles.size() / 3) + " triangles" +
              (c.touches > 0 ? "; " + std::to_string(c.touches) + " places where an edge touches a triangle" : "") + "\n";
  }
  std::fputs(report.c_str(), stdout);
  return any ? kExitCrossings : kExitClean;
}
