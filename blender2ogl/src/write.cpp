// Atomic output: every file goes to a temp file in the target folder first; only when all
// are written are they renamed over the old ones, the first file of the list (the header, the
// commit point) last. Files whose bytes are unchanged are left alone, so builds do not
// recompile what did not change.
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>

#include <signal.h>
#include <unistd.h>

#include "converter.hpp"

namespace b2o::conv {
namespace {

bool same_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec) || std::filesystem::file_size(p, ec) != bytes.size()) return false;
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return in.good() && ss.str() == bytes;
}

// Test-only fault hook: B2O_FAULT_AFTER_WRITES=K ends the process (_exit, exit status
// kFaultExit, no clean-up) before its (K+1)-th file operation (write of a temp file, mkdir,
// rename, delete), as a kill there would.
constexpr int kFaultExit = 86;
void file_operation() {
  static const long limit = [] {
    const char* v = std::getenv("B2O_FAULT_AFTER_WRITES");
    return v != nullptr && *v != '\0' ? std::strtol(v, nullptr, 10) : -1L;
  }();
  static long done = 0;
  if (limit >= 0 && done >= limit) ::_exit(kFaultExit);
  ++done;
}

}  // namespace

namespace {

// Creates `dir` and its missing parents, recording each folder made (top first) so a failed
// run can take them away again.
void make_dirs(const std::filesystem::path& dir, std::vector<std::filesystem::path>& made) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> missing;
  for (fs::path p = dir; !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  if (missing.empty()) {
    if (!fs::is_directory(dir, ec)) throw InputError(dir.string() + ": target exists and is not a directory");
    return;
  }
  file_operation();
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    fs::create_directory(*it, ec);
    if (ec) throw InputError(dir.string() + ": cannot create target folder: " + ec.message());
    made.push_back(*it);
  }
}

}  // namespace

int write_outputs(const std::filesystem::path& dir, const std::vector<OutputFile>& files,
                  const std::vector<std::pair<std::filesystem::path, std::string>>& extra) {
  namespace fs = std::filesystem;
  std::error_code ec;
  static std::atomic<unsigned> counter{0};
  struct Target {
    fs::path path;
    const std::string* bytes;
    bool direct = false;  // a character device or FIFO in its place: written into, never renamed over
  };
  // The order of publication: the extras (the depfile), then the files in reverse order: the
  // header, which the build and readers start from, last.
  std::vector<Target> targets;
  for (const auto& [path, bytes] : extra) targets.push_back({path, &bytes});
  for (auto it = files.rbegin(); it != files.rend(); ++it) targets.push_back({dir / it->name, &it->bytes});

  std::vector<fs::path> made;                          // folders created, top first
  std::vector<std::pair<fs::path, fs::path>> pending;  // temp -> final
  auto cleanup = [&] {
    for (const auto& [tmp, final_path] : pending) fs::remove(tmp, ec);
    for (auto it = made.rbegin(); it != made.rend(); ++it) fs::remove(*it, ec);
  };
  try {
    // What is in each output's place, before anything is written: a regular file (or nothing)
    // is replaced by a rename; a character device or FIFO (--depfile /dev/null) is written
    // into; anything else (a folder, a block device, a socket, a symbolic link to a file) is
    // refused. A rename never replaces something that is not a regular file.
    for (Target& t : targets) {
      const fs::file_status link = fs::symlink_status(t.path, ec);
      if (!fs::exists(link) || fs::is_regular_file(link)) continue;
      const fs::file_status target = fs::status(t.path, ec);
      if (fs::is_character_file(target) || fs::is_fifo(target)) {
        t.direct = true;
        continue;
      }
      throw InputError(t.path.string() + ": cannot write: " +
                       (fs::is_directory(target) ? "a folder" : "something other than a file") + " is in the way");
    }
    make_dirs(dir, made);
    for (const auto& [path, bytes] : extra) {
      try {
        make_dirs(path.parent_path().empty() ? fs::path(".") : path.parent_path(), made);
      } catch (const InputError& e) {
        throw InputError(path.string() + ": cannot write: " + e.what());
      }
    }
    for (const Target& t : targets) {
      if (t.direct || same_bytes(t.path, *t.bytes)) continue;
      file_operation();
      const fs::path folder = t.path.parent_path().empty() ? fs::path(".") : t.path.parent_path();
      const fs::path tmp = folder / ("." + t.path.filename().string() + ".tmp" + std::to_string(::getpid()) + "." +
                                     std::to_string(counter++));
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (out) out.write(t.bytes->data(), static_cast<std::streamsize>(t.bytes->size()));
      if (out) out.close();
      if (!out) {
        const std::string why = std::strerror(errno);
        fs::remove(tmp, ec);
        throw InputError(t.path.string() + ": cannot write: " + why);
      }
      pending.emplace_back(tmp, t.path);
    }
    // Commit: devices first (they can fail, a rename hardly), then the renames in order.
    for (const Target& t : targets) {
      if (!t.direct) continue;
      file_operation();
      std::ofstream out(t.path, std::ios::binary | std::ios::out);
      if (out) out.write(t.bytes->data(), static_cast<std::streamsize>(t.bytes->size()));
      if (out) out.close();
      if (!out) throw InputError(t.path.string() + ": cannot write: " + std::strerror(errno));
    }
    for (const auto& [tmp, final_path] : pending) {
      file_operation();
      fs::rename(tmp, final_path, ec);
      if (ec) throw InputError(final_path.string() + ": cannot write: " + ec.message());
    }
  } catch (...) {
    cleanup();
    throw;
  }
  return static_cast<int>(pending.size());
}

void remove_stale_bins(const std::filesystem::path& dir, const std::string& name, const std::vector<OutputFile>& keep,
                       const std::vector<std::filesystem::path>& protect) {
  namespace fs = std::filesystem;
  // Only names this converter makes for this scene: <name>.<16 hex digits>.bin, and temp files
  // .<output>.tmp<pid>.<n> of a converter that was killed (its process is gone).
  const std::string outputs = name + R"((\.[0-9a-f]{16}\.bin|\.h|\.cpp|\.S))";
  const std::regex ours(name + R"(\.[0-9a-f]{16}\.bin)"), temp("\\." + outputs + R"(\.tmp([0-9]{1,9})\.[0-9]+)");
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string file = it->path().filename().string();
    bool kept = false;
    for (const OutputFile& f : keep) kept = kept || f.name == file;
    std::smatch m;
    const bool dead_temp = std::regex_match(file, m, temp) && std::stol(m[2].str()) != ::getpid() &&
                           ::kill(static_cast<pid_t>(std::stol(m[2].str())), 0) != 0 && errno == ESRCH;
    if (((!kept && std::regex_match(file, ours)) || dead_temp) && it->is_regular_file(ec)) stale.push_back(it->path());
  }
  for (const fs::path& p : stale) {
    bool input = false;
    for (const fs::path& in : protect) input = input || fs::equivalent(p, in, ec);
    if (input) continue;
    file_operation();
    fs::remove(p, ec);  // best effort: a stale .bin left behind is harmless (nothing refers to it)
  }
}

}  // namespace b2o::conv
