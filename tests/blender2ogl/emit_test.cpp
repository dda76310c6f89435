// emit + write: golden files, determinism, atomicity, unchanged files left alone.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "support.hpp"

namespace {

using namespace b2o::test;
namespace conv = b2o::conv;

struct Case {
  const char* golden;  // folder under golden/
  const char* input;
  std::vector<std::string> args;
};

const std::vector<Case>& golden_cases() {
  static const std::vector<Case> cases = {
      {"grid", "grid.obj", {"-a", "Cloth", "-r", "--param", "dt=0.002", "--param", "k_rep=2000"}},
      {"odd_names_combined", "odd_names.obj", {"-c", "-n", "odd"}},
      {"ngons", "ngons_crlf.obj", {"-n", "ngons", "-a", "class"}},
  };
  return cases;
}

// Regenerate with: B2O_UPDATE_GOLDEN=1 ctest -R Golden   (then review the diff and commit)
TEST(Emit, GoldenFiles) {
  const bool update = std::getenv("B2O_UPDATE_GOLDEN") != nullptr;
  for (const Case& c : golden_cases()) {
    const auto out = scratch(std::string("golden_") + c.golden);
    std::vector<std::string> args = c.args;
    args.insert(args.end(), {"-t", out.string(), fixture(c.input).string()});
    const auto r = run_converter(args);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const fs::path golden = fs::path(B2O_GOLDEN) / c.golden;
    if (update) {
      fs::remove_all(golden);
      fs::create_directories(golden);
      for (const auto& [name, bytes] : snapshot(out)) write_file(golden / name, bytes);
      continue;
    }
    const auto want = snapshot(golden);
    const auto got = snapshot(out);
    ASSERT_FALSE(want.empty()) << "no golden files in " << golden << " (run with B2O_UPDATE_GOLDEN=1)";
    ASSERT_EQ(want.size(), got.size()) << c.golden;
    for (const auto& [name, bytes] : want) {
      ASSERT_EQ(got.count(name), 1u) << name;
      EXPECT_TRUE(got.at(name) == bytes) << c.golden << "/" << name << " differs from the golden file";
    }
  }
}

TEST(Emit, DeterministicAcrossRunsAndTargets) {
  const auto a = scratch("det_a"), b = scratch("det_b");
  for (const auto& dir : {a, b}) {
    const auto r = run_converter({"-a", "Cloth", "-r", "-t", dir.string(), fixture("grid.obj").string()});
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  EXPECT_EQ(snapshot(a), snapshot(b));
  // in process too: same scene + options -> same bytes
  conv::Options o;
  o.input = fixture("odd_names.obj");
  const auto s1 = convert(o), s2 = convert(o);
  const auto f1 = conv::emit_scene(s1, o), f2 = conv::emit_scene(s2, o);
  ASSERT_EQ(f1.size(), f2.size());
  for (std::size_t i = 0; i < f1.size(); ++i) EXPECT_EQ(f1[i].bytes, f2[i].bytes);
}

// -s: the header is the only file whose bytes name the bake; the .bin is named by its hash and
// the .cpp/.S are stubs that never change (the set switches with the header's rename).
// The .bin's name is the FNV-1a 64 of its bytes, as docs/blender2ogl.md says: the published
// test vectors.
TEST(Emit, BinHashIsFnv1a64) {
  EXPECT_EQ(conv::hash_hex(""), "cbf29ce484222325");
  EXPECT_EQ(conv::hash_hex("a"), "af63dc4c8601ec8c");
  EXPECT_EQ(conv::hash_hex("foobar"), "85944171f73967e8");
}

TEST(Emit, BinNamedByItsHashStubsFixed) {
  conv::Options o;
  o.input = fixture("grid.obj");
  auto s = convert(o);
  const auto before = conv::emit_scene(s, o);
  s.positions[0] = 42.0f;
  const auto after = conv::emit_scene(s, o);
  ASSERT_EQ(before.size(), 4u);
  ASSERT_EQ(before[0].name, "grid.h");
  ASSERT_EQ(before[1].name, "grid.cpp");
  ASSERT_EQ(before[2].name, "grid.S");
  EXPECT_EQ(before[3].name, "grid." + conv::hash_hex(before[3].bytes) + ".bin");
  EXPECT_EQ(after[3].name, "grid." + conv::hash_hex(after[3].bytes) + ".bin");
  EXPECT_NE(before[3].name, after[3].name);
  EXPECT_EQ(before[1].bytes, after[1].bytes);
  EXPECT_EQ(before[2].bytes, after[2].bytes);
  EXPECT_NE(before[0].bytes, after[0].bytes);
  EXPECT_NE(before[0].bytes.find("\"" + before[3].name + "\""), std::string::npos);  // the header names its .bin
  // the stubs depend on the name only: another scene's stubs are the same text renamed
  conv::Options other;
  other.input = fixture("ngons_crlf.obj");
  other.name = "grid";
  const auto third = conv::emit_scene(convert(other), other);
  EXPECT_EQ(third[1].bytes, before[1].bytes);
  EXPECT_EQ(third[2].bytes, before[2].bytes);
}

TEST(Write, FailedConversionLeavesTargetUntouched) {
  const auto dir = scratch("atomic");
  ASSERT_EQ(run_converter({"-t", dir.string(), fixture("grid.obj").string()}).exit_code, 0);
  const auto before = snapshot(dir);
  const auto r = run_converter({"-n", "grid", "-t", dir.string(), fixture("bad/out_of_range.obj").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(snapshot(dir), before);
  // a missing target folder is not created on failure
  const auto missing = dir / "not_there";
  EXPECT_EQ(run_converter({"-t", missing.string(), fixture("bad/nan.obj").string()}).exit_code, 1);
  EXPECT_FALSE(fs::exists(missing));
  // a bad -a after a successful import: still nothing written
  EXPECT_EQ(run_converter({"-a", "Nope", "-t", missing.string(), fixture("grid.obj").string()}).exit_code, 1);
  EXPECT_FALSE(fs::exists(missing));
}

TEST(Write, UnchangedFilesAreNotRewrittenAndNoTempFilesRemain) {
  const auto dir = scratch("unchanged");
  ASSERT_EQ(run_converter({"-t", dir.string(), fixture("grid.obj").string()}).exit_code, 0);
  const auto t0 = fs::last_write_time(dir / "grid.cpp");
  // another bake with the same result must keep the old files (and their times)
  fs::last_write_time(dir / "grid.cpp", t0 - std::chrono::hours(1));
  const auto old = fs::last_write_time(dir / "grid.cpp");
  ASSERT_EQ(run_converter({"-t", dir.string(), fixture("grid.obj").string()}).exit_code, 0);
  EXPECT_EQ(fs::last_write_time(dir / "grid.cpp"), old);
  for (const auto& e : fs::directory_iterator(dir)) EXPECT_NE(e.path().filename().string()[0], '.') << e.path();
  EXPECT_EQ(snapshot(dir).size(), 4u);
  // a different bake replaces the .bin (new name) and deletes the old one; the stubs stay
  const auto cpp_before = read_file(dir / "grid.cpp");
  ASSERT_EQ(run_converter({"-a", "Cloth", "-t", dir.string(), fixture("grid.obj").string()}).exit_code, 0);
  EXPECT_EQ(fs::last_write_time(dir / "grid.cpp"), old);
  EXPECT_EQ(read_file(dir / "grid.cpp"), cpp_before);
  EXPECT_EQ(snapshot(dir).size(), 4u);
}

}  // namespace
