// A converter killed at any point leaves the committed set (the header, the .bin it names and
// the fixed .cpp/.S stubs) either all old or all new, never a mix, and that set builds.
// Deterministic, no timing: the test-only hook B2O_FAULT_AFTER_WRITES=K ends the process
// (_exit 86) before its (K+1)-th file operation, for every K until a run completes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "support.hpp"

namespace {

using namespace b2o::test;

constexpr int kFaultExit = 86;
const std::vector<std::string> kOld = {"-a", "Cloth"};
const std::vector<std::string> kNew = {"-a", "Cloth", "-r", "--param", "dt=0.002"};

using Files = std::map<std::string, std::string>;

// The visible files of a folder (temp files start with '.').
Files visible(const fs::path& dir) {
  Files out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string()[0] != '.') out[e.path().filename().string()] = read_file(e.path());
  return out;
}

// The .bin a header names in its .incbin lines ("" when none).
std::string bin_named_by(const std::string& header) {
  const std::string key = ".incbin \"";
  const auto p = header.find(key);
  if (p == std::string::npos) return "";
  return header.substr(p + key.size(), header.find('"', p + key.size()) - p - key.size());
}

// What a build of `dir` reads: the header, the stubs and the .bin the header names.
Files committed(const fs::path& dir) {
  Files out;
  for (const char* f : {"grid.h", "grid.cpp", "grid.S"})
    if (fs::exists(dir / f)) out[f] = read_file(dir / f);
  const std::string bin = bin_named_by(out["grid.h"]);
  if (!bin.empty() && fs::exists(dir / bin)) out[bin] = read_file(dir / bin);
  return out;
}

ProcessResult convert_into(const fs::path& dir, const std::vector<std::string>& opts, long fault_after = -1) {
  std::string cmd = fault_after >= 0 ? "B2O_FAULT_AFTER_WRITES=" + std::to_string(fault_after) + " " : "";
  cmd += shell_quote(B2O_CONVERTER);
  for (const auto& a : opts) cmd += " " + shell_quote(a);
  cmd += " -t " + shell_quote(dir.string()) + " " + shell_quote(fixture("grid.obj").string());
  return run_command(cmd);
}

// Builds the set in `dir` and runs a program that prints what it linked: whether the cloth has
// a vertex->mass map, the number of params, and the first position's bits.
std::string build_and_read(const fs::path& dir) {
  const fs::path work = dir.parent_path() / (dir.filename().string() + "_build");
  fs::remove_all(work);
  write_file(work / "main.cpp",
             "#include \"grid.h\"\n#include <cstdio>\n#include <cstring>\n"
             "int main() {\n"
             "  const b2o::Scene& s = b2o::gen::grid::scene;\n"
             "  unsigned bits = 0;\n  std::memcpy(&bits, s.positions, 4);\n"
             "  std::printf(\"%d %u %08x\\n\", s.cloths[0].vertex_mass != nullptr ? 1 : 0, s.param_count, bits);\n"
             "}\n");
  const std::string cmd = "g++ -std=c++20 -Wall -Wextra -Wpedantic -Werror -I" + shell_quote(B2O_INCLUDE) + " -I" +
                          shell_quote(dir.string()) + " " + shell_quote((work / "main.cpp").string()) + " " +
                          shell_quote((dir / "grid.cpp").string()) + " " + shell_quote((dir / "grid.S").string()) +
                          " -o " + shell_quote((work / "prog").string()) + " && " + shell_quote((work / "prog").string());
  const auto r = run_command(cmd);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.output;
}

std::string expected_reading(const Files& set, bool is_new) {
  const auto bin = std::find_if(set.begin(), set.end(), [](const auto& f) { return f.first.ends_with(".bin"); });
  unsigned bits = 0;
  std::memcpy(&bits, bin->second.data(), 4);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%d %u %08x\n", is_new ? 1 : 0, is_new ? 1u : 0u, bits);
  return buf;
}

TEST(Kill, EveryKillPointLeavesAllOldOrAllNewAndItBuilds) {
  const auto old_dir = scratch("kill_old"), new_dir = scratch("kill_new");
  ASSERT_EQ(convert_into(old_dir, kOld).exit_code, 0);
  ASSERT_EQ(convert_into(new_dir, kNew).exit_code, 0);
  const Files old_set = visible(old_dir), new_set = visible(new_dir);
  ASSERT_EQ(old_set.size(), 4u);
  ASSERT_EQ(committed(old_dir), old_set);
  ASSERT_EQ(committed(new_dir), new_set);
  ASSERT_NE(old_set.at("grid.h"), new_set.at("grid.h"));
  ASSERT_NE(bin_named_by(old_set.at("grid.h")), bin_named_by(new_set.at("grid.h")));  // the .bin changes too

  const fs::path target = fs::path(B2O_SCRATCH) / "kill_target";
  auto start_from_old = [&] {
    fs::remove_all(target);
    for (const auto& [name, bytes] : old_set) write_file(target / name, bytes);
  };
  std::vector<bool> new_at;  // per kill point: is the committed set the new one?
  long operations = -1;
  for (long k = 0; k < 100 && operations < 0; ++k) {
    SCOPED_TRACE("killed before file operation " + std::to_string(k + 1));
    start_from_old();
    const auto r = convert_into(target, kNew, k);
    if (r.exit_code == 0) {  // k operations were all it needed
      operations = k;
      EXPECT_EQ(visible(target), new_set);
      break;
    }
    ASSERT_EQ(r.exit_code, kFaultExit) << r.output;
    const Files set = committed(target);
    const bool is_old = set == old_set, is_new = set == new_set;
    EXPECT_TRUE(is_old || is_new) << "a mix of old and new files is committed";
    new_at.push_back(is_new);
    // No torn or foreign file: everything visible is a complete old or new output.
    for (const auto& [name, bytes] : visible(target)) {
      const bool from_old = old_set.count(name) && old_set.at(name) == bytes;
      const bool from_new = new_set.count(name) && new_set.at(name) == bytes;
      EXPECT_TRUE(from_old || from_new) << name;
    }
    // The next run completes the bake and removes what the killed one left (temp files too).
    ASSERT_EQ(convert_into(target, kNew).exit_code, 0);
    EXPECT_EQ(visible(target), new_set);
    for (const auto& e : fs::directory_iterator(target)) EXPECT_NE(e.path().filename().string()[0], '.') << e.path();
  }
  ASSERT_GE(operations, 5) << "temp .bin and .h, two renames, one delete";
  ASSERT_EQ(new_at.size(), static_cast<std::size_t>(operations));
  // Old until the header's rename, new from then on (exactly one switch).
  EXPECT_FALSE(new_at.front());
  EXPECT_TRUE(new_at.back());
  EXPECT_TRUE(std::is_sorted(new_at.begin(), new_at.end()));

  // The first, a middle and the last kill point build, and read the bake they committed.
  for (long k : {0L, operations / 2, operations - 1}) {
    SCOPED_TRACE("built after a kill before operation " + std::to_string(k + 1));
    start_from_old();
    ASSERT_EQ(convert_into(target, kNew, k).exit_code, kFaultExit);
    const bool is_new = new_at[static_cast<std::size_t>(k)];
    EXPECT_EQ(build_and_read(target), expected_reading(is_new ? new_set : old_set, is_new));
  }
}

// A first bake into a new folder, killed anywhere: no header (nothing committed) or the whole set.
TEST(Kill, FirstBakeIsAllOrNothing) {
  const auto ref = scratch("kill_first_ref");
  ASSERT_EQ(convert_into(ref, kNew).exit_code, 0);
  const Files new_set = visible(ref);
  const fs::path target = fs::path(B2O_SCRATCH) / "kill_first";
  bool completed = false;
  for (long k = 0; k < 100 && !completed; ++k) {
    SCOPED_TRACE("killed before file operation " + std::to_string(k + 1));
    fs::remove_all(target);
    const auto r = convert_into(target, kNew, k);
    completed = r.exit_code == 0;
    if (!completed) {
      ASSERT_EQ(r.exit_code, kFaultExit) << r.output;
    }
    if (!fs::exists(target / "grid.h")) continue;  // nothing committed
    EXPECT_EQ(committed(target), new_set);
  }
  EXPECT_TRUE(completed);
}

}  // namespace
