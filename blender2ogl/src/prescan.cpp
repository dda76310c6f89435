// A light check of .obj text before assimp reads it. assimp's OBJ importer accepts binary
// garbage, truncated lines and out-of-range indices silently (or crashes); this pass only
// tokenizes lines to give a clear message with a line number. It builds no geometry.
#include <cctype>
#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <fstream>
#include <sstream>
#include <string_view>

#include "converter.hpp"
#include "prescan.hpp"

namespace b2o::conv {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, std::size_t line, const std::string& what) {
  throw InputError(file.string() + ":" + std::to_string(line) + ": " + what);
}

// A decimal number as OBJ writers produce it: [+-]digits[.digits][(e|E)[+-]digits].
bool parse_number(std::string_view t, double& value) {
  std::size_t i = 0;
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  std::size_t digits = 0;
  while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++digits;
  if (i < t.size() && t[i] == '.') {
    ++i;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    std::size_t exp_digits = 0;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++exp_digits;
    if (exp_digits == 0) return false;
  }
  if (i != t.size()) return false;
  // Only a long mantissa or an exponent can leave float range; assimp reads floats.
  value = 0.0;
  if (t.size() > 30 || t.find_first_of("eE") != std::string_view::npos) {
    const std::string copy(t);
    value = std::strtod(copy.c_str(), nullptr);
    if (std::fabs(value) > static_cast<double>(std::numeric_limits<float>::max()))
      value = std::numeric_limits<double>::infinity();
  }
  return true;
}

// The most corners of a face assimp reads (AI_MAX_FACE_INDICES).
constexpr std::size_t kMaxFaceCorners = 0x7fff;

// The OBJ statements of freeform curves and surfaces (the spec's "free-form geometry").
bool is_freeform(std::string_view key) {
  for (std::string_view k : {"cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole",
                             "scrv", "sp", "end", "con"})
    if (key == k) return true;
  return false;
}

bool parse_int(std::string_view t, long long& value) {
  if (t.empty()) return false;
  std::size_t i = (t[0] == '-' || t[0] == '+') ? 1 : 0;
  if (i == t.size() || t.size() > 12) return false;
  long long v = 0;
  for (std::size_t k = i; k < t.size(); ++k) {
    if (t[k] < '0' || t[k] > '9') return false;
    v = v * 10 + (t[k] - '0');
  }
  value = t[0] == '-' ? -v : v;
  return true;
}

bool is_number_like(std::string_view t) {
  double ignored = 0;
  if (parse_number(t, ignored)) return true;
  // nan/inf spelled out, to report them as such rather than as garbage
  std::string lower;
  for (char c : t) lower += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return lower.find("nan") != std::string::npos || lower.find("inf") != std::string::npos;
}

}  // namespace

ObjScan prescan_obj_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw InputError(file.string() + ": is a directory, not a model file");
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(file.string() + ": cannot open: " + std::strerror(errno));
  std::string text(static_cast<std::size_t>(in.tellg()), '\0');
  in.seekg(0);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (!in) throw InputError(file.string() + ": cannot read");

  ObjScan scan;
  std::string_view rest(text);
  if (rest.size() >= 2 && ((rest[0] == '\xFE' && rest[1] == '\xFF') || (rest[0] == '\xFF' && rest[1] == '\xFE')))
    fail(file, 1, "UTF-16 text is not supported; save the file as UTF-8 (Blender does)");
  // A UTF-8 byte-order mark: assimp would read it as part of the first statement (and drop
  // that statement); it gets the text without it.
  struct Cut {
    std::size_t at = 0, length = 0;  // bytes of the file assimp does not get
    std::string instead;             // and what it gets there
  };
  std::vector<Cut> cuts;  // in file order
  if (rest.substr(0, 3) == "\xEF\xBB\xBF") {
    rest.remove_prefix(3);
    cuts.push_back({0, 3, {}});
  }

  std::size_t line_no = 0;
  std::string current_group;
  // assimp's OBJ state, to catch names it would resolve to the wrong object: the object that
  // takes faces (the last `o`/`g` that made or found one) and the active group (`g` only).
  std::string owner, intended, active_group, misplaced;  // misplaced: why owner != intended
  bool in_pin_object = false;
  std::string joined;
  std::vector<std::string_view> tok;
  std::size_t freeform = 0, freeform_line = 0;  // freeform statements cut, the first one's line
  // Per object name: the vertices written under it, whether a face uses one of them, and its
  // first line (an object of loose vertices is left out by assimp: warned below). Faces may
  // come under another name than their vertices (Blender's Material Groups: `o Cube`, then
  // `g Cube_Cube_Material` with the faces).
  struct Made {
    std::size_t vertices = 0, line = 0;
    bool used = false;
  };
  std::map<std::string, Made> made;
  Made outside;  // the vertices written under no object name
  std::vector<Made*> vertex_object;  // per `v`: the object it was written under (`outside`: none)
  std::vector<std::uint8_t> vertex_used;  // per `v`: whether a face uses it
  // Faces with no material: Blender 4 writes no `usemtl` in an object without materials, and
  // assimp gave such faces another object's material (or the library's first). A face before
  // any `usemtl` of the file, or after an `o` without one, is given assimp's default material
  // (a `g` keeps the material before it, as OBJ reads).
  bool no_material = true;
  // Whether Blender wrote the file (its exporters start with "# Blender"), and a `g` since the
  // last face that vertices then follow
  const std::size_t first_text = text.find_first_not_of(" \t\r\n");
  const bool blender_export = first_text != std::string_view::npos && text.substr(first_text, 9) == "# Blender";
  bool group_before_vertices = false;
  while (!rest.empty()) {
    ++line_no;
    const std::size_t start_line = line_no;
    std::size_t nl = rest.find('\n');
    std::string_view line = rest.substr(0, nl);
    rest = (nl == std::string_view::npos) ? std::string_view() : rest.substr(nl + 1);
    // A trailing backslash continues the line (rare: only then is the line copied).
    std::string_view body_all = line;
    bool continued = !line.empty() && (line.back() == '\\' || (line.size() > 1 && line.back() == '\r' && line[line.size() - 2] == '\\'));
    // A comment ending in '\' (a Windows folder: "# from C:\models\") would take the next
    // statement into the comment, for assimp too (a face lost): assimp gets it without the '\'.
    if (const std::size_t first = line.find_first_not_of(" \t"); continued && first != std::string_view::npos &&
                                                                    line[first] == '#') {
      continued = false;
      const std::size_t slash = line.rfind('\\');
      cuts.push_back({static_cast<std::size_t>(line.data() - text.data()) + slash, 1, {}});
    }
    if (continued) joined.assign(line);
    while (continued && !joined.empty() && (joined.back() == '\\' || (joined.back() == '\r' && joined.size() > 1 && joined[joined.size() - 2] == '\\')) && !rest.empty()) {
      joined.erase(joined.rfind('\\'));
      nl = rest.find('\n');
      // assimp joins a continuation with the next line that is not empty: another line than here
      if (rest.substr(0, nl).find_first_not_of(" \t\r\f\v") == std::string_view::npos)
        fail(file, start_line, "line continuation ('\\' at the end) followed by an empty line");
      joined.append(rest.substr(0, nl));
      rest = (nl == std::string_view::npos) ? std::string_view() : rest.substr(nl + 1);
      ++line_no;
    }
    if (continued) body_all = joined;
    // One pass: binary bytes, the comment, the tokens.
    tok.clear();
    std::size_t tok_start = std::string_view::npos, end = body_all.size();
    for (std::size_t i = 0; i < end; ++i) {
      const unsigned char c = static_cast<unsigned char>(body_all[i]);
      if (c > ' ') {
        if (c == '#') {
          end = i;  // (bytes after '#' are still checked below)
          break;
        }
        if (tok_start == std::string_view::npos) tok_start = i;
        continue;
      }
      if (c != ' ' && c != '\t' && c != '\r' && c != '\f' && c != '\v') {
        const char* hex = "0123456789abcdef";
        fail(file, start_line, std::string("binary data (byte 0x") + hex[c >> 4] + hex[c & 15] + ") in a text model file");
      }
      // assimp ends a line at a lone '\r'; this scan would see another line than it does
      if (c == '\r' && i + 1 < body_all.size())
        fail(file, start_line, "carriage return inside a line (old Mac line endings are not supported)");
      if (tok_start != std::string_view::npos) {
        tok.push_back(body_all.substr(tok_start, i - tok_start));
        tok_start = std::string_view::npos;
      }
    }
    if (tok_start != std::string_view::npos) tok.push_back(body_all.substr(tok_start, end - tok_start));
    for (std::size_t i = end; i < body_all.size(); ++i) {
      const unsigned char c = static_cast<unsigned char>(body_all[i]);
      if (c == '\r' && i + 1 < body_all.size())
        fail(file, start_line, "carriage return inside a line (old Mac line endings are not supported)");
      if (c < 0x20 && c != '\t' && c != '\r' && c != '\f' && c != '\v') {
        const char* hex = "0123456789abcdef";
        fail(file, start_line, std::string("binary data (byte 0x") + hex[c >> 4] + hex[c & 15] + ") in a text model file");
      }
    }
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    // MSVC writes infinity and NaN as 1.#INF, -1.#IND, 1.#QNAN: the '#' read as a comment
    // left "'v' needs 3 coordinates, found 1"
    if (end < body_all.size() && end > 0 && static_cast<unsigned char>(body_all[end - 1]) > ' ' && key.size() <= 2 &&
        key[0] == 'v') {
      std::string after(body_all.substr(end + 1, 4));
      for (char& ch : after) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
      if (after.rfind("INF", 0) == 0 || after.rfind("IND", 0) == 0 || after.rfind("QNAN", 0) == 0 ||
          after.rfind("SNAN", 0) == 0) {
        const std::size_t to = body_all.find_first_of(" \t\r", end);
        fail(file, start_line, "non-finite number " + quote_input(std::string(tok.back()) +
                                                          std::string(body_all.substr(end, to == std::string_view::npos ? std::string_view::npos : to - end))) +
                                   " (MSVC's spelling of infinity or NaN)");
      }
    }
    // A comment after the numbers of a v/vt/vn/f/l/p statement: assimp would read it as
    // numbers (f 1 2 3 # x: "Invalid face index"); it is given the line without it.
    if (end < body_all.size() && (key == "v" || key == "vt" || key == "vn" || key == "vp" || key == "f" ||
                                  key == "fo" || key == "l" || key == "p")) {
      if (continued) fail(file, start_line, "a comment on a continued line ('\\' at the end) is not supported");
      const std::size_t from = static_cast<std::size_t>(tok.back().data() + tok.back().size() - text.data());
      std::size_t to = static_cast<std::size_t>(line.data() + line.size() - text.data());
      if (!line.empty() && line.back() == '\r') --to;
      cuts.push_back({from, to - from, {}});
    }
    double values[4] = {0, 0, 0, 0};
    auto numbers = [&](std::size_t min_count, const char* what) -> const double* {
      if (tok.size() - 1 < min_count)
        fail(file, start_line, quote_input(key) + " needs " + std::to_string(min_count) + " " + what +
                                   ", found " + std::to_string(tok.size() - 1) + " (truncated file?)");
      for (std::size_t k = 1; k < tok.size(); ++k) {
        double v = 0;
        if (!parse_number(tok[k], v)) {
          if (is_number_like(tok[k])) fail(file, start_line, "non-finite number " + quote_input(tok[k]));
          fail(file, start_line, "malformed number " + quote_input(tok[k]));
        }
        if (!std::isfinite(v)) fail(file, start_line, "number out of range " + quote_input(tok[k]));
        // '.5': assimp 5.2.5 takes no number for it and skips the whole statement (a vertex
        // lost, every later index shifted); it is given '0.5'
        if (tok[k][0] == '.') {
          if (continued) fail(file, start_line, "a number starting with '.' on a continued line ('\\' at the end) is not supported; write " + quote_input("0" + std::string(tok[k])));
          cuts.push_back({static_cast<std::size_t>(tok[k].data() - text.data()), 0, "0"});
        }
        if (k <= 4) values[k - 1] = v;
      }
      return values;
    };
    // Counts assimp reads right; others it misreads (a vertex skipped: later indices shift)
    // or refuses without a line. Nothing else may follow the numbers.
    auto count_in = [&](std::initializer_list<std::size_t> allowed, const char* what) {
      for (std::size_t n : allowed)
        if (tok.size() - 1 == n) return;
      fail(file, start_line, quote_input(key) + " takes " + what + ", found " + std::to_string(tok.size() - 1));
    };
    if (key == "v") {
      const double* v = numbers(3, "coordinates");
      count_in({3, 4, 6}, "3 coordinates (x y z), 4 (x y z w) or 6 (x y z r g b)");
      if (tok.size() == 5 && std::strtod(std::string(tok[4]).c_str(), nullptr) == 0.0) fail(file, start_line, "'v' with w = 0 (a point at infinity)");
      ++scan.positions;
      if (group_before_vertices) no_material = true, group_before_vertices = false;
      // (vertices before any `o`/`g`, or under a bare `o`: `outside`, for the loose-vertex check)
      Made* under = current_group.empty() ? &outside : &made[current_group];
      if (under->vertices++ == 0 && under == &outside) outside.line = start_line;
      vertex_object.push_back(under);
      vertex_used.push_back(0);
      if (in_pin_object) {
        // (the values are only parsed here: pin points need them, nothing else does)
        double xyz[3];
        for (int k = 0; k < 3; ++k) xyz[k] = std::strtod(std::string(tok[static_cast<std::size_t>(k) + 1]).c_str(), nullptr);
        v = xyz;
        auto& pts = scan.pin_points[current_group];
        pts.insert(pts.end(), {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])});
      }
    } else if (key == "vt") {
      numbers(1, "coordinate");
      count_in({2, 3}, "2 coordinates (u v) or 3 (u v w)");
      ++scan.texcoords;
    } else if (key == "vn") {
      numbers(3, "coordinates");
      count_in({3}, "3 coordinates (x y z)");
      ++scan.normals;
    } else if (key == "vp") {
      numbers(1, "coordinate");
    } else if (key == "f" || key == "fo" || key == "l" || key == "p") {
      const bool face = key == "f" || key == "fo";
      const std::size_t need = face ? 3 : 1;
      // assimp refuses larger faces without naming the line ("Face 0 has too many faces")
      if (face && tok.size() - 1 > kMaxFaceCorners)
        fail(file, start_line, "a face with " + std::to_string(tok.size() - 1) + " corners (at most " +
                                   std::to_string(kMaxFaceCorners) + ")");
      if (tok.size() - 1 < need)
        fail(file, start_line, quote_input(key) + " needs at least " + std::to_string(need) +
                                   " vertices, found " + std::to_string(tok.size() - 1));
      int form = -1;  // the first corner's fields: 1 v, 2 v/vt, 3 v//vn, 4 v/vt/vn
      for (std::size_t k = 1; k < tok.size(); ++k) {
        const std::string_view ref = tok[k];
        std::size_t part = 0, pos = 0;
        int fields = 1;
        bool ended = false;  // else a 3rd slash follows the 3 fields ("1/1/1/1")
        while (part < 3) {
          const std::size_t slash = ref.find('/', pos);
          const std::string_view field = ref.substr(pos, slash == std::string_view::npos ? std::string_view::npos : slash - pos);
          const std::size_t count = part == 0 ? scan.positions : part == 1 ? scan.texcoords : scan.normals;
          if (!(field.empty() && part > 0)) {
            long long idx = 0;
            // ('+3' is no index for assimp: it read `f 1 2 +3` as four corners)
            if ((!field.empty() && field[0] == '+') || !parse_int(field, idx) || idx == 0)
              fail(file, start_line, "malformed vertex reference " + quote_input(ref));
            // ('01': assimp read `f 01 02 03` as four triangles of other vertices)
            if (const std::size_t d = field[0] == '-' ? 1 : 0; field.size() > d + 1 && field[d] == '0')
              fail(file, start_line, "vertex reference " + quote_input(ref) + " has a leading zero (assimp misreads it); write " +
                                         quote_input((d ? "-" : "") + std::to_string(idx < 0 ? -idx : idx)));
            if (part == 1) fields |= 2;
            if (part == 2) fields |= 4;
            const long long n = static_cast<long long>(count);
            if (part == 0 && key != "l" && key != "p" && idx <= n && idx >= -n) {
              const auto vi = static_cast<std::size_t>(idx > 0 ? idx - 1 : n + idx);
              vertex_object[vi]->used = true;
              vertex_used[vi] = 1;
            }
            if (idx > n || idx < -n)
              fail(file, start_line, std::string(part == 0 ? "vertex" : part == 1 ? "texture coordinate" : "normal") +
                                         " index " + std::to_string(idx) + " out of range (" + std::to_string(count) +
                                         " defined so far)");
          }
          ++part;
          if (slash == std::string_view::npos) {
            ended = true;
            break;
          }
          pos = slash + 1;
        }
        if (!ended || (pos < ref.size() && ref.find('/', pos) != std::string_view::npos))
          fail(file, start_line, "malformed vertex reference " + quote_input(ref));
        // assimp takes the first corner's form for all: `f 1/2 2 3/1` gave vertex 2 the third
        // corner's texture coordinate
        const int this_form = fields == 1 ? 1 : fields == 3 ? 2 : fields == 5 ? 3 : 4;
        if (form < 0) form = this_form;
        if (this_form != form)
          fail(file, start_line, "a " + quote_input(key) + " statement mixes vertex reference forms (" +
                                     quote_input(tok[1]) + " and " + quote_input(ref) +
                                     "): assimp would give texture coordinates or normals to the wrong corners; "
                                     "write every corner the same way (v, v/vt, v//vn or v/vt/vn)");
      }
      if (face && owner != intended) throw InputError(misplaced);
      group_before_vertices = false;
      if (face && no_material) {
        cuts.push_back({static_cast<std::size_t>(line.data() - text.data()), 0, "usemtl DefaultMaterial\n"});
        no_material = false;
      }
      if (face) ++scan.faces; else ++scan.lines_points;
    } else if (key == "o" || key == "g") {
      ++scan.groups;
      // (a new object resets the material below; a `g` of a Blender export that vertices
      // follow is one too: Blender 4's "Object Groups" writes `g Obj_Mesh` for `o Obj`)
      if (blender_export && key == "g") group_before_vertices = true;
      // The name as the file writes it: the rest of the line, spaces inside kept (Blender
      // writes `o My Cloth`), up to a comment (a '#' after a space) and trimmed.
      current_group.clear();
      std::size_t name_at = std::string_view::npos, raw_end = body_all.size();
      if (tok.size() > 1) {
        name_at = static_cast<std::size_t>(tok[1].data() - body_all.data());
        std::size_t stop = body_all.size(), hash = std::string_view::npos;
        for (std::size_t i = name_at; i < body_all.size(); ++i)
          if (body_all[i] == '#' && (body_all[i - 1] == ' ' || body_all[i - 1] == '\t')) {
            stop = hash = i;
            break;
          }
        if (!body_all.empty() && body_all.back() == '\r') raw_end = body_all.size() - 1;
        stop = std::min(stop, raw_end);
        while (stop > name_at && (body_all[stop - 1] == ' ' || body_all[stop - 1] == '\t' ||
                                  body_all[stop - 1] == '\f' || body_all[stop - 1] == '\v'))
          --stop;
        current_group.assign(body_all.substr(name_at, stop - name_at));
        // Blender allows '#' in names and writes it as it is; a '#' after a space is read as
        // the start of a comment, as in the OBJ spec
        if (hash < raw_end && !current_group.empty()) {
          scan.warnings.push_back(file.string() + ":" + std::to_string(start_line) + ": object name read as " +
                                  quote_input(current_group) + ": " +
                                  quote_input(std::string(body_all.substr(hash, raw_end - hash))) +
                                  " is a comment in OBJ; if it is part of the name, rename the object without "
                                  "' #' (an -a or CLOTH name and a '_pins' helper must use " +
                                  quote_input(current_group) + ")");
        }
        if (!current_group.empty() && made.count(current_group) == 0) made[current_group].line = start_line;
      }
      // assimp reads an `o` name up to its first space and a `g` name with the rest of the
      // line (comment and trailing spaces included); it is given the name encoded (spaces,
      // '#' and '%' as %XX, see decode_object_name) and the import decodes it.
      const std::string encoded = encode_object_name(current_group);
      // assimp's aiString holds 1023 bytes: a longer name would silently become ""
      if (encoded.size() > 1023)
        fail(file, start_line, "object name longer than 1023 bytes (" + std::to_string(encoded.size()) +
                                   (encoded.size() != current_group.size() ? " with its spaces encoded" : "") +
                                   "): " + quote_input(current_group));
      if (name_at != std::string_view::npos && body_all.substr(name_at, raw_end - name_at) != encoded) {
        if (continued) fail(file, start_line, "an object name on a continued line ('\\' at the end) is not supported");
        const std::size_t from = static_cast<std::size_t>(body_all.data() - text.data()) + name_at;
        cuts.push_back({from, raw_end - name_at, encoded});
      }
      in_pin_object = is_pin_object_name(current_group);
      if (in_pin_object) scan.pin_points[current_group];  // (a helper without vertices is an error)
      // Repeated names. assimp 5.2.5 finds an `o` name it has seen (from `o` or `g`) and makes
      // that object current but keeps adding faces to the mesh before it ("owner"); a `g` equal
      // to the active group is ignored, so after an `o` in between its faces go to that `o`'s
      // object. A face read while the owner is not the object the file names is refused, at
      // the line that named it. A `g` repeated after another group makes a second object of
      // that name (its faces are right): a warning.
      const std::string& name = current_group;
      auto seen = scan.object_lines.find(name);
      const std::string first =
          seen == scan.object_lines.end() ? "" : " (first at line " + std::to_string(seen->second.front()) + ")";
      const std::string where = file.string() + ":" + std::to_string(start_line) + ": ";
      if (key == "o" && !(name.empty() || name == intended)) no_material = true;
      if (name.empty() || name == intended) {
        // a continuation (an empty name is left to assimp as before; a `g` with the current
        // object's name makes an object of the same name, which the import joins to it)
        if (key == "g" && !name.empty()) active_group = name;
      } else if (key == "o" && seen != scan.object_lines.end()) {
        intended = name;
        misplaced = where + "object name " + quote_input(name) + " repeated" + first + ": assimp would give its faces to " +
                    quote_input(owner) + "; give each object its own name";
      } else if (key == "g" && name == active_group) {
        intended = name;
        misplaced = where + "group " + quote_input(name) + " repeated" + first + " after object " + quote_input(owner) +
                    ": assimp would give its faces to " + quote_input(owner) + "; give each object its own name";
      } else {
        if (seen != scan.object_lines.end())
          scan.warnings.push_back(where + "group " + quote_input(name) + " repeated" + first +
                                  ": kept as another object of the same name");
        scan.object_lines[name].push_back(start_line);
        owner = intended = name;
        if (key == "g") active_group = name;
      }
    } else if (key == "usemtl") {
      // as assimp reads it: the rest of the line, comment included, trimmed
      std::string name(body_all.substr(static_cast<std::size_t>(key.data() + key.size() - body_all.data())));
      const std::size_t a = name.find_first_not_of(" \t\r\f\v"), b = name.find_last_not_of(" \t\r\f\v");
      name = a == std::string::npos ? std::string() : name.substr(a, b - a + 1);
      if (!name.empty()) scan.usemtl.emplace_back(name, start_line);
      // (Blender 4 writes `usemtl ` with no name for an empty material slot: no material)
      no_material = name.empty();
    } else if (key == "lod") {
      // A display attribute (level of detail) nothing here uses; assimp 5.2.5 took it for an
      // `l` line and failed ("bad vertex index", no line): it gets the line blank.
      const std::size_t at = static_cast<std::size_t>(line.data() - text.data());
      if (continued) fail(file, start_line, "'lod' on a continued line ('\\' at the end) is not supported");
      cuts.push_back({at, line.size() - (!line.empty() && line.back() == '\r' ? 1 : 0), {}});
    } else if (is_freeform(key)) {
      // Freeform geometry (Blender's "Curves as NURBS"): assimp does not read it, and misread
      // what follows (a face after `cstype` was lost, `curv` failed without a line). It has
      // no faces to draw: assimp gets the line blank (its line breaks kept), with one warning.
      const std::size_t at = static_cast<std::size_t>(line.data() - text.data());
      const std::size_t to = rest.empty() ? text.size() : static_cast<std::size_t>(rest.data() - text.data()) - 1;
      cuts.push_back({at, to - at, std::string(static_cast<std::size_t>(std::count(text.begin() + static_cast<std::ptrdiff_t>(at),
                                                                                   text.begin() + static_cast<std::ptrdiff_t>(to), '\n')),
                                               '\n')});
      if (freeform++ == 0) freeform_line = start_line;
    } else if (std::string_view("flpog").find(key[0]) != std::string_view::npos ||
               (key[0] == 'v' && (key[1] == 't' || key[1] == 'n'))) {
      // assimp reads a statement by its first letter (v: its first two): `fx 1 2 3` was drawn
      // as a face, `vtx 1 1` failed without a line, `ox` named an object. Other unknown
      // statements (`vD`, `shadow_obj`) assimp ignores, and so does this scan.
      fail(file, start_line, "unknown statement " + quote_input(key) + " (assimp would read it as " +
                                 quote_input(std::string(1, key[0])) + "): fix or remove the line");
    } else if (key == "mtllib") {
      // A name may hold spaces; assimp takes the rest of the line.
      const std::string_view body = body_all.substr(0, end);
      std::string name(body.substr(body.find("mtllib") + 6));
      while (!name.empty() && (name.front() == ' ' || name.front() == '\t')) name.erase(0, 1);
      while (!name.empty() && (name.back() == ' ' || name.back() == '\t' || name.back() == '\r')) name.pop_back();
      // Several libraries on one line (the OBJ spec allows it; assimp reads the rest of the
      // line as one name): when no file has the whole name but every word names one.
      std::vector<std::string> libs{name};
      const std::filesystem::path folder = file.parent_path();
      if (!continued && name.find_first_of(" \t") != std::string::npos &&
          !std::filesystem::exists(folder / name, ec)) {
        std::vector<std::string> words;
        std::istringstream split(name);
        for (std::string w; split >> w;) words.push_back(w);
        // (or every word is named *.mtl: then a missing one is reported by its own name)
        const auto mtl_named = [](const std::string& w) {
          return w.size() > 4 && (w.compare(w.size() - 4, 4, ".mtl") == 0 || w.compare(w.size() - 4, 4, ".MTL") == 0);
        };
        if (std::all_of(words.begin(), words.end(),
                        [&](const std::string& w) { return std::filesystem::is_regular_file(folder / w, ec); }) ||
            std::all_of(words.begin(), words.end(), mtl_named))
          libs = words, name = words.front();
      }
      // assimp opens the rest of the line as it is: trailing spaces or a comment lost the
      // library (a default grey material, no warning); it is given the name alone
      if (!continued && !name.empty()) {
        const std::size_t at =
            static_cast<std::size_t>(body.find(name, body.find("mtllib") + 6) + (body.data() - text.data()));
        std::size_t to = static_cast<std::size_t>(line.data() + line.size() - text.data());
        if (!line.empty() && line.back() == '\r') --to;
        if (to > at + name.size()) cuts.push_back({at + name.size(), to - at - name.size(), {}});
      }
      for (std::size_t k = 0; k < libs.size(); ++k) {
        scan.mtllibs.push_back(libs[k]);
        scan.mtllib_lines.push_back(start_line);
        scan.mtllib_joined.push_back(k > 0);
      }
    }
  }
  // Objects of loose vertices (no faces): assimp drops them. A pin helper is read above by
  // its name; any other one is left out, which the user is told.
  for (const auto& [name, m] : made)
    if (m.vertices > 0 && !m.used && !is_pin_object_name(name)) {
      const bool pin_like = name.find("_pins") != std::string::npos || name.find(".pins") != std::string::npos;
      scan.warnings.push_back(
          file.string() + ":" + std::to_string(m.line) + ": object " + quote_input(name) + " has " +
          std::to_string(m.vertices) + " vertices and no face uses them: left out (only faces are drawn)" +
          (pin_like ? std::string("; a pin helper is found by the exact name '<cloth>_pins' (Blender 4's "
                                  "'Object Groups' and the legacy exporter write 'Object_Mesh': untick Object "
                                  "Groups, or give the mesh data the object's name)")
                    : std::string()));
    }
  // Loose vertices of an object that has faces (the 2016 skirt's 353rd, at the origin): assimp
  // reads only the vertices faces use, so they get no mass and are not drawn.
  {
    struct Loose {
      std::size_t count = 0, first = 0;  // first: its 1-based `v` number
    };
    std::map<const Made*, Loose> loose;
    for (std::size_t i = 0; i < vertex_used.size(); ++i)
      if (!vertex_used[i] && vertex_object[i]->used) {
        Loose& l = loose[vertex_object[i]];
        if (l.count++ == 0) l.first = i + 1;
      }
    if (const auto it = loose.find(&outside); it != loose.end())
      scan.warnings.push_back(file.string() + ":" + std::to_string(outside.line) + ": " +
                              std::to_string(it->second.count) + " of the " + std::to_string(outside.vertices) +
                              " vertices before any object name " + (it->second.count == 1 ? "is" : "are") +
                              " in no face (the first: vertex " + std::to_string(it->second.first) +
                              "): left out (no mass, not drawn)");
    for (const auto& [name, m] : made)
      if (const auto it = loose.find(&m); it != loose.end() && !is_pin_object_name(name))  // (a helper's are pins)
        scan.warnings.push_back(file.string() + ":" + std::to_string(m.line) + ": object " + quote_input(name) + ": " +
                                std::to_string(it->second.count) + " of its " + std::to_string(m.vertices) +
                                " vertices " + (it->second.count == 1 ? "is" : "are") +
                                " in no face (the first: vertex " + std::to_string(it->second.first) +
                                "): left out (no mass, not drawn)");
  }
  if (freeform > 0)
    scan.warnings.push_back(file.string() + ":" + std::to_string(freeform_line) + ": " + std::to_string(freeform) +
                            " freeform curve/surface statement" + (freeform == 1 ? "" : "s") +
                            " (cstype, curv, surf, ...) ignored: only faces are drawn (Blender: export with "
                            "'Curves as NURBS' off, or convert the curve to a mesh)");
  if (!cuts.empty()) {
    // (a line's comment is cut before its numbers are read)
    std::stable_sort(cuts.begin(), cuts.end(), [](const Cut& a, const Cut& b) { return a.at < b.at; });
    scan.cleaned = true;
    scan.clean_text.reserve(text.size());
    std::size_t from = 0;
    for (const Cut& c : cuts) {
      scan.clean_text.append(text, from, c.at - from);
      scan.clean_text.append(c.instead);
      from = c.at + c.length;
    }
    scan.clean_text.append(text, from, std::string::npos);
  }
  if (scan.positions == 0) throw InputError(file.string() + ": no vertices (empty or not an OBJ file)");
  if (scan.faces == 0) throw InputError(file.string() + ": no faces: nothing to draw (points and lines are not supported)");
  return scan;
}

MtlScan prescan_mtl_file(const std::filesystem::path& file, const std::filesystem::path& model_folder) {
  MtlScan scan;
  std::vector<MapKd>& maps = scan.maps;
  std::map<std::string, std::size_t> defined;  // name -> first line
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open: " + std::strerror(errno));
  std::string line;
  std::size_t line_no = 0;
  bool in_material = false;
  while (std::getline(in, line)) {
    ++line_no;
    // a UTF-8 byte-order mark (assimp is given the file without it)
    if (line_no == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) {
      line.erase(0, 3);
      scan.cleaned = true;
    }
    const std::size_t clean_from = scan.clean_text.size();
    scan.clean_text.append(line).push_back('\n');
    std::vector<std::string_view> tok;
    std::size_t start = std::string::npos;
    for (std::size_t i = 0; i <= line.size(); ++i) {
      const unsigned char c = i < line.size() ? static_cast<unsigned char>(line[i]) : ' ';
      // Vertical tab and form feed too: assimp does not skip them, so "\vnewmtl" is no newmtl
      // to it, and a statement after it crashed assimp 5.2.5 (found by the long fuzz run).
      if (c < 0x20 && c != '\t' && c != '\r') {
        const char* hex = "0123456789abcdef";
        fail(file, line_no, std::string("binary data (byte 0x") + hex[c >> 4] + hex[c & 15] + ") in a material file");
      }
      if (c == '\r' && i + 1 < line.size())
        fail(file, line_no, "carriage return inside a line (old Mac line endings are not supported)");
      const bool space = c == ' ' || c == '\t' || c == '\r';
      if (!space && start == std::string::npos) start = i;
      if (space && start != std::string::npos) {
        tok.emplace_back(line.data() + start, i - start);
        start = std::string::npos;
      }
    }
    if (tok.empty() || tok[0][0] == '#') continue;
    const std::string_view key = tok[0];
    if (key == "newmtl") {
      in_material = true;
      // as assimp reads it: the rest of the line, trimmed ("newmtl" alone: its default name)
      std::string name = line.substr(static_cast<std::size_t>(tok[0].data() + tok[0].size() - line.data()));
      const std::size_t a = name.find_first_not_of(" \t\r"), b = name.find_last_not_of(" \t\r");
      name = a == std::string::npos ? std::string("DefaultMaterial") : name.substr(a, b - a + 1);
      if (auto [it, added] = defined.try_emplace(name, line_no); !added)
        scan.warnings.push_back(file.string() + ":" + std::to_string(line_no) + ": material " + quote_input(name) +
                                " defined again (first at line " + std::to_string(it->second) +
                                "); assimp merges the two, the later values win");
      else
        scan.materials.push_back(name);
      continue;
    }
    if (!in_material) fail(file, line_no, quote_input(key) + " before any 'newmtl'");
    auto replace_line = [&](const std::string& with) {
      scan.clean_text.resize(clean_from);
      scan.clean_text.append(with).push_back('\n');
      scan.cleaned = true;
    };
    if (key.size() == 6 && (key[0] | 0x20) == 'm' && (key[1] | 0x20) == 'a' && (key[2] | 0x20) == 'p' &&
        key[3] == '_' && (key[4] | 0x20) == 'k' && (key[5] | 0x20) == 'd') {  // map_Kd in any case
      // assimp is given `map_Kd <file>`: it misread options with fewer than 3 numbers
      // (`-s 2 2`), or ones it does not know (`-type`, `-cc`), as part of the name and lost
      // the texture; trailing spaces too. The scale, offset and turbulence are not drawn.
      const std::string where = file.string() + ":" + std::to_string(line_no) + ": ";
      std::size_t k = 1;
      bool transformed = false;
      while (k < tok.size() && tok[k].size() > 1 && tok[k][0] == '-' && !(tok[k][1] >= '0' && tok[k][1] <= '9')) {
        const std::string option(tok[k]);
        std::size_t most = 0, least = 0;  // numbers it takes; or one word (on/off, a type, a channel)
        bool word = false;
        if (option == "-s" || option == "-o" || option == "-t") most = 3, least = 1;
        else if (option == "-mm") most = 2, least = 1;
        else if (option == "-bm" || option == "-boost" || option == "-texres") most = least = 1;
        else if (option == "-blendu" || option == "-blendv" || option == "-cc" || option == "-clamp" ||
                 option == "-imfchan" || option == "-type")
          word = true;
        else if (k + 1 == tok.size())
          break;  // the last word: a file name that starts with '-' (given to assimp as ./-name)
        else
          fail(file, line_no, "unknown map_Kd option " + quote_input(option) +
                                  " (known: -s -o -t -mm -bm -boost -texres -blendu -blendv -cc -clamp -imfchan "
                                  "-type; a file name starting with '-' is written ./" + option + ")");
        ++k;
        if (word) {
          if (k >= tok.size()) fail(file, line_no, "map_Kd option " + quote_input(option) + " needs a value");
          ++k;
          continue;
        }
        std::size_t got = 0;
        double v = 0.0;
        // (a texture named like a number, after all the option's numbers, stays the name)
        while (got < most && k + 1 < tok.size() && parse_number(tok[k], v)) {
          v = std::strtod(std::string(tok[k]).c_str(), nullptr);  // (parse_number gives only large values)
          const double neutral = option == "-s" ? 1.0 : 0.0;
          if ((option == "-s" || option == "-o" || option == "-t") && v != neutral) transformed = true;
          ++got, ++k;
        }
        if (got < least) fail(file, line_no, "map_Kd option " + quote_input(option) + " needs a number");
      }
      if (k >= tok.size()) fail(file, line_no, "map_Kd without a file name");
      std::string name = line.substr(static_cast<std::size_t>(tok[k].data() - line.data()));
      while (!name.empty() && (name.back() == ' ' || name.back() == '\t' || name.back() == '\r')) name.pop_back();
      if (name[0] == '-') name = "./" + name;  // (assimp would take it for an option)
      // A relative name is relative to this .mtl: from another folder than the model's it is
      // given as relative to the model's folder, which the import reads textures from.
      std::string rel = name;
      std::replace(rel.begin(), rel.end(), '\\', '/');
      const std::filesystem::path mtl_folder = file.parent_path();
      std::error_code ec;
      if (!model_folder.empty() && !std::filesystem::path(rel).is_absolute() && !rel.empty() &&
          !std::filesystem::equivalent(mtl_folder.empty() ? "." : mtl_folder,
                                       model_folder.empty() ? "." : model_folder, ec) &&
          std::filesystem::is_regular_file(mtl_folder / rel, ec)) {
        // the .mtl's folder as the mtllib line names it from the model's folder, '..' and all
        // (normalised as text, 'link/..' through a symbolic link would be another folder)
        const std::filesystem::path prefix = file.lexically_relative(model_folder).parent_path();
        const std::filesystem::path from_model = prefix / rel;
        if (!prefix.empty() && std::filesystem::is_regular_file(model_folder / from_model, ec))
          name = from_model.generic_string();
      }
      if (transformed)
        scan.warnings.push_back(where + "the texture's scale, offset or turbulence (-s, -o, -t) are not drawn: " +
                                quote_input(name) + " is mapped as the UVs say");
      maps.push_back({name, line_no});
      replace_line("map_Kd " + name);
      continue;
    }
    // Statements the converter does not read are not given to assimp: they are ignored as
    // they would be, and cannot fail it (assimp 5.2.5 stopped on Blender 4's `aniso` with
    // "Cannot parse string \"niso\"", naming no file).
    // (as assimp reads them: K and N in either case, the second letter as written)
    std::string canon(key);
    if (canon.size() == 2 && (canon[0] == 'k' || canon[0] == 'n')) canon[0] = static_cast<char>(canon[0] - 'a' + 'A');
    if (!(canon == "Ka" || canon == "Kd" || canon == "Ks" || canon == "Ke" || canon == "Tf" || canon == "Ns" ||
          canon == "d" || canon == "Tr" || canon == "Ni")) {
      replace_line("");
      continue;
    }
    const bool color = canon == "Ka" || canon == "Kd" || canon == "Ks" || canon == "Ke" || canon == "Tf";
    {
      for (std::size_t k = 1; k < tok.size(); ++k) {
        double v = 0;
        if (tok[k][0] == '#') {
          tok.resize(k);  // a comment
          break;
        }
        if (parse_number(tok[k], v)) {
          if (!std::isfinite(v)) fail(file, line_no, "number out of range " + quote_input(tok[k]));
        } else if (is_number_like(tok[k])) {
          fail(file, line_no, "non-finite value " + quote_input(tok[k]));
        } else {
          // (assimp would fail with "Cannot parse string" naming neither file nor line)
          fail(file, line_no, "malformed number " + quote_input(tok[k]) + " in " + quote_input(key));
        }
      }
      // assimp reads 3 numbers for a color (a missing one fails it) and 1 for the others
      const std::size_t n = tok.size() - 1;
      if (color && n != 3 && n != 1)
        fail(file, line_no, quote_input(key) + " takes 3 numbers (r g b) or 1 (grey), found " + std::to_string(n));
      if (!color && n != 1) fail(file, line_no, quote_input(key) + " takes 1 number, found " + std::to_string(n));
      // One number is a grey (the MTL spec: g = b = r); assimp would read (r, 0, 0).
      if (color && n == 1) {
        std::string grey(key);
        for (int k = 0; k < 3; ++k) grey.append(" ").append(tok[1]);
        if (!line.empty() && line.back() == '\r') grey.push_back('\r');
        scan.clean_text.resize(clean_from);
        scan.clean_text.append(grey).push_back('\n');
        scan.cleaned = true;
      }
    }
  }
  if (!scan.cleaned) scan.clean_text.clear();
  return scan;
}

std::string encode_object_name(const std::string& name) {
  std::string out;
  out.reserve(name.size());
  for (unsigned char c : name) {
    // ('\\': a name ending in one, `o foo\ ` once its spaces were cut, continued the line)
    if (c == ' ' || c == '\t' || c == '\f' || c == '\v' || c == '#' || c == '%' || c == '\\') {
      const char* hex = "0123456789ABCDEF";
      out.push_back('%');
      out.push_back(hex[c >> 4]);
      out.push_back(hex[c & 15]);
    } else {
      out.push_back(static_cast<char>(c));
    }
  }
  return out;
}

std::string decode_object_name(const std::string& name) {
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string out;
  out.reserve(name.size());
  for (std::size_t i = 0; i < name.size(); ++i) {
    if (name[i] == '%' && i + 2 < name.size() && hex(name[i + 1]) >= 0 && hex(name[i + 2]) >= 0) {
      out.push_back(static_cast<char>(hex(name[i + 1]) * 16 + hex(name[i + 2])));
      i += 2;
    } else {
      out.push_back(name[i]);
    }
  }
  return out;
}

bool is_pin_object_name(const std::string& name) {
  auto ends = [&](const char* s) {
    const std::string suffix(s);
    return name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends("_pins") || ends(".pins");
}

std::string pin_target_name(const std::string& name) { return name.substr(0, name.size() - 5); }

}  // namespace b2o::conv
