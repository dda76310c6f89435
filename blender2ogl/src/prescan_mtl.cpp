// The pre-scan of a .mtl: refuses what assimp would misread or crash on (a statement before the
// first `newmtl`), and gives it the text with the statements it does not need left out.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <string_view>

#include "converter.hpp"
#include "prescan.hpp"
#include "prescan_text.hpp"

namespace b2o::conv {
namespace {

// map_Kd in any case
bool is_map_kd(std::string_view key) {
  return key.size() == 6 && (key[0] | 0x20) == 'm' && (key[1] | 0x20) == 'a' && (key[2] | 0x20) == 'p' &&
         key[3] == '_' && (key[4] | 0x20) == 'k' && (key[5] | 0x20) == 'd';
}

// Reads a .mtl line by line into an MtlScan.
class MtlPrescan {
 public:
  MtlPrescan(const std::filesystem::path& file, const std::filesystem::path& model_folder)
      : file_(file), model_folder_(model_folder) {}

  // Scans the whole file; throws InputError at the first line assimp would misread.
  MtlScan run() {
    std::ifstream in(file_, std::ios::binary);
    if (!in) throw InputError(file_.string() + ": cannot open: " + std::strerror(errno));
    while (std::getline(in, line_)) {
      ++line_no_;
      // a UTF-8 byte-order mark (assimp is given the file without it)
      if (line_no_ == 1 && line_.compare(0, 3, "\xEF\xBB\xBF") == 0) {
        line_.erase(0, 3);
        scan_.cleaned = true;
      }
      clean_from_ = scan_.clean_text.size();
      scan_.clean_text.append(line_).push_back('\n');
      tokenize();
      if (!tok_.empty() && tok_[0][0] != '#') statement();
    }
    if (!scan_.cleaned) scan_.clean_text.clear();
    return std::move(scan_);
  }

 private:
  // Splits the line into tokens at spaces, tabs and '\r'; refuses control bytes.
  void tokenize() {
    tok_.clear();
    std::size_t start = std::string::npos;
    for (std::size_t i = 0; i <= line_.size(); ++i) {
      const unsigned char c = i < line_.size() ? static_cast<unsigned char>(line_[i]) : ' ';
      // Vertical tab and form feed too: assimp does not skip them, so "\vnewmtl" is no newmtl
      // to it, and a statement after it crashes assimp 5.2.5.
      if (c < 0x20 && c != '\t' && c != '\r') fail_binary(file_, line_no_, c, "material file");
      if (c == '\r' && i + 1 < line_.size()) fail_carriage_return(file_, line_no_);
      const bool space = c == ' ' || c == '\t' || c == '\r';
      if (!space && start == std::string::npos) start = i;
      if (space && start != std::string::npos) {
        tok_.emplace_back(line_.data() + start, i - start);
        start = std::string::npos;
      }
    }
  }

  // One statement (not a comment): checked, and given to assimp as it is, rewritten or blank.
  void statement() {
    const std::string_view key = tok_[0];
    if (key == "newmtl") return newmtl();
    if (!in_material_) fail(file_, line_no_, quote_input(key) + " before any 'newmtl'");
    if (is_map_kd(key)) return map_kd();
    // Statements the converter does not read are not given to assimp: they are ignored as
    // they would be, and cannot fail it (assimp 5.2.5 stops on Blender 4's `aniso` with
    // "Cannot parse string \"niso\"", naming no file).
    // (as assimp reads them: K and N in either case, the second letter as written)
    std::string canon(key);
    if (canon.size() == 2 && (canon[0] == 'k' || canon[0] == 'n')) canon[0] = static_cast<char>(canon[0] - 'a' + 'A');
    if (!(canon == "Ka" || canon == "Kd" || canon == "Ks" || canon == "Ke" || canon == "Tf" || canon == "Ns" ||
          canon == "d" || canon == "Tr" || canon == "Ni"))
      return replace_line("");
    numbers(key, canon == "Ka" || canon == "Kd" || canon == "Ks" || canon == "Ke" || canon == "Tf");
  }

  // Gives assimp `with` in place of the current line.
  void replace_line(const std::string& with) {
    scan_.clean_text.resize(clean_from_);
    scan_.clean_text.append(with).push_back('\n');
    scan_.cleaned = true;
  }

  // `newmtl`: the material's name, warned when a name is defined again.
  void newmtl() {
    in_material_ = true;
    // as assimp reads it: the rest of the line, trimmed ("newmtl" alone: its default name)
    std::string name = line_.substr(static_cast<std::size_t>(tok_[0].data() + tok_[0].size() - line_.data()));
    const std::size_t a = name.find_first_not_of(" \t\r"), b = name.find_last_not_of(" \t\r");
    name = a == std::string::npos ? std::string("DefaultMaterial") : name.substr(a, b - a + 1);
    if (auto [it, added] = defined_.try_emplace(name, line_no_); !added)
      scan_.warnings.push_back(file_.string() + ":" + std::to_string(line_no_) + ": material " + quote_input(name) +
                               " defined again (first at line " + std::to_string(it->second) +
                               "); assimp merges the two, the later values win");
    else
      scan_.materials.push_back(name);
  }

  // `map_Kd [options] file`: assimp is given `map_Kd <file>` alone. It misreads options with
  // fewer than 3 numbers (`-s 2 2`), or ones it does not know (`-type`, `-cc`), as part of the
  // name and loses the texture; trailing spaces too. The scale, offset and turbulence are not drawn.
  void map_kd() {
    bool transformed = false;
    const std::size_t k = skip_map_kd_options(transformed);
    if (k >= tok_.size()) fail(file_, line_no_, "map_Kd without a file name");
    std::string name = line_.substr(static_cast<std::size_t>(tok_[k].data() - line_.data()));
    while (!name.empty() && (name.back() == ' ' || name.back() == '\t' || name.back() == '\r')) name.pop_back();
    if (name[0] == '-') name = "./" + name;  // (assimp would take it for an option)
    name = relative_to_model(name);
    if (transformed)
      scan_.warnings.push_back(file_.string() + ":" + std::to_string(line_no_) +
                               ": the texture's scale, offset or turbulence (-s, -o, -t) are not drawn: " +
                               quote_input(name) + " is mapped as the UVs say");
    scan_.maps.push_back({name, line_no_});
    replace_line("map_Kd " + name);
  }

  // The map_Kd options, checked; returns the token of the file name. `transformed`: a scale,
  // offset or turbulence other than the neutral one.
  std::size_t skip_map_kd_options(bool& transformed) {
    std::size_t k = 1;
    while (k < tok_.size() && tok_[k].size() > 1 && tok_[k][0] == '-' && !(tok_[k][1] >= '0' && tok_[k][1] <= '9')) {
      const std::string option(tok_[k]);
      std::size_t most = 0, least = 0;  // numbers it takes; or one word (on/off, a type, a channel)
      bool word = false;
      if (option == "-s" || option == "-o" || option == "-t") most = 3, least = 1;
      else if (option == "-mm") most = 2, least = 1;
      else if (option == "-bm" || option == "-boost" || option == "-texres") most = least = 1;
      else if (option == "-blendu" || option == "-blendv" || option == "-cc" || option == "-clamp" ||
               option == "-imfchan" || option == "-type")
        word = true;
      else if (k + 1 == tok_.size())
        break;  // the last word: a file name that starts with '-' (given to assimp as ./-name)
      else
        fail(file_, line_no_, "unknown map_Kd option " + quote_input(option) +
                                  " (known: -s -o -t -mm -bm -boost -texres -blendu -blendv -cc -clamp -imfchan "
                                  "-type; a file name starting with '-' is written ./" + option + ")");
      ++k;
      if (word) {
        if (k >= tok_.size()) fail(file_, line_no_, "map_Kd option " + quote_input(option) + " needs a value");
        ++k;
        continue;
      }
      std::size_t got = 0;
      double v = 0.0;
      // (a texture named like a number, after all the option's numbers, stays the name)
      while (got < most && k + 1 < tok_.size() && parse_number(tok_[k], v)) {
        v = std::strtod(std::string(tok_[k]).c_str(), nullptr);  // (parse_number gives only large values)
        const double neutral = option == "-s" ? 1.0 : 0.0;
        if ((option == "-s" || option == "-o" || option == "-t") && v != neutral) transformed = true;
        ++got, ++k;
      }
      if (got < least) fail(file_, line_no_, "map_Kd option " + quote_input(option) + " needs a number");
    }
    return k;
  }

  // A relative texture name is relative to this .mtl: from another folder than the model's it
  // is given as relative to the model's folder, which the import reads textures from.
  std::string relative_to_model(const std::string& name) const {
    std::string rel = name;
    std::replace(rel.begin(), rel.end(), '\\', '/');
    const std::filesystem::path mtl_folder = file_.parent_path();
    std::error_code ec;
    if (!model_folder_.empty() && !std::filesystem::path(rel).is_absolute() && !rel.empty() &&
        !std::filesystem::equivalent(mtl_folder.empty() ? "." : mtl_folder,
                                     model_folder_.empty() ? "." : model_folder_, ec) &&
        std::filesystem::is_regular_file(mtl_folder / rel, ec)) {
      // the .mtl's folder as the mtllib line names it from the model's folder, '..' and all
      // (normalised as text, 'link/..' through a symbolic link would be another folder)
      const std::filesystem::path prefix = file_.lexically_relative(model_folder_).parent_path();
      const std::filesystem::path from_model = prefix / rel;
      if (!prefix.empty() && std::filesystem::is_regular_file(model_folder_ / from_model, ec))
        return from_model.generic_string();
    }
    return name;
  }

  // A color (3 numbers, or 1 for a grey) or a one-number statement: finite numbers only.
  void numbers(std::string_view key, bool color) {
    for (std::size_t k = 1; k < tok_.size(); ++k) {
      double v = 0;
      if (tok_[k][0] == '#') {
        tok_.resize(k);  // a comment
        break;
      }
      if (parse_number(tok_[k], v)) {
        if (!std::isfinite(v)) fail(file_, line_no_, "number out of range " + quote_input(tok_[k]));
      } else if (is_number_like(tok_[k])) {
        fail(file_, line_no_, "non-finite value " + quote_input(tok_[k]));
      } else {
        // (assimp would fail with "Cannot parse string" naming neither file nor line)
        fail(file_, line_no_, "malformed number " + quote_input(tok_[k]) + " in " + quote_input(key));
      }
    }
    // assimp reads 3 numbers for a color (a missing one fails it) and 1 for the others
    const std::size_t n = tok_.size() - 1;
    if (color && n != 3 && n != 1)
      fail(file_, line_no_, quote_input(key) + " takes 3 numbers (r g b) or 1 (grey), found " + std::to_string(n));
    if (!color && n != 1) fail(file_, line_no_, quote_input(key) + " takes 1 number, found " + std::to_string(n));
    // One number is a grey (the MTL spec: g = b = r); assimp would read (r, 0, 0).
    if (color && n == 1) {
      std::string grey(key);
      for (int k = 0; k < 3; ++k) grey.append(" ").append(tok_[1]);
      if (!line_.empty() && line_.back() == '\r') grey.push_back('\r');
      replace_line(grey);
    }
  }

  const std::filesystem::path& file_;
  const std::filesystem::path& model_folder_;
  MtlScan scan_;
  std::map<std::string, std::size_t> defined_;  // name -> first line
  std::string line_;
  std::size_t line_no_ = 0;
  std::size_t clean_from_ = 0;  // where the current line starts in scan_.clean_text
  std::vector<std::string_view> tok_;
  bool in_material_ = false;
};

}  // namespace

MtlScan prescan_mtl_file(const std::filesystem::path& file, const std::filesystem::path& model_folder) {
  return MtlPrescan(file, model_folder).run();
}

}  // namespace b2o::conv
