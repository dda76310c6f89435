// clothsim_crossings run as a user would: its line per file, exit 0 / 1 for meshes without /
// with self-crossings, and bad input (exit 2, one message naming the file and line, nothing
// else written).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "program.hpp"

namespace {

using namespace clothsim::testing;

Result run(const std::string& args) { return run_program(CLOTHSIM_CROSSINGS_EXE, args); }

fs::path write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p;
}

long lines(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }

// A 2 x 1 strip of quads in the plane y = 0 written as Blender does, with a UV seam: the
// middle column's two vertices twice (same positions, other texture coordinates), the second
// quad using the copies; quads are split into fans.
const char* const kStrip =
    "# a strip\no Strip\n"
    "v 0 0 0\nv 0 0 1\nv 1 0 0\nv 1 0 1\nv 1 0 0\nv 1 0 1\nv 2 0 0\nv 2 0 1\n"
    "vt 0 0\nvt 0 1\nvt 0.5 0\nvt 0.5 1\nvn 0 1 0\n"
    "f 1/1/1 3/3/1 4/4/1 2/2/1\r\n"
    "f 5/1/1 7/3/1 8/4/1 6/2/1\n";

// Two squares crossing (the hand count of tests/core/self_crossings_test.cpp,
// TwoSquaresCrossingCountedByHand: 4 crossings, 3 triangle pairs): the second with negative
// indices and v//vn corners.
const char* const kCross =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
    "v 0.3 -0.5 -1\nv 0.3 0.5 -1\nv 0.3 0.5 1\nv 0.3 -0.5 1\nvn 1 0 0\n"
    "g A\nf 1 2 3 4\n"
    "g B\nf -4//1 -3//1 -2//1 -1//1\n";

TEST(CrossingsCli, HelpExplainsUsageAndExitCodes) {
  const Result r = run("--help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.output.find("usage: clothsim_crossings [--quiet] FILE.obj..."), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Exit codes: 0"), std::string::npos) << r.output;
}

TEST(CrossingsCli, CleanMeshExitsZeroWithItsLine) {
  const fs::path d = fresh_dir("crossings_clean");
  const fs::path f = write(d / "strip.obj", kStrip);
  const Result r = run(q(f));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output, f.string() + ": 0 self-crossings (0 triangle pairs), 4 triangles\n");
}

TEST(CrossingsCli, CrossingMeshExitsOneWithTheCounts) {
  const fs::path d = fresh_dir("crossings_cross");
  const fs::path clean = write(d / "strip.obj", kStrip), cross = write(d / "cross.obj", kCross);
  const Result r = run(q(clean) + " " + q(cross));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output, clean.string() + ": 0 self-crossings (0 triangle pairs), 4 triangles\n" + cross.string() +
                          ": 4 self-crossings (3 triangle pairs), 4 triangles\n");
  const Result quiet = run("--quiet " + q(clean) + " " + q(cross));
  EXPECT_EQ(quiet.code, 1);
  EXPECT_EQ(quiet.output, cross.string() + ": 4 self-crossings (3 triangle pairs), 4 triangles\n");
  const Result quiet_clean = run("--quiet " + q(clean));
  EXPECT_EQ(quiet_clean.code, 0);
  EXPECT_EQ(quiet_clean.output, "");
}

// Bad input: exit 2 and one message naming the file (and the line), even after good files.
TEST(CrossingsCli, BadInputExitsTwoNamingFileAndLine) {
  const fs::path d = fresh_dir("crossings_bad");
  const fs::path good = write(d / "strip.obj", kStrip);
  struct Case {
    std::string name, text, expect;
  };
  const Case cases[] = {
      {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "range.obj:4: vertex index 9 is out of range (3 vertices"},
      {"negative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "negative.obj:4: vertex index -4 is out of range"},
      {"zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "zero.obj:4: vertex index 0 is out of range"},
      {"number.obj", "v 0 0 0\nv 1 0 0\n\nv 0 1x 0\n", "number.obj:4: '1x' is not a finite number"},
      {"nan.obj", "v 0 nan 0\n", "nan.obj:1: 'nan' is not a finite number"},
      {"short.obj", "v 0 0\n", "short.obj:1: a vertex needs 3 coordinates"},
      {"index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a/1\n", "index.obj:4: 'a/1' is not a vertex index"},
      {"edge.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", "edge.obj:3: a face needs at least 3 corners"},
  };
  for (const Case& c : cases) {
    const fs::path f = write(d / c.name, c.text);
    const Result r = run(q(good) + " " + q(f));
    EXPECT_EQ(r.code, 2) << c.name << ": " << r.output;
    EXPECT_NE(r.output.find("clothsim_crossings: error: " + d.string() + "/" + c.expect), std::string::npos)
        << c.name << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1) << c.name << ": " << r.output;  // not the good file's line
  }
  const Result missing = run(q(d / "none.obj"));
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.output.find((d / "none.obj").string() + ": cannot open the file"), std::string::npos) << missing.output;
  EXPECT_EQ(lines(missing.output), 1);
  const Result dir = run(q(d));
  EXPECT_EQ(dir.code, 2);
  EXPECT_NE(dir.output.find("is a directory"), std::string::npos) << dir.output;
  const Result none = run("");
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.output.find("no OBJ file given"), std::string::npos) << none.output;
  const Result unknown = run("--fast " + q(good));
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.output.find("unknown option '--fast'"), std::string::npos) << unknown.output;
}

}  // namespace
