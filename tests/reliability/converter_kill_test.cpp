// Killing the converter while it writes leaves either the old outputs or the new ones, never a
// mix. Deterministic, no timing: strace's fault injection delivers SIGKILL at the entry of the
// K-th writev (file contents), rename (publishing) or unlink (clean-up) system call, for every K.
// After each kill: every visible file is a complete old or new version, and the set builds
// into a program that reads exactly the old scene or exactly the new one.
#include <gtest/gtest.h>

#include <cstdlib>
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

std::string quote(const fs::path& p) {
  std::string q(1, '\'');  // built by appends: GCC 12 warns falsely (-Wrestrict) on "'" + s + "'"
  q.append(p.string());
  q.push_back('\'');
  return q;
}

// Builds the scene in `dir` with a program that prints what it reads; "" if it does not build.
std::string build_and_read(const fs::path& dir) {
  TempDir build("killbuild");
  reliability::write_file(build.path / "main.cpp", R"(#include <cstdio>
#include "dice.h"
int main() {
  const auto& s = b2o::gen::dice::scene;
  unsigned long long h = 14695981039346656037ull;
  const auto* p = reinterpret_cast<const unsigned char*>(s.positions);
  for (unsigned i = 0; i < s.vertex_count * 3u * 4u; ++i) h = (h ^ p[i]) * 1099511628211ull;
  std::printf("%u %u %u %llx\n", s.vertex_count, s.index_count, s.cloth_count, h);
}
)");
  const std::string cmd = std::string(CXX_COMPILER) + " -std=c++20 -w -I" + B2O_INCLUDE + " -I" + quote(dir) + " " +
                          quote(build.path / "main.cpp") + " " + quote(dir / "dice.cpp") + " " + quote(dir / "dice.S") +
                          " -o " + quote(build.path / "prog") + " && " + quote(build.path / "prog");
  const Result r = reliability::run({"/bin/sh", "-c", cmd}, {}, 120.0);
  return r.exit_code == 0 ? r.out : "";
}

struct Fixture {
  TempDir work{"kill"};
  fs::path model, target;
  std::map<std::string, std::string> old_set, new_set;
  std::string old_reads, new_reads;

  Fixture() {
    for (const char* f : {"dice.obj", "dice.mtl", "die_faces.png", "plane_tiles.png"})
      fs::copy_file(kModels / "dice" / f, work.path / f);
    model = work.path / "dice.obj";
    target = work.path / "target";
    old_set = convert(kOld, work.path / "old");
    new_set = convert(kNew, work.path / "new");
    old_reads = build_and_read(work.path / "old");
    new_reads = build_and_read(work.path / "new");
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
    // LeakSanitizer cannot run under ptrace: off for the traced run in sanitizer builds.
    const char* asan = std::getenv("ASAN_OPTIONS");
    const std::string asan_options = std::string("ASAN_OPTIONS=") + (asan != nullptr ? asan : "") + ":detect_leaks=0";
    return reliability::run(argv, {asan_options});
  }
};

TEST(Interrupted, KilledAnywhereLeavesTheOldOrTheNewScene) {
  const std::string strace = find_strace();
  if (strace.empty()) GTEST_SKIP() << "strace not installed (cmake/install-deps.sh installs it)";
  Fixture fx;
  ASSERT_FALSE(fx.old_reads.empty()) << "the old set does not build";
  ASSERT_FALSE(fx.new_reads.empty()) << "the new set does not build";
  ASSERT_NE(fx.old_reads, fx.new_reads) << "old and new should differ";
  std::map<std::map<std::string, std::string>, std::string> reads_of;  // each distinct state built once
  int killed = 0;
  for (const std::string syscall : {"writev", "rename", "unlink"}) {
    for (int k = 1; k <= static_cast<int>(fx.new_set.size()) + 1; ++k) {
      SCOPED_TRACE(syscall + " #" + std::to_string(k));
      const Result r = fx.run_killed(strace, syscall, k);
      if (r.exit_code == 0) {  // fewer such calls than k: it finished
        EXPECT_EQ(outputs(fx.target), fx.new_set);
        continue;
      }
      // strace ends itself with the tracee's signal.
      EXPECT_TRUE(r.signal == SIGKILL || r.exit_code == 128 + SIGKILL) << "not killed: exit " << r.exit_code << "\n" << r.err;
      ++killed;
      const auto got = outputs(fx.target);
      for (const auto& [name, bytes] : got) {
        const bool is_old = fx.old_set.count(name) != 0 && fx.old_set.at(name) == bytes;
        const bool is_new = fx.new_set.count(name) != 0 && fx.new_set.at(name) == bytes;
        EXPECT_TRUE(is_old || is_new) << name << " is neither a complete old nor a complete new output";
      }
      auto it = reads_of.find(got);
      if (it == reads_of.end()) it = reads_of.emplace(got, build_and_read(fx.target)).first;
      EXPECT_TRUE(it->second == fx.old_reads || it->second == fx.new_reads)
          << "the outputs left behind read as '" << it->second << "', neither the old scene ('" << fx.old_reads
          << "') nor the new one ('" << fx.new_reads << "')";
      // The next run repairs everything.
      std::vector<std::string> argv = {kExe};
      argv.insert(argv.end(), kNew.begin(), kNew.end());
      argv.insert(argv.end(), {"-t", fx.target.string(), fx.model.string()});
      const Result again = reliability::run(argv);
      EXPECT_EQ(again.exit_code, 0) << again.err;
      EXPECT_EQ(outputs(fx.target), fx.new_set);
    }
  }
  EXPECT_GE(killed, 4) << "the kill points should hit the writes and the renames";
  std::cout << "[ killed ] " << killed << " kill points, " << reads_of.size() << " distinct states left behind\n";
}

}  // namespace
