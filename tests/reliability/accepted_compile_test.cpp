// Property on fuzz inputs the converter accepts: the generated code compiles without a
// warning. accepted/ holds a committed sample of 20 accepted fuzz-corpus inputs
// (accepted/make_sample.py made it); all are converted, then compiled in one compiler run
// with -Wall -Wextra -Wpedantic -Werror, together with one file that includes every header
// (scenes must not clash with each other either).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "process.hpp"

namespace fs = std::filesystem;
using reliability::Result;
using reliability::TempDir;

namespace {

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q.append("'\\''");
    else q.push_back(c);
  }
  q.push_back('\'');
  return q;
}

TEST(AcceptedFuzzInputs, GeneratedCodeCompilesWithoutWarnings) {
  const fs::path accepted = ACCEPTED_DIR;
  TempDir work("accepted");
  const fs::path out = work.path / "out";
  std::vector<std::string> stems;
  for (const auto& e : fs::directory_iterator(accepted))
    if (e.path().extension() == ".obj") stems.push_back(e.path().stem().string());
  std::sort(stems.begin(), stems.end());
  ASSERT_GE(stems.size(), 20u);
  for (const auto& e : fs::directory_iterator(accepted)) fs::copy_file(e.path(), work.path / e.path().filename());

  std::string all_headers;
  for (const std::string& stem : stems) {
    SCOPED_TRACE(stem);
    // the fuzz target converts with missing .mtl/textures allowed; so does this run
    std::vector<std::string> argv = {B2O_EXE, "--allow-missing"};
    std::ifstream args(accepted / (stem + ".args"));
    for (std::string a; std::getline(args, a);)
      if (!a.empty()) argv.push_back(a);
    argv.insert(argv.end(), {"-t", out.string(), (work.path / (stem + ".obj")).string()});
    const Result r = reliability::run(argv);
    ASSERT_EQ(r.exit_code, 0) << "the sample should be accepted: " << r.err;
    ASSERT_TRUE(fs::exists(out / (stem + ".h")));
    all_headers += "#include \"" + stem + ".h\"\n";
  }
  reliability::write_file(out / "all_headers.cpp", all_headers + "int main() { return 0; }\n");

  // One batch: every generated source and assembler file, and the file with every header.
  std::string files;
  int sources = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    const auto ext = e.path().extension();
    if (ext == ".cpp" || ext == ".S") {
      ++sources;
      files.push_back(' ');
      files.append(quote(e.path().filename().string()));
    }
  }
  ASSERT_GE(sources, 21) << "expected the generated sources of every sample";
  const std::string cmd = "cd " + quote(out.string()) + " && " + quote(CXX_COMPILER) +
                          " -std=c++20 -O0 -Wall -Wextra -Wpedantic -pedantic -Werror -Wshadow -Wold-style-cast"
                          " -Wcast-align -Wnull-dereference -I" + quote(B2O_INCLUDE) + " -I. -c" + files + " 2>&1";
  const Result c = reliability::run({"/bin/sh", "-c", cmd}, {}, 300.0);
  EXPECT_EQ(c.exit_code, 0) << cmd << "\n" << c.out;
  EXPECT_EQ(c.out, "") << "the compiler said something:\n" << c.out;
}

}  // namespace
