// blender2ogl: bakes a Blender export (.obj/.mtl + textures) into C++ sources.
// Exit codes: 0 success, 1 bad input (the message names the file and line), 2 bad usage.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <set>
#include <string_view>

#include "converter.hpp"

namespace {

using b2o::conv::UsageError;

constexpr const char* kHelp = R"(Usage: blender2ogl [options] MODEL.obj

Bakes a model (Wavefront .obj + .mtl + textures, as Blender exports it) into C++:
<name>.h (counts, the tables, a small API), <name>.cpp (a stub the library compiles),
<name>.S and <name>.<hash>.bin (the bulk arrays, linked as raw bytes through .incbin).
The program that links them reads no file at run time.

Options:
  -t, --target DIR        write into DIR (created if missing; default: the model's folder)
  -s, --separate          header + sources + .S/.bin (the default; the fast path for big scenes)
  -c, --combined          one header with everything as text (exact hex floats; small scenes only)
  -m, --merge             merge all objects into one (named after the file)
  -a, --cloth OBJECT      give OBJECT masses and springs (repeatable); OBJECT as written in
                          the file (spaces allowed: -a "My Cloth") or its C++ identifier;
                          the 2016 form <file>_<OBJECT> is accepted too
  -r, --reverse-map       also bake render vertex -> mass (Cloth::vertex_mass)
  -o, --object-metadata   accepted for compatibility: object tables are always written
  -n, --name NAME         scene name: C++ namespace b2o::gen::NAME and output file stem
                          (default: the model's file name without extension, cleaned)
  -p, --pin OBJECT:x,y,z  pin the mass of OBJECT nearest to (x, y, z) (repeatable; OBJECT
                          needs -a)
      --param KEY=VALUE   bake a value into Scene::params (repeatable), e.g. dt=0.002
      --depfile FILE      write a Makefile-style list of the files read (for build tools)
      --allow-missing     a missing or unreadable .mtl or texture image is a warning (default
                          material / no texture) instead of an error
  -v, --verbose           print statistics (objects, vertices, triangles, masses, springs,
                          pins, warnings, time)
  -h, -?, --help          this help
      --version           the version

Pins from the model: an object named <OBJECT>_pins or <OBJECT>.pins is not written out;
each of its vertices pins the nearest mass of OBJECT (an error if that mass is farther
than 1 % of OBJECT's bounding-box diagonal). Loose vertices are enough.

Formats: .obj is the checked path (a text pre-scan gives line numbers for bad input).
assimp 5 also reads, among others: .fbx .dae .gltf .glb .ply .stl .3ds .blend (old)
.x .off .dxf .lwo .ms3d .ac .ifc; node transforms are applied, texture paths resolved
next to the model.

Exit status: 0 success, 1 bad input (the message names the file, and the line when
known; nothing is written), 2 bad usage.
)";

float parse_float(const std::string& s, const std::string& what) {
  char* end = nullptr;
  errno = 0;
  const float v = std::strtof(s.c_str(), &end);
  if (s.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw UsageError(what + ": " + b2o::conv::quote_input(s) + " is not a finite number");
  return v;
}

b2o::conv::Options parse(int argc, char** argv, bool& done) {
  b2o::conv::Options o;
  std::set<std::string> param_keys;
  std::vector<std::string> positional;
  // Options that take one value, and the output form: given twice they are a mistake (the last
  // silently won).
  std::map<std::string, std::string> once;
  const auto only_once = [&](const std::string& what, const std::string& as) {
    const auto [it, fresh] = once.emplace(what, as);
    if (!fresh)
      throw UsageError(as == it->second ? as + " given twice" : as + " and " + it->second + " given together");
  };
  bool options_end = false;  // after "--" every argument is a file
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (options_end) {
      positional.push_back(arg);
      continue;
    }
    if (arg == "--") {
      options_end = true;
      continue;
    }
    std::string value;
    bool has_value = false;
    if (arg.rfind("--", 0) == 0 && arg.find('=') != std::string::npos) {
      value = arg.substr(arg.find('=') + 1);
      arg = arg.substr(0, arg.find('='));
      has_value = true;
    }
    auto need = [&](const char* flag) -> std::string {
      if (has_value) return value;
      if (i + 1 >= argc) throw UsageError(std::string(flag) + " needs a value");
      return argv[++i];
    };
    // short options with an attached value: -tDIR
    if (arg.size() > 2 && arg[0] == '-' && arg[1] != '-' && std::string_view("tanp").find(arg[1]) != std::string_view::npos) {
      value = arg.substr(2);
      arg = arg.substr(0, 2);
      has_value = true;
    }
    if (arg == "-h" || arg == "-?" || arg == "--help") {
      std::cout << kHelp;
      done = true;
      return o;
    } else if (arg == "--version") {
      std::cout << "blender2ogl " << b2o::conv::kVersion << "\n";
      done = true;
      return o;
    } else if (arg == "-t" || arg == "--target") {
      only_once("-t", "-t");
      o.target_dir = need("-t");
      if (o.target_dir.empty()) throw UsageError("-t: the folder name is empty (leave -t out to write next to the model)");
    } else if (arg == "-s" || arg == "--separate") {
      only_once("form", "-s");
      o.combined = false;
    } else if (arg == "-c" || arg == "--combined") {
      only_once("form", "-c");
      o.combined = true;
    } else if (arg == "-m" || arg == "--merge") {
      o.merge = true;
    } else if (arg == "-a" || arg == "--cloth") {
      o.cloth_objects.push_back(need("-a"));
    } else if (arg == "-r" || arg == "--reverse-map") {
      o.reverse_map = true;
    } else if (arg == "-o" || arg == "--object-metadata") {
      o.object_metadata = true;
    } else if (arg == "-v" || arg == "--verbose") {
      o.verbose = true;
    } else if (arg == "-n" || arg == "--name") {
      only_once("-n", "-n");
      o.name = need("-n");
      if (o.name.empty()) throw UsageError("-n: the name is empty");
      // A name given is used as it is, or refused: the build that asked for NAME.h would not
      // find the files of a cleaned name (class_.h).
      if (b2o::conv::clean_identifier(o.name) != o.name)
        throw UsageError("-n " + b2o::conv::quote_input(o.name) +
                         ": not usable as a scene name (the C++ namespace b2o::gen::NAME): letters, digits and "
                         "single '_' inside, not starting with a digit, and not a C++ keyword, a macro (linux, SIZE_MAX, "
                         "INT32_MAX, ...) or std, b2o, gen");
    } else if (arg == "-p" || arg == "--pin") {
      const std::string spec = need("-p");
      const auto colon = spec.rfind(':');
      if (colon == std::string::npos || colon == 0) throw UsageError("-p " + spec + ": expected OBJECT:x,y,z");
      b2o::conv::PinSpec pin;
      pin.object = spec.substr(0, colon);
      std::string rest = spec.substr(colon + 1);
      for (int k = 0; k < 3; ++k) {
        const auto comma = rest.find(',');
        if ((k < 2) != (comma != std::string::npos)) throw UsageError("-p " + spec + ": expected OBJECT:x,y,z");
        pin.point[static_cast<std::size_t>(k)] = parse_float(rest.substr(0, comma), "-p " + spec);
        rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
      }
      o.pins.push_back(pin);
    } else if (arg == "--param") {
      const std::string kv = need("--param");
      const auto eq = kv.find('=');
      if (eq == std::string::npos || eq == 0) throw UsageError("--param " + kv + ": expected KEY=VALUE");
      const std::string key = kv.substr(0, eq), text = kv.substr(eq + 1);
      // (the value is baked as text for the program that reads the scene: one printable word)
      const auto printable = [](char c) { return c > ' ' && c < 127 && c != '"' && c != '\'' && c != '\\'; };
      if (text.empty() || !std::all_of(text.begin(), text.end(), printable))
        throw UsageError("--param " + kv + ": the value must be one word of printable characters (no spaces or quotes)");
      if (!param_keys.insert(key).second) throw UsageError("--param " + key + " given twice");
      o.params.emplace_back(key, text);
    } else if (arg == "--allow-missing") {
      if (has_value) throw UsageError("--allow-missing takes no value");
      o.allow_missing = true;
    } else if (arg == "--depfile") {
      only_once("--depfile", "--depfile");
      o.depfile = need("--depfile");
    } else if (arg.size() > 1 && arg[0] == '-') {
      throw UsageError("unknown option " + b2o::conv::quote_input(arg));
    } else {
      positional.push_back(arg);
    }
  }
  if (positional.empty()) throw UsageError("no model file given");
  if (positional.size() > 1) throw UsageError("one model file at a time (got " + b2o::conv::quote_input(positional[1]) + " too)");
  o.input = positional.front();
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    bool done = false;
    const b2o::conv::Options options = parse(argc, argv, done);
    if (done) return 0;
    return b2o::conv::run(options, std::cerr);
  } catch (const b2o::conv::UsageError& e) {
    std::cerr << "blender2ogl: error: " << e.what() << " (see blender2ogl --help)\n";
    return 2;
  } catch (const b2o::conv::InputError& e) {
    std::cerr << "blender2ogl: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "blender2ogl: error: " << e.what() << "\n";
    return 1;
  }
}
