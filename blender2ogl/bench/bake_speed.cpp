// bake_speed: makes a Blender-like OBJ with about N triangles (a wavy grid with vt and vn),
// then measures, with /usr/bin/time -v, (1) blender2ogl converting it and (2) the compiler
// building the generated sources (the .cpp tables and the .S with .incbin) into objects.
// Prints wall time and peak memory of each step and their sum.
//
//   bake_speed [--triangles N] [--work DIR] [--converter PATH] [--cxx COMPILER] [--include DIR]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include <assimp/Importer.hpp>
#include <assimp/scene.h>

#include "converter.hpp"

namespace fs = std::filesystem;

namespace {

struct Measure {
  double seconds = 0;
  double peak_mb = 0;
  int exit_code = -1;
};

// Runs `command` under /usr/bin/time -v; reads "Elapsed (wall clock)" and "Maximum resident".
Measure timed(const std::string& command, const fs::path& log) {
  const std::string full = "/usr/bin/time -v " + command + " > '" + log.string() + "' 2>&1";
  Measure m;
  const int status = std::system(full.c_str());
  m.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("Elapsed (wall clock) time") != std::string::npos) {
      const std::string t = line.substr(line.rfind(' ') + 1);  // [h:]mm:ss.ss
      double total = 0, part = 0;
      std::stringstream ss(t);
      std::string field;
      while (std::getline(ss, field, ':')) {
        part = std::atof(field.c_str());
        total = total * 60 + part;
      }
      m.seconds = total;
    } else if (line.find("Maximum resident set size") != std::string::npos) {
      m.peak_mb = std::atof(line.substr(line.rfind(' ') + 1).c_str()) / 1024.0;
    }
  }
  return m;
}

void write_obj(const fs::path& file, long triangles) {
  const long quads = std::max(1L, triangles / 2);
  const long n = std::max(2L, static_cast<long>(std::lround(std::sqrt(static_cast<double>(quads))))) + 1;  // vertices per side
  std::ofstream out(file);
  out << "# bake_speed: a " << n << " x " << n << " grid, " << 2 * (n - 1) * (n - 1) << " triangles\n";
  out << "o Sheet\n";
  char buf[128];
  for (long j = 0; j < n; ++j)
    for (long i = 0; i < n; ++i) {
      const double x = double(i) / double(n - 1), z = double(j) / double(n - 1);
      std::snprintf(buf, sizeof buf, "v %.6f %.6f %.6f\n", x * 20 - 10, 0.1 * std::sin(x * 40) * std::cos(z * 40), z * 20 - 10);
      out << buf;
    }
  for (long j = 0; j < n; ++j)
    for (long i = 0; i < n; ++i) {
      std::snprintf(buf, sizeof buf, "vt %.6f %.6f\n", double(i) / double(n - 1), double(j) / double(n - 1));
      out << buf;
    }
  for (long j = 0; j < n; ++j)
    for (long i = 0; i < n; ++i) out << "vn 0.0000 1.0000 0.0000\n";
  out << "s 1\n";
  for (long j = 0; j + 1 < n; ++j)
    for (long i = 0; i + 1 < n; ++i) {
      const long a = j * n + i + 1, b = a + 1, c = a + n + 1, d = a + n;
      out << "f " << a << '/' << a << '/' << a << ' ' << d << '/' << d << '/' << d << ' ' << c << '/' << c << '/' << c
          << ' ' << b << '/' << b << '/' << b << '\n';
    }
}

// The bulk bytes: <name>.<hash>.bin (one per bake in the folder).
std::uintmax_t bin_bytes(const fs::path& dir) {
  std::uintmax_t n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".bin") n += e.file_size();
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  // Reference mode: only assimp reading the model, as the converter reads it.
  if (argc == 3 && std::string(argv[1]) == "--assimp-only") {
    Assimp::Importer importer;
    return b2o::conv::read_with_assimp(importer, argv[2]) != nullptr ? 0 : 1;
  }
  long triangles = 1000000;
  fs::path work = fs::temp_directory_path() / "b2o_bake_speed";
  std::string converter = B2O_CONVERTER, cxx = "c++", include = B2O_INCLUDE;
  for (int i = 1; i < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::cout << "Usage: bake_speed [--triangles N] [--work DIR] [--converter PATH] [--cxx COMPILER] [--include DIR]\n"
                   "Writes a Blender-like OBJ of about N triangles (default 1000000) into DIR (default "
                << (fs::temp_directory_path() / "b2o_bake_speed").string()
                << "), then times blender2ogl\n"
                   "converting it and the compiler building what it wrote (docs/bake-speed.md). DIR must be\n"
                   "new, empty or made by an earlier run: its files are replaced.\n";
      return 0;
    }
    if (i + 1 >= argc) {
      std::cerr << "bake_speed: " << a << (a.rfind("--", 0) == 0 ? " needs a value" : ": unknown argument")
                << " (bake_speed --help)\n";
      return 2;
    }
    if (a == "--triangles") {
      char* end = nullptr;
      triangles = std::strtol(argv[i + 1], &end, 10);
      if (end == argv[i + 1] || *end != '\0') triangles = 0;
    } else if (a == "--work") work = argv[i + 1];
    else if (a == "--converter") converter = argv[i + 1];
    else if (a == "--cxx") cxx = argv[i + 1];
    else if (a == "--include") include = argv[i + 1];
    else {
      std::cerr << "bake_speed: unknown option " << a << "\n";
      return 2;
    }
  }
  if (triangles < 2) {
    std::cerr << "bake_speed: --triangles must be >= 2\n";
    return 2;
  }
  // Only a folder this tool made is emptied (it holds its marker): any other, not empty, is
  // refused (--work . would delete the folder it is run in).
  const fs::path marker = work / ".b2o_bake_speed";
  std::error_code ec;
  if (fs::exists(work, ec)) {
    if (!fs::is_directory(work, ec)) {
      std::cerr << "bake_speed: --work " << work.string() << " is not a directory\n";
      return 2;
    }
    // (the default folder is this tool's by its name)
    if (!fs::is_empty(work, ec) && !fs::exists(marker, ec) && work != fs::temp_directory_path() / "b2o_bake_speed") {
      std::cerr << "bake_speed: --work " << work.string()
                << " is not empty and was not made by bake_speed: give a new or empty folder\n";
      return 2;
    }
    for (const auto& e : fs::directory_iterator(work, ec)) fs::remove_all(e.path(), ec);
  }
  fs::create_directories(work, ec);
  if (ec || !std::ofstream(marker)) {
    std::cerr << "bake_speed: cannot use --work " << work.string() << (ec ? ": " + ec.message() : "") << "\n";
    return 2;
  }
  const fs::path obj = work / "sheet.obj";
  write_obj(obj, triangles);
  std::cout << "model     " << obj.string() << " (" << static_cast<double>(fs::file_size(obj)) / 1e6 << " MB, about "
            << triangles << " triangles)\n";

  // Reference, measured in the same run: assimp alone reading the same file.
  const Measure ref = timed("'" + fs::canonical("/proc/self/exe").string() + "' --assimp-only '" + obj.string() + "'",
                            work / "assimp_only.log");
  if (ref.exit_code != 0) {
    std::cerr << "bake_speed: assimp could not read the model\n";
    return 1;
  }
  std::printf("reference assimp ReadFile alone %5.2f s %7.1f MB\n", ref.seconds, ref.peak_mb);
  // Two bakes of the same model: the scene as geometry (the target: < 3 s and < 300 MB for
  // convert + compile), and the whole sheet given masses and springs (-a Sheet -r).
  struct Variant {
    const char* name;
    const char* args;
  };
  bool ok = true;
  for (const Variant& v : {Variant{"geometry", ""}, Variant{"cloth", "-a Sheet -r "}}) {
    const fs::path out = work / v.name;
    fs::create_directories(out);
    const Measure conv = timed("'" + converter + "' " + v.args + "-t '" + out.string() + "' '" + obj.string() + "'",
                               work / (std::string(v.name) + "_convert.log"));
    if (conv.exit_code != 0) {
      std::cerr << "bake_speed: the converter failed; see " << (work / (std::string(v.name) + "_convert.log")).string() << "\n";
      return 1;
    }
    // Both generated sources in one compiler call, as a build would (-O2, -Werror).
    const Measure comp = timed("sh -c \"cd '" + out.string() + "' && " + cxx +
                                   " -std=c++20 -O2 -Wall -Wextra -Wpedantic -Werror -I'" + include +
                                   "' -I. -c sheet.cpp sheet.S\"",
                               work / (std::string(v.name) + "_compile.log"));
    if (comp.exit_code != 0) {
      std::cerr << "bake_speed: compiling failed; see " << (work / (std::string(v.name) + "_compile.log")).string() << "\n";
      return 1;
    }
    const double total = conv.seconds + comp.seconds, peak = std::max(conv.peak_mb, comp.peak_mb);
    std::printf("%-9s convert = %.2f x assimp's read\n", v.name, ref.seconds > 0 ? conv.seconds / ref.seconds : 0.0);
    std::printf("%-9s convert %6.2f s %7.1f MB | compile %5.2f s %6.1f MB | total %6.2f s, peak %6.1f MB | .bin %6.1f MB\n",
                v.name, conv.seconds, conv.peak_mb, comp.seconds, comp.peak_mb, total, peak,
                static_cast<double>(bin_bytes(out)) / 1e6);
    if (std::string(v.name) == "geometry") ok = total < 3.0 && peak < 300.0;
  }
  std::printf("target (geometry: convert + compile < 3 s and < 300 MB): %s\n", ok ? "met" : "NOT met");
  return 0;
}
