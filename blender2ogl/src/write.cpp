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

int write_outputs(const std::filesystem::path& dir, const std::vector<OutputFile>& files) {
  namespace fs = std::filesystem;
  std::error_code ec;
  bool created_dir = false;
  if (!fs::is_directory(dir, ec)) {
    if (fs::exists(dir, ec)) throw InputError(dir.string() + ": target exists and is not a directory");
    file_operation();
    fs::create_directories(dir, ec);
    if (ec) throw InputError(dir.string() + ": cannot create target folder: " + ec.message());
    created_dir = true;
  }
  static std::atomic<unsigned> counter{0};
  std::vector<std::pair<fs::path, fs::path>> pending;  // temp -> final
  auto cleanup = [&] {
    for (const auto& [tmp, final_path] : pending) fs::remove(tmp, ec);
    if (created_dir) fs::remove(dir, ec);
  };
  // Anything but a regular file in an output's place fails before anything is written.
  for (const OutputFile& f : files) {
    const fs::path final_path = dir / f.name;
    if (fs::exists(fs::symlink_status(final_path, ec)) && !fs::is_regular_file(fs::symlink_status(final_path, ec))) {
      cleanup();
      throw InputError(final_path.string() + ": cannot write: something other than a file is in the way");
    }
  }
  // Published in reverse order: the header, which the build and readers start from, last.
  for (auto it = files.rbegin(); it != files.rend(); ++it) {
    const OutputFile& f = *it;
    const fs::path final_path = dir / f.name;
    if (same_bytes(final_path, f.bytes)) continue;
    file_operation();
    const fs::path tmp = dir / ("." + f.name + ".tmp" + std::to_string(::getpid()) + "." + std::to_string(counter++));
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (out) out.write(f.bytes.data(), static_cast<std::streamsize>(f.bytes.size()));
    if (out) out.close();
    if (!out) {
      const std::string why = std::strerror(errno);
      fs::remove(tmp, ec);
      cleanup();
      throw InputError(final_path.string() + ": cannot write: " + why);
    }
    pending.emplace_back(tmp, final_path);
  }
  for (const auto& [tmp, final_path] : pending) {
    file_operation();
    fs::rename(tmp, final_path, ec);
    if (ec) {
      const std::string why = ec.message();
      cleanup();
      throw InputError(final_path.string() + ": cannot write: " + why);
    }
  }
  return static_cast<int>(pending.size());
}

void remove_stale_bins(const std::filesystem::path& dir, const std::string& name, const std::vector<OutputFile>& keep) {
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
    file_operation();
    fs::remove(p, ec);  // best effort: a stale .bin left behind is harmless (nothing refers to it)
  }
}

}  // namespace b2o::conv
