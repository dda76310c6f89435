// Killing the converter while it writes leaves, for every output, either the old complete file
// or the new complete file. Deterministic, no timing: strace's fault injection delivers SIGKILL
// at the entry of the K-th writev (file contents) or rename (publishing) system call, for every K.
#include <gtest/gtest.h>

#include <map>

#include "process.hpp"

namespace fs = std::filesystem;
using reliability::Result;
using reliability::TempDir;

namespace {

const std::string kExe = B2O_EXE;
const fs::path kModels = MODELS_DIR;
const std::vector<std::string> kOld = {"-a", "RollingDie"};
const std::vector<std::string> kNew = {"-a", "RollingDie", "-a", "Die", "-r"};

std::string find_strace() {
  for (const char* p : {"/usr/bin/strace", "/bin/strace"})
    if (fs::exists(p)) return p;
  return "";
}

// The visible outputs of a folder (temp files start with '.'): name -> bytes.
std::map<std::string, std::string> outputs(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string()[0] != '.') out[e.path().filename().string()] = reliability::read_file(e.path());
  return out;
}

struct Fixture {
  TempDir work{"kill"};
  fs::path model, target;
  std::map<std::string, std::string> old_set, new_set;

  Fixture() {
    for (const char* f : {"dice.obj", "dice.mtl", "die_faces.png", "plane_tiles.png"})
      fs::copy_file(kModels / "dice" / f, work.path / f);
    model = work.path / "dice.obj";
    target = work.path / "target";
    old_set = convert(kOld, work.path / "old");
    new_set = convert(kNew, work.path / "new");
  }
  std::map<std::string, std::string> convert(const std::vector<std::string>& opts, const fs::path& dir) const {
    std::vector<std::string> argv = {kExe};
    argv.insert(argv.end(), opts.begin(), opts.end());
    argv.insert(argv.end(), {"-t", dir.string(), model.string()});
    const Result r = reliability::run(argv);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return outputs(dir);
  }
  // Old outputs in the target, then the new conversion killed at the K-th `syscall`.
  Result run_killed(const std::string& strace, const std::string& syscall, int k) const {
    fs::remove_all(target);
    fs::create_directories(target);
    for (const auto& [name, bytes] : old_set) reliability::write_file(target / name, bytes);
    std::vector<std::string> argv = {strace, "-qq", "-f", "-o", "/dev/null", "-e", "trace=" + syscall,
                                     "-e", "inject=" + syscall + ":signal=SIGKILL:when=" + std::to_string(k), kExe};
    argv.insert(argv.end(), kNew.begin(), kNew.end());
    argv.insert(argv.end(), {"-t", target.string(), model.string()});
    return reliability::run(argv);
  }
};

// Compiles and links the scene in `dir` with a main that reads it.
bool builds(const fs::path& dir) {
  reliability::write_file(dir / "main.cpp", "#include \"dice.h\"\nint main() { return static_cast<int>(b2o::gen::dice::scene.vertex_count & 1u); }\n");
  const std::string cmd = std::string(CXX_COMPILER) + " -std=c++20 -w -I" + B2O_INCLUDE + " -I'" + dir.string() + "' '" +
                          (dir / "main.cpp").string() + "' '" + (dir / "dice.cpp").string() + "' '" +
                          (dir / "dice.S").string() + "' -o '" + (dir / "prog").string() + "'";
  const Result r = reliability::run({"/bin/sh", "-c", cmd});
  fs::remove(dir / "main.cpp");
  fs::remove(dir / "prog");
  return r.exit_code == 0;
}

// For each kill point: does every output hold a complete old or new version, and is the set
// all-old or all-new? Returns the number of kill points that actually killed.
int kill_everywhere(const Fixture& fx, const std::string& strace, bool check_set) {
  int killed = 0;
  for (const std::string syscall : {"writev", "rename"}) {
    for (int k = 1; k <= static_cast<int>(fx.new_set.size()) + 1; ++k) {
      SCOPED_TRACE(syscall + " #" + std::to_string(k));
      const Result r = fx.run_killed(strace, syscall, k);
      if (r.exit_code == 0) {  // fewer calls than k: it finished
        EXPECT_EQ(outputs(fx.target), fx.new_set);
        continue;
      }
      ++killed;
      const auto got = outputs(fx.target);
      EXPECT_EQ(got.size(), fx.old_set.size()) << "an output disappeared or a stray file appeared";
      if (got.size() != fx.old_set.size()) continue;
      int old_count = 0, new_count = 0;
      for (const auto& [name, bytes] : got) {
        const bool is_old = fx.old_set.at(name) == bytes, is_new = fx.new_set.at(name) == bytes;
        EXPECT_TRUE(is_old || is_new) << name << " is neither the old nor the new version (" << bytes.size()
                                      << " bytes)";
        old_count += is_old;
        new_count += is_new && !is_old;
      }
      const bool mixed = old_count != static_cast<int>(got.size()) && new_count != static_cast<int>(got.size());
      if (check_set && mixed) {
        // The converter's design: a mixed set may exist on disk but must never build.
        EXPECT_FALSE(builds(fx.target)) << old_count << " old and " << new_count << " new outputs build together";
      }
      // The next run repairs everything.
      std::vector<std::string> argv = {kExe};
      argv.insert(argv.end(), kNew.begin(), kNew.end());
      argv.insert(argv.end(), {"-t", fx.target.string(), fx.model.string()});
      const Result again = reliability::run(argv);
      EXPECT_EQ(again.exit_code, 0) << again.err;
      EXPECT_EQ(outputs(fx.target), fx.new_set);
    }
  }
  return killed;
}

TEST(Interrupted, EachOutputIsOldOrNewNeverTorn) {
  const std::string strace = find_strace();
  if (strace.empty()) GTEST_SKIP() << "strace not installed (cmake/install-deps.sh installs it)";
  Fixture fx;
  ASSERT_EQ(fx.old_set.size(), fx.new_set.size());
  for (const auto& [name, bytes] : fx.new_set) ASSERT_NE(fx.old_set.at(name), bytes) << name << " should change";
  EXPECT_GE(kill_everywhere(fx, strace, false), 2 * static_cast<int>(fx.new_set.size()));
}

// Known issue (reported to the converter): the outputs are published with one rename each
// (.bin, .S, .cpp, .h), so a kill between two renames leaves old and new files side by side.
// The converter ties .h/.cpp/.S together by a bake id (a mix fails to build), but not the .bin:
// a kill right after the .bin's rename leaves the old .S reading the new .bin at the old
// offsets, and that builds. Enable once the .bin is tied in too (e.g. named by its hash).
TEST(KnownIssues, DISABLED_KilledWriteLeavesNoMixThatBuilds) {
  const std::string strace = find_strace();
  if (strace.empty()) GTEST_SKIP() << "strace not installed";
  Fixture fx;
  kill_everywhere(fx, strace, true);
}

}  // namespace
