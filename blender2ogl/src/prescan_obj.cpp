// The pre-scan of a .obj before assimp reads it. assimp's OBJ importer accepts binary garbage,
// truncated lines and out-of-range indices silently (or crashes); this pass only tokenizes
// lines to give a clear message with a line number, and gives assimp the text with what it
// would misread rewritten. It builds no geometry.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

#include "converter.hpp"
#include "prescan.hpp"
#include "prescan_text.hpp"

namespace b2o::conv {
namespace {

// The most corners of a face assimp reads (AI_MAX_FACE_INDICES).
constexpr std::size_t kMaxFaceCorners = 0x7fff;

// The OBJ statements of freeform curves and surfaces (the spec's "free-form geometry").
bool is_freeform(std::string_view key) {
  for (std::string_view k : {"cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole",
                             "scrv", "sp", "end", "con"})
    if (key == k) return true;
  return false;
}

// Whether a line ends in '\' (before a '\r'): it continues on the next line.
bool ends_in_backslash(std::string_view s) {
  return !s.empty() && (s.back() == '\\' || (s.size() > 1 && s.back() == '\r' && s[s.size() - 2] == '\\'));
}

// The file's bytes; refuses a folder or a file it cannot read.
std::string read_model_text(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw InputError(file.string() + ": is a directory, not a model file");
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(file.string() + ": cannot open: " + std::strerror(errno));
  std::string text(static_cast<std::size_t>(in.tellg()), '\0');
  in.seekg(0);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (!in) throw InputError(file.string() + ": cannot read");
  return text;
}

// Bytes of the file replaced in what assimp gets.
struct Cut {
  std::size_t at = 0, length = 0;  // bytes of the file assimp does not get
  std::string instead;             // and what it gets there
};

// Per object name: the vertices written under it, whether a face uses one of them, and its
// first line (an object of loose vertices is left out by assimp: warned). Faces may come under
// another name than their vertices (Blender's Material Groups: `o Cube`, then
// `g Cube_Cube_Material` with the faces).
struct Made {
  std::size_t vertices = 0, line = 0;
  bool used = false;
};

// One statement: its lines (a trailing '\' joins the next), its tokens and where its comment starts.
struct Statement {
  std::string_view line;  // the first line, as in the file
  std::string_view body;  // the whole statement: `line`, or the lines joined
  std::size_t end = 0;    // where a comment starts in `body` (body.size(): none)
  std::size_t line_no = 0;
  bool continued = false;
  std::vector<std::string_view> tok;
  std::string_view key() const { return tok[0]; }  // the keyword (`v`, `f`, `o`, ...)
};

// Where an `o`/`g` name stands in its statement's body.
struct NameSpan {
  std::size_t at = std::string_view::npos, raw_end = 0;  // raw_end: the body's end before a '\r'
};

// Reads a .obj statement by statement into an ObjScan, following assimp's OBJ state.
class ObjPrescan {
 public:
  ObjPrescan(const std::filesystem::path& file, std::string text);
  ObjPrescan(const ObjPrescan&) = delete;
  ObjPrescan& operator=(const ObjPrescan&) = delete;
  ObjScan run();

 private:
  // Where `p` (a pointer into the text) is in the file.
  std::size_t offset(const char* p) const { return static_cast<std::size_t>(p - text_.data()); }
  std::size_t line_end(std::string_view line) const;
  bool next_lines(Statement& st);
  void tokenize(Statement& st) const;
  void check_space_byte(const Statement& st, std::size_t i) const;
  void check_msvc_nonfinite(const Statement& st) const;
  void cut_number_comment(const Statement& st);
  void statement(const Statement& st);
  void check_numbers(const Statement& st, std::size_t min_count, const char* what);
  void check_count(const Statement& st, std::initializer_list<std::size_t> allowed, const char* what) const;
  void vertex(const Statement& st);
  void face(const Statement& st);
  int vertex_reference(const Statement& st, std::string_view ref);
  void object_name(const Statement& st);
  NameSpan read_object_name(const Statement& st);
  void give_encoded_name(const Statement& st, const NameSpan& span);
  void follow_repeated_names(const Statement& st);
  void usemtl(const Statement& st);
  void blank_lod(const Statement& st);
  void blank_freeform(const Statement& st);
  void mtllib(const Statement& st);
  std::vector<std::string> split_libraries(std::string& name, bool continued) const;
  void warn_loose_objects();
  void warn_loose_vertices();
  void apply_cuts();

  const std::filesystem::path& file_;
  const std::string text_;
  std::string_view rest_;  // the text not read yet
  ObjScan scan_;
  std::vector<Cut> cuts_;
  std::size_t line_no_ = 0;
  std::string joined_;  // a continued statement's lines, joined
  std::string current_group_;
  // assimp's OBJ state, to catch names it would resolve to the wrong object: the object that
  // takes faces (the last `o`/`g` that made or found one) and the active group (`g` only).
  std::string owner_, intended_, active_group_, misplaced_;  // misplaced: why owner != intended
  bool in_pin_object_ = false;
  std::size_t freeform_ = 0, freeform_line_ = 0;  // freeform statements cut, the first one's line
  std::map<std::string, Made> made_;
  Made outside_;                           // the vertices written under no object name
  std::vector<Made*> vertex_object_;       // per `v`: the object it is written under (`outside_`: none)
  std::vector<std::uint8_t> vertex_used_;  // per `v`: whether a face uses it
  // Faces with no material: Blender 4 writes no `usemtl` in an object without materials, and
  // assimp gives such faces another object's material (or the library's first). A face before
  // any `usemtl` of the file, or after an `o` without one, is given assimp's default material
  // (a `g` keeps the material before it, as OBJ reads).
  bool no_material_ = true;
  // Whether Blender wrote the file (its exporters start with "# Blender"), and a `g` since the
  // last face that vertices then follow
  bool blender_export_ = false;
  bool group_before_vertices_ = false;
};

// Refuses UTF-16; a UTF-8 byte-order mark is cut (assimp would read it as part of the first
// statement, and drop that statement).
ObjPrescan::ObjPrescan(const std::filesystem::path& file, std::string text) : file_(file), text_(std::move(text)) {
  rest_ = text_;
  if (rest_.size() >= 2 && ((rest_[0] == '\xFE' && rest_[1] == '\xFF') || (rest_[0] == '\xFF' && rest_[1] == '\xFE')))
    fail(file_, 1, "UTF-16 text is not supported; save the file as UTF-8 (Blender does)");
  if (rest_.substr(0, 3) == "\xEF\xBB\xBF") {
    rest_.remove_prefix(3);
    cuts_.push_back({0, 3, {}});
  }
  const std::size_t first_text = text_.find_first_not_of(" \t\r\n");
  blender_export_ = first_text != std::string_view::npos && text_.substr(first_text, 9) == "# Blender";
}

// Scans every statement, then warns of what assimp leaves out and builds what it is given.
ObjScan ObjPrescan::run() {
  Statement st;
  while (next_lines(st)) {
    tokenize(st);
    if (st.tok.empty()) continue;
    check_msvc_nonfinite(st);
    cut_number_comment(st);
    statement(st);
  }
  warn_loose_objects();
  warn_loose_vertices();
  if (freeform_ > 0)
    scan_.warnings.push_back(file_.string() + ":" + std::to_string(freeform_line_) + ": " + std::to_string(freeform_) +
                             " freeform curve/surface statement" + (freeform_ == 1 ? "" : "s") +
                             " (cstype, curv, surf, ...) ignored: only faces are drawn (Blender: export with "
                             "'Curves as NURBS' off, or convert the curve to a mesh)");
  apply_cuts();
  if (scan_.positions == 0) throw InputError(file_.string() + ": no vertices (empty or not an OBJ file)");
  if (scan_.faces == 0) throw InputError(file_.string() + ": no faces: nothing to draw (points and lines are not supported)");
  return std::move(scan_);
}

// Where a line of the text ends, before its '\r'.
std::size_t ObjPrescan::line_end(std::string_view line) const {
  std::size_t to = offset(line.data() + line.size());
  if (!line.empty() && line.back() == '\r') --to;
  return to;
}

// Reads the next statement's lines into `st`; false at the end of the text.
bool ObjPrescan::next_lines(Statement& st) {
  if (rest_.empty()) return false;
  st.line_no = ++line_no_;
  std::size_t nl = rest_.find('\n');
  st.line = rest_.substr(0, nl);
  rest_ = (nl == std::string_view::npos) ? std::string_view() : rest_.substr(nl + 1);
  st.body = st.line;
  // A trailing backslash continues the line (rare: only then is the line copied).
  st.continued = ends_in_backslash(st.line);
  // A comment ending in '\' (a Windows folder: "# from C:\models\") would take the next
  // statement into the comment, for assimp too (a face lost): assimp gets it without the '\'.
  if (const std::size_t first = st.line.find_first_not_of(" \t");
      st.continued && first != std::string_view::npos && st.line[first] == '#') {
    st.continued = false;
    cuts_.push_back({offset(st.line.data()) + st.line.rfind('\\'), 1, {}});
  }
  if (!st.continued) return true;
  joined_.assign(st.line);
  while (ends_in_backslash(joined_) && !rest_.empty()) {
    joined_.erase(joined_.rfind('\\'));
    nl = rest_.find('\n');
    // assimp joins a continuation with the next line that is not empty: another line than here
    if (rest_.substr(0, nl).find_first_not_of(" \t\r\f\v") == std::string_view::npos)
      fail(file_, st.line_no, "line continuation ('\\' at the end) followed by an empty line");
    joined_.append(rest_.substr(0, nl));
    rest_ = (nl == std::string_view::npos) ? std::string_view() : rest_.substr(nl + 1);
    ++line_no_;
  }
  st.body = joined_;
  return true;
}

// One pass over the statement: binary bytes, the comment, the tokens.
void ObjPrescan::tokenize(Statement& st) const {
  st.tok.clear();
  std::size_t tok_start = std::string_view::npos;
  st.end = st.body.size();
  for (std::size_t i = 0; i < st.end; ++i) {
    const unsigned char c = static_cast<unsigned char>(st.body[i]);
    if (c > ' ') {
      if (c == '#') {
        st.end = i;  // (bytes after '#' are still checked below)
        break;
      }
      if (tok_start == std::string_view::npos) tok_start = i;
      continue;
    }
    check_space_byte(st, i);
    if (tok_start != std::string_view::npos) {
      st.tok.push_back(st.body.substr(tok_start, i - tok_start));
      tok_start = std::string_view::npos;
    }
  }
  if (tok_start != std::string_view::npos) st.tok.push_back(st.body.substr(tok_start, st.end - tok_start));
  for (std::size_t i = st.end; i < st.body.size(); ++i) check_space_byte(st, i);
}

// Refuses a control byte, and a '\r' inside the line (assimp ends a line at a lone '\r': this
// scan would see another line than it does).
void ObjPrescan::check_space_byte(const Statement& st, std::size_t i) const {
  const unsigned char c = static_cast<unsigned char>(st.body[i]);
  if (c < 0x20 && c != '\t' && c != '\r' && c != '\f' && c != '\v') fail_binary(file_, st.line_no, c, "text model file");
  if (c == '\r' && i + 1 < st.body.size()) fail_carriage_return(file_, st.line_no);
}

// MSVC writes infinity and NaN as 1.#INF, -1.#IND, 1.#QNAN: the '#' read as a comment would
// leave "'v' needs 3 coordinates, found 1"; refused by name.
void ObjPrescan::check_msvc_nonfinite(const Statement& st) const {
  const std::string_view body = st.body, key = st.key();
  const std::size_t end = st.end;
  if (!(end < body.size() && end > 0 && static_cast<unsigned char>(body[end - 1]) > ' ' && key.size() <= 2 &&
        key[0] == 'v'))
    return;
  std::string after(body.substr(end + 1, 4));
  for (char& ch : after) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  if (after.rfind("INF", 0) == 0 || after.rfind("IND", 0) == 0 || after.rfind("QNAN", 0) == 0 ||
      after.rfind("SNAN", 0) == 0) {
    const std::size_t to = body.find_first_of(" \t\r", end);
    fail(file_, st.line_no,
         "non-finite number " +
             quote_input(std::string(st.tok.back()) +
                         std::string(body.substr(end, to == std::string_view::npos ? std::string_view::npos : to - end))) +
             " (MSVC's spelling of infinity or NaN)");
  }
}

// A comment after the numbers of a v/vt/vn/f/l/p statement: assimp would read it as numbers
// (f 1 2 3 # x: "Invalid face index"); it is given the line without it.
void ObjPrescan::cut_number_comment(const Statement& st) {
  const std::string_view key = st.key();
  if (!(st.end < st.body.size() && (key == "v" || key == "vt" || key == "vn" || key == "vp" || key == "f" ||
                                    key == "fo" || key == "l" || key == "p")))
    return;
  if (st.continued) fail(file_, st.line_no, "a comment on a continued line ('\\' at the end) is not supported");
  const std::size_t from = offset(st.tok.back().data() + st.tok.back().size());
  cuts_.push_back({from, line_end(st.line) - from, {}});
}

// Checks one statement by its keyword (unknown ones assimp ignores are ignored here too).
void ObjPrescan::statement(const Statement& st) {
  const std::string_view key = st.key();
  if (key == "v") {
    vertex(st);
  } else if (key == "vt") {
    check_numbers(st, 1, "coordinate");
    check_count(st, {2, 3}, "2 coordinates (u v) or 3 (u v w)");
    ++scan_.texcoords;
  } else if (key == "vn") {
    check_numbers(st, 3, "coordinates");
    check_count(st, {3}, "3 coordinates (x y z)");
    ++scan_.normals;
  } else if (key == "vp") {
    check_numbers(st, 1, "coordinate");
  } else if (key == "f" || key == "fo" || key == "l" || key == "p") {
    face(st);
  } else if (key == "o" || key == "g") {
    object_name(st);
  } else if (key == "usemtl") {
    usemtl(st);
  } else if (key == "lod") {
    blank_lod(st);
  } else if (is_freeform(key)) {
    blank_freeform(st);
  } else if (std::string_view("flpog").find(key[0]) != std::string_view::npos ||
             (key[0] == 'v' && (key[1] == 't' || key[1] == 'n'))) {
    // assimp reads a statement by its first letter (v: its first two): it draws `fx 1 2 3` as
    // a face, fails on `vtx 1 1` without a line, takes `ox` for an object name. Other unknown
    // statements (`vD`, `shadow_obj`) assimp ignores, and so does this scan.
    fail(file_, st.line_no, "unknown statement " + quote_input(key) + " (assimp would read it as " +
                                quote_input(std::string(1, key[0])) + "): fix or remove the line");
  } else if (key == "mtllib") {
    mtllib(st);
  }
}

// At least `min_count` numbers, each finite and as OBJ writes them. A '.5' is given to assimp
// as '0.5': assimp 5.2.5 takes no number for it and skips the whole statement (a vertex lost,
// every later index shifted).
void ObjPrescan::check_numbers(const Statement& st, std::size_t min_count, const char* what) {
  const auto& tok = st.tok;
  if (tok.size() - 1 < min_count)
    fail(file_, st.line_no, quote_input(st.key()) + " needs " + std::to_string(min_count) + " " + what +
                                ", found " + std::to_string(tok.size() - 1) + " (truncated file?)");
  for (std::size_t k = 1; k < tok.size(); ++k) {
    double v = 0;
    if (!parse_number(tok[k], v)) {
      if (is_number_like(tok[k])) fail(file_, st.line_no, "non-finite number " + quote_input(tok[k]));
      fail(file_, st.line_no, "malformed number " + quote_input(tok[k]));
    }
    if (!std::isfinite(v)) fail(file_, st.line_no, "number out of range " + quote_input(tok[k]));
    if (tok[k][0] == '.') {
      if (st.continued)
        fail(file_, st.line_no, "a number starting with '.' on a continued line ('\\' at the end) is not supported; write " +
                                    quote_input("0" + std::string(tok[k])));
      cuts_.push_back({offset(tok[k].data()), 0, "0"});
    }
  }
}

// Counts assimp reads right; others it misreads (a vertex skipped: later indices shift) or
// refuses without a line. Nothing else may follow the numbers.
void ObjPrescan::check_count(const Statement& st, std::initializer_list<std::size_t> allowed, const char* what) const {
  for (std::size_t n : allowed)
    if (st.tok.size() - 1 == n) return;
  fail(file_, st.line_no, quote_input(st.key()) + " takes " + what + ", found " + std::to_string(st.tok.size() - 1));
}

// `v`: a position, counted under its object (for the loose-vertex check); a pin helper's are kept.
void ObjPrescan::vertex(const Statement& st) {
  const auto& tok = st.tok;
  check_numbers(st, 3, "coordinates");
  check_count(st, {3, 4, 6}, "3 coordinates (x y z), 4 (x y z w) or 6 (x y z r g b)");
  if (tok.size() == 5 && std::strtod(std::string(tok[4]).c_str(), nullptr) == 0.0)
    fail(file_, st.line_no, "'v' with w = 0 (a point at infinity)");
  ++scan_.positions;
  if (group_before_vertices_) no_material_ = true, group_before_vertices_ = false;
  // (vertices before any `o`/`g`, or under a bare `o`: `outside_`, for the loose-vertex check)
  Made* under = current_group_.empty() ? &outside_ : &made_[current_group_];
  if (under->vertices++ == 0 && under == &outside_) outside_.line = st.line_no;
  vertex_object_.push_back(under);
  vertex_used_.push_back(0);
  if (in_pin_object_) {
    // (the values are only parsed here: pin points need them, nothing else does)
    auto& pts = scan_.pin_points[current_group_];
    for (std::size_t k = 1; k <= 3; ++k)
      pts.push_back(static_cast<float>(std::strtod(std::string(tok[k]).c_str(), nullptr)));
  }
}

// `f`/`fo` (a face), `l`/`p` (lines and points, which are not drawn): the vertex references.
void ObjPrescan::face(const Statement& st) {
  const std::string_view key = st.key();
  const std::size_t corners = st.tok.size() - 1;
  const bool is_face = key == "f" || key == "fo";
  const std::size_t need = is_face ? 3 : 1;
  // assimp refuses larger faces without naming the line ("Face 0 has too many faces")
  if (is_face && corners > kMaxFaceCorners)
    fail(file_, st.line_no, "a face with " + std::to_string(corners) + " corners (at most " +
                                std::to_string(kMaxFaceCorners) + ")");
  if (corners < need)
    fail(file_, st.line_no, quote_input(key) + " needs at least " + std::to_string(need) + " vertices, found " +
                                std::to_string(corners));
  int form = -1;  // the first corner's fields
  for (std::size_t k = 1; k < st.tok.size(); ++k) {
    const int this_form = vertex_reference(st, st.tok[k]);
    // assimp takes the first corner's form for all: `f 1/2 2 3/1` would give vertex 2 the
    // third corner's texture coordinate
    if (form < 0) form = this_form;
    if (this_form != form)
      fail(file_, st.line_no, "a " + quote_input(key) + " statement mixes vertex reference forms (" +
                                  quote_input(st.tok[1]) + " and " + quote_input(st.tok[k]) +
                                  "): assimp would give texture coordinates or normals to the wrong corners; "
                                  "write every corner the same way (v, v/vt, v//vn or v/vt/vn)");
  }
  if (is_face && owner_ != intended_) throw InputError(misplaced_);
  group_before_vertices_ = false;
  if (is_face && no_material_) {
    cuts_.push_back({offset(st.line.data()), 0, "usemtl DefaultMaterial\n"});
    no_material_ = false;
  }
  if (is_face) ++scan_.faces; else ++scan_.lines_points;
}

// One corner `v[/vt[/vn]]`: each index in range and as assimp reads it; marks the vertex used
// by a face. Returns its form: 1 v, 2 v/vt, 3 v//vn, 4 v/vt/vn.
int ObjPrescan::vertex_reference(const Statement& st, std::string_view ref) {
  const std::string_view key = st.key();
  std::size_t part = 0, pos = 0;
  int fields = 1;
  bool ended = false;  // else a 3rd slash follows the 3 fields ("1/1/1/1")
  while (part < 3) {
    const std::size_t slash = ref.find('/', pos);
    const std::string_view field = ref.substr(pos, slash == std::string_view::npos ? std::string_view::npos : slash - pos);
    const std::size_t count = part == 0 ? scan_.positions : part == 1 ? scan_.texcoords : scan_.normals;
    if (!(field.empty() && part > 0)) {
      long long idx = 0;
      // ('+3' is no index for assimp: it reads `f 1 2 +3` as four corners)
      if ((!field.empty() && field[0] == '+') || !parse_int(field, idx) || idx == 0)
        fail(file_, st.line_no, "malformed vertex reference " + quote_input(ref));
      // ('01': assimp reads `f 01 02 03` as four triangles of other vertices)
      if (const std::size_t d = field[0] == '-' ? 1 : 0; field.size() > d + 1 && field[d] == '0')
        fail(file_, st.line_no, "vertex reference " + quote_input(ref) + " has a leading zero (assimp misreads it); write " +
                                    quote_input((d ? "-" : "") + std::to_string(idx < 0 ? -idx : idx)));
      if (part == 1) fields |= 2;
      if (part == 2) fields |= 4;
      const long long n = static_cast<long long>(count);
      if (part == 0 && key != "l" && key != "p" && idx <= n && idx >= -n) {
        const auto vi = static_cast<std::size_t>(idx > 0 ? idx - 1 : n + idx);
        vertex_object_[vi]->used = true;
        vertex_used_[vi] = 1;
      }
      if (idx > n || idx < -n)
        fail(file_, st.line_no, std::string(part == 0 ? "vertex" : part == 1 ? "texture coordinate" : "normal") +
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
    fail(file_, st.line_no, "malformed vertex reference " + quote_input(ref));
  return fields == 1 ? 1 : fields == 3 ? 2 : fields == 5 ? 3 : 4;
}

// `o`/`g`: the object (or group) faces now go to, as the file means it and as assimp reads it.
void ObjPrescan::object_name(const Statement& st) {
  ++scan_.groups;
  // (a new object resets the material; a `g` of a Blender export that vertices follow is one
  // too: Blender 4's "Object Groups" writes `g Obj_Mesh` for `o Obj`)
  if (blender_export_ && st.key() == "g") group_before_vertices_ = true;
  give_encoded_name(st, read_object_name(st));
  in_pin_object_ = is_pin_object_name(current_group_);
  if (in_pin_object_) scan_.pin_points[current_group_];  // (a helper without vertices is an error)
  follow_repeated_names(st);
}

// The name as the file writes it: the rest of the line, spaces inside kept (Blender writes
// `o My Cloth`), up to a comment (a '#' after a space) and trimmed. Sets current_group_.
NameSpan ObjPrescan::read_object_name(const Statement& st) {
  const std::string_view body = st.body;
  current_group_.clear();
  NameSpan span;
  span.raw_end = body.size();
  if (st.tok.size() <= 1) return span;
  span.at = static_cast<std::size_t>(st.tok[1].data() - body.data());
  std::size_t stop = body.size(), hash = std::string_view::npos;
  for (std::size_t i = span.at; i < body.size(); ++i)
    if (body[i] == '#' && (body[i - 1] == ' ' || body[i - 1] == '\t')) {
      stop = hash = i;
      break;
    }
  if (!body.empty() && body.back() == '\r') span.raw_end = body.size() - 1;
  stop = std::min(stop, span.raw_end);
  while (stop > span.at && (body[stop - 1] == ' ' || body[stop - 1] == '\t' || body[stop - 1] == '\f' ||
                            body[stop - 1] == '\v'))
    --stop;
  current_group_.assign(body.substr(span.at, stop - span.at));
  // Blender allows '#' in names and writes it as it is; a '#' after a space is read as the
  // start of a comment, as in the OBJ spec
  if (hash < span.raw_end && !current_group_.empty()) {
    scan_.warnings.push_back(file_.string() + ":" + std::to_string(st.line_no) + ": object name read as " +
                             quote_input(current_group_) + ": " +
                             quote_input(std::string(body.substr(hash, span.raw_end - hash))) +
                             " is a comment in OBJ; if it is part of the name, rename the object without "
                             "' #' (an -a or CLOTH name and a '_pins' helper must use " +
                             quote_input(current_group_) + ")");
  }
  if (!current_group_.empty() && made_.count(current_group_) == 0) made_[current_group_].line = st.line_no;
  return span;
}

// assimp reads an `o` name up to its first space and a `g` name with the rest of the line
// (comment and trailing spaces included); it is given the name encoded (spaces, '#' and '%' as
// %XX, see decode_object_name) and the import decodes it.
void ObjPrescan::give_encoded_name(const Statement& st, const NameSpan& span) {
  const std::string encoded = encode_object_name(current_group_);
  // assimp's aiString holds 1023 bytes: a longer name would silently become ""
  if (encoded.size() > 1023)
    fail(file_, st.line_no, "object name longer than 1023 bytes (" + std::to_string(encoded.size()) +
                                (encoded.size() != current_group_.size() ? " with its spaces encoded" : "") +
                                "): " + quote_input(current_group_));
  if (span.at != std::string_view::npos && st.body.substr(span.at, span.raw_end - span.at) != encoded) {
    if (st.continued) fail(file_, st.line_no, "an object name on a continued line ('\\' at the end) is not supported");
    cuts_.push_back({offset(st.body.data()) + span.at, span.raw_end - span.at, encoded});
  }
}

// Repeated names. assimp 5.2.5 finds an `o` name it has seen (from `o` or `g`) and makes that
// object current but keeps adding faces to the mesh before it ("owner"); a `g` equal to the
// active group is ignored, so after an `o` in between its faces go to that `o`'s object. A face
// read while the owner is not the object the file names is refused, at the line that named it.
// A `g` repeated after another group makes a second object of that name (its faces are
// right): a warning.
void ObjPrescan::follow_repeated_names(const Statement& st) {
  const std::string_view key = st.key();
  const std::string& name = current_group_;
  auto seen = scan_.object_lines.find(name);
  const std::string first =
      seen == scan_.object_lines.end() ? "" : " (first at line " + std::to_string(seen->second.front()) + ")";
  const std::string where = file_.string() + ":" + std::to_string(st.line_no) + ": ";
  if (key == "o" && !(name.empty() || name == intended_)) no_material_ = true;
  if (name.empty() || name == intended_) {
    // a continuation (an empty name is left to assimp as it is; a `g` with the current
    // object's name makes an object of the same name, which the import joins to it)
    if (key == "g" && !name.empty()) active_group_ = name;
  } else if (key == "o" && seen != scan_.object_lines.end()) {
    intended_ = name;
    misplaced_ = where + "object name " + quote_input(name) + " repeated" + first + ": assimp would give its faces to " +
                 quote_input(owner_) + "; give each object its own name";
  } else if (key == "g" && name == active_group_) {
    intended_ = name;
    misplaced_ = where + "group " + quote_input(name) + " repeated" + first + " after object " + quote_input(owner_) +
                 ": assimp would give its faces to " + quote_input(owner_) + "; give each object its own name";
  } else {
    if (seen != scan_.object_lines.end())
      scan_.warnings.push_back(where + "group " + quote_input(name) + " repeated" + first +
                               ": kept as another object of the same name");
    scan_.object_lines[name].push_back(st.line_no);
    owner_ = intended_ = name;
    if (key == "g") active_group_ = name;
  }
}

// `usemtl`: the name as assimp reads it (the rest of the line, comment included, trimmed).
void ObjPrescan::usemtl(const Statement& st) {
  const std::string_view key = st.key();
  std::string name(st.body.substr(static_cast<std::size_t>(key.data() + key.size() - st.body.data())));
  const std::size_t a = name.find_first_not_of(" \t\r\f\v"), b = name.find_last_not_of(" \t\r\f\v");
  name = a == std::string::npos ? std::string() : name.substr(a, b - a + 1);
  if (!name.empty()) scan_.usemtl.emplace_back(name, st.line_no);
  // (Blender 4 writes `usemtl ` with no name for an empty material slot: no material)
  no_material_ = name.empty();
}

// `lod`: a display attribute (level of detail) nothing here uses; assimp 5.2.5 takes it for an
// `l` line and fails ("bad vertex index", no line): it gets the line blank.
void ObjPrescan::blank_lod(const Statement& st) {
  const std::size_t at = offset(st.line.data());
  if (st.continued) fail(file_, st.line_no, "'lod' on a continued line ('\\' at the end) is not supported");
  cuts_.push_back({at, line_end(st.line) - at, {}});
}

// Freeform geometry (Blender's "Curves as NURBS"): assimp does not read it, and misreads what
// follows (it loses a face after `cstype`, fails on `curv` without a line). It has no faces to
// draw: assimp gets the statement blank (its line breaks kept), with one warning.
void ObjPrescan::blank_freeform(const Statement& st) {
  const std::size_t at = offset(st.line.data());
  const std::size_t to = rest_.empty() ? text_.size() : offset(rest_.data()) - 1;
  cuts_.push_back({at, to - at,
                   std::string(static_cast<std::size_t>(std::count(text_.begin() + static_cast<std::ptrdiff_t>(at),
                                                                   text_.begin() + static_cast<std::ptrdiff_t>(to), '\n')),
                               '\n')});
  if (freeform_++ == 0) freeform_line_ = st.line_no;
}

// `mtllib`: the material libraries it names. A name may hold spaces; assimp takes the rest of
// the line.
void ObjPrescan::mtllib(const Statement& st) {
  const std::string_view body = st.body.substr(0, st.end);
  std::string name(body.substr(body.find("mtllib") + 6));
  while (!name.empty() && (name.front() == ' ' || name.front() == '\t')) name.erase(0, 1);
  while (!name.empty() && (name.back() == ' ' || name.back() == '\t' || name.back() == '\r')) name.pop_back();
  const std::vector<std::string> libs = split_libraries(name, st.continued);
  // assimp opens the rest of the line as it is: trailing spaces or a comment would lose the
  // library (a default grey material, no warning); it is given the name alone
  if (!st.continued && !name.empty()) {
    const std::size_t at = body.find(name, body.find("mtllib") + 6) + offset(body.data());
    const std::size_t to = line_end(st.line);
    if (to > at + name.size()) cuts_.push_back({at + name.size(), to - at - name.size(), {}});
  }
  for (std::size_t k = 0; k < libs.size(); ++k) {
    scan_.mtllibs.push_back(libs[k]);
    scan_.mtllib_lines.push_back(st.line_no);
    scan_.mtllib_joined.push_back(k > 0);
  }
}

// Several libraries on one line (the OBJ spec allows it; assimp reads the rest of the line as
// one name): when no file has the whole name but every word names one, or every word is named
// *.mtl (a missing one is then reported by its own name). `name` becomes the first word.
std::vector<std::string> ObjPrescan::split_libraries(std::string& name, bool continued) const {
  const std::filesystem::path folder = file_.parent_path();
  std::error_code ec;
  if (continued || name.find_first_of(" \t") == std::string::npos || std::filesystem::exists(folder / name, ec))
    return {name};
  std::vector<std::string> words;
  std::istringstream split(name);
  for (std::string w; split >> w;) words.push_back(w);
  const auto mtl_named = [](const std::string& w) {
    return w.size() > 4 && (w.compare(w.size() - 4, 4, ".mtl") == 0 || w.compare(w.size() - 4, 4, ".MTL") == 0);
  };
  if (!std::all_of(words.begin(), words.end(),
                   [&](const std::string& w) { return std::filesystem::is_regular_file(folder / w, ec); }) &&
      !std::all_of(words.begin(), words.end(), mtl_named))
    return {name};
  name = words.front();
  return words;
}

// Objects of loose vertices (no faces): assimp drops them. A pin helper is read by its name;
// any other one is left out, which the user is told.
void ObjPrescan::warn_loose_objects() {
  for (const auto& [name, m] : made_)
    if (m.vertices > 0 && !m.used && !is_pin_object_name(name)) {
      const bool pin_like = name.find("_pins") != std::string::npos || name.find(".pins") != std::string::npos;
      scan_.warnings.push_back(
          file_.string() + ":" + std::to_string(m.line) + ": object " + quote_input(name) + " has " +
          std::to_string(m.vertices) + " vertices and no face uses them: left out (only faces are drawn)" +
          (pin_like ? std::string("; a pin helper is found by the exact name '<cloth>_pins' (Blender 4's "
                                  "'Object Groups' and the legacy exporter write 'Object_Mesh': untick Object "
                                  "Groups, or give the mesh data the object's name)")
                    : std::string()));
    }
}

// Loose vertices of an object that has faces (a stray vertex at the origin): assimp reads only
// the vertices faces use, so they get no mass and are not drawn.
void ObjPrescan::warn_loose_vertices() {
  struct Loose {
    std::size_t count = 0, first = 0;  // first: its 1-based `v` number
  };
  std::map<const Made*, Loose> loose;
  for (std::size_t i = 0; i < vertex_used_.size(); ++i)
    if (!vertex_used_[i] && vertex_object_[i]->used) {
      Loose& l = loose[vertex_object_[i]];
      if (l.count++ == 0) l.first = i + 1;
    }
  if (const auto it = loose.find(&outside_); it != loose.end())
    scan_.warnings.push_back(file_.string() + ":" + std::to_string(outside_.line) + ": " +
                             std::to_string(it->second.count) + " of the " + std::to_string(outside_.vertices) +
                             " vertices before any object name " + (it->second.count == 1 ? "is" : "are") +
                             " in no face (the first: vertex " + std::to_string(it->second.first) +
                             "): left out (no mass, not drawn)");
  for (const auto& [name, m] : made_)
    if (const auto it = loose.find(&m); it != loose.end() && !is_pin_object_name(name))  // (a helper's are pins)
      scan_.warnings.push_back(file_.string() + ":" + std::to_string(m.line) + ": object " + quote_input(name) + ": " +
                               std::to_string(it->second.count) + " of its " + std::to_string(m.vertices) +
                               " vertices " + (it->second.count == 1 ? "is" : "are") +
                               " in no face (the first: vertex " + std::to_string(it->second.first) +
                               "): left out (no mass, not drawn)");
}

// The text assimp is given: the file with the cuts applied (none: the file as it is).
void ObjPrescan::apply_cuts() {
  if (cuts_.empty()) return;
  // (a line's comment is cut before its numbers are read)
  std::stable_sort(cuts_.begin(), cuts_.end(), [](const Cut& a, const Cut& b) { return a.at < b.at; });
  scan_.cleaned = true;
  scan_.clean_text.reserve(text_.size());
  std::size_t from = 0;
  for (const Cut& c : cuts_) {
    scan_.clean_text.append(text_, from, c.at - from);
    scan_.clean_text.append(c.instead);
    from = c.at + c.length;
  }
  scan_.clean_text.append(text_, from, std::string::npos);
}

}  // namespace

ObjScan prescan_obj_file(const std::filesystem::path& file) { return ObjPrescan(file, read_model_text(file)).run(); }

}  // namespace b2o::conv
