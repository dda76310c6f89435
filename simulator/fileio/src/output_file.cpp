#include <clothsim/output_file.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

namespace clothsim::io {

struct SignalHandlers::Saved {
  struct sigaction old[2];
  bool ok[2];
};

SignalHandlers::SignalHandlers(int a, int b, void (*handler)(int)) : sig_{a, b}, saved_(new Saved{}) {
  struct sigaction set {};
  set.sa_handler = handler;
  sigemptyset(&set.sa_mask);
  for (int k = 0; k < 2; ++k) saved_->ok[k] = ::sigaction(sig_[k], &set, &saved_->old[k]) == 0;
}

SignalHandlers::~SignalHandlers() {
  for (int k = 0; k < 2; ++k)
    if (saved_->ok[k]) ::sigaction(sig_[k], &saved_->old[k], nullptr);
  delete saved_;
}

namespace {

namespace fs = std::filesystem;

// 'path', on one line whatever the name holds.
std::string quote(const std::string& path) {
  std::string q = "'";
  for (const char c : path) q += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  return q + "'";
}

std::string error_text(int e) { return std::error_code(e, std::generic_category()).message(); }

std::string parent_dir(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

bool is_symlink(const std::string& path) {
  struct stat l {};
  return ::lstat(path.c_str(), &l) == 0 && S_ISLNK(l.st_mode);
}

// Empty, or why files cannot be created in the existing directory `dir`.
std::string check_writable_dir(const std::string& dir) {
  if (::faccessat(AT_FDCWD, dir.c_str(), W_OK | X_OK, AT_EACCESS) != 0)
    return "directory " + quote(dir) + " is not writable (" + error_text(errno) + ")";
  // The permission bits can say yes where no file can be made (/proc, some mounts, as root):
  // one is made and removed, so that a run does not fail only at its end.
  std::string probe = (dir.empty() ? std::string(".") : dir) + "/.clothsim-write-test-XXXXXX";
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) return "cannot create a file in " + quote(dir.empty() ? "." : dir) + " (" + error_text(errno) + ")";
  ::close(fd);
  ::unlink(probe.c_str());
  return {};
}

// Empty, or why `path` cannot be created in `dir` (a temporary file goes there too).
std::string in_writable_dir(const std::string& path, const std::string& dir) {
  const std::string why = check_writable_dir(dir);
  return why.empty() ? why : "cannot write " + quote(path) + ": " + why;
}

// While alive: SIGPIPE (a pipe or FIFO whose reader left) and SIGXFSZ (a file size limit)
// are ignored, so write() fails with EPIPE / EFBIG instead of the process being killed.
struct IgnoreWriteSignals : SignalHandlers {
  IgnoreWriteSignals() : SignalHandlers(SIGPIPE, SIGXFSZ, SIG_IGN) {}
};

// 0, or the errno of the failed write.
int write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return 0;
}

mode_t current_umask() {
  const mode_t m = ::umask(0);
  ::umask(m);
  return m;
}

// A regular file (or none yet) at `target`: a temporary file beside it, then rename. `shown`
// is the name the user gave (target is it with a symbolic link resolved). `old`: the file
// replaced, whose permissions and owner the new one keeps.
std::string replace_file(const std::string& shown, const std::string& target, std::string_view bytes,
                         const struct stat* old) {
  const auto fail = [&shown](int e) { return "cannot write " + quote(shown) + ": " + error_text(e); };
  std::string tmp = target + ".tmpXXXXXX";
  std::vector<char> name(tmp.begin(), tmp.end());
  name.push_back('\0');
  int fd = ::mkstemp(name.data());
  if (fd < 0 && errno == ENAMETOOLONG) {  // a file name near NAME_MAX: a short one beside it
    tmp = (fs::path(parent_dir(target)) / ".clothsim.tmpXXXXXX").string();
    name.assign(tmp.begin(), tmp.end());
    name.push_back('\0');
    fd = ::mkstemp(name.data());
  }
  if (fd < 0) return fail(errno);
  tmp = name.data();
  const mode_t mode = old ? (old->st_mode & 07777) : (0666 & ~current_umask());
  int e = ::fchmod(fd, mode) == 0 ? 0 : errno;
  if (e == 0 && old && (old->st_uid != ::geteuid() || old->st_gid != ::getegid()) && ::geteuid() == 0)
    if (::fchown(fd, old->st_uid, old->st_gid) != 0) e = errno;
  if (e == 0) {
    const IgnoreWriteSignals guard;
    e = write_all(fd, bytes);
  }
  if (::close(fd) != 0 && e == 0) e = errno;
  if (e == 0 && ::rename(tmp.c_str(), target.c_str()) != 0) e = errno;
  if (e != 0) {
    ::unlink(tmp.c_str());
    return fail(e);
  }
  return {};
}

// Not a regular file and not a directory: written where it is (a device, a FIFO, a pipe).
std::string write_in_place(const std::string& path, std::string_view bytes) {
  const auto fail = [&path](int e) { return "cannot write " + quote(path) + ": " + error_text(e); };
  // O_NONBLOCK: a FIFO without a reader fails (ENXIO) instead of blocking forever.
  const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    struct stat st {};
    if (e == ENXIO && ::stat(path.c_str(), &st) == 0 && S_ISFIFO(st.st_mode))
      return "cannot write " + quote(path) + ": a FIFO with no reader";
    if (e == ENXIO && ::stat(path.c_str(), &st) == 0 && S_ISSOCK(st.st_mode))
      return "cannot write " + quote(path) + ": it is a socket";
    return fail(e);
  }
  struct stat st {};
  int e = ::fstat(fd, &st) == 0 ? 0 : errno;
  if (e == 0 && S_ISREG(st.st_mode)) {  // replaced by a regular file since the caller looked
    ::close(fd);
    return write_output_file(path, bytes);
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (e == 0 && (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0)) e = errno;
  if (e == 0) {
    const IgnoreWriteSignals guard;
    e = write_all(fd, bytes);
  }
  if (::close(fd) != 0 && e == 0) e = errno;
  return e == 0 ? std::string() : fail(e);
}

}  // namespace

std::string check_output_file(const std::string& path) {
  if (path.empty()) return "no file name given";
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) return quote(path) + " is a directory (give a file name)";
    if (S_ISSOCK(st.st_mode)) return quote(path) + " is a socket";
    if (!S_ISREG(st.st_mode)) return {};  // a device or a FIFO: written in place
    if (is_symlink(path)) {
      char* real = ::realpath(path.c_str(), nullptr);
      if (!real) return "cannot write " + quote(path) + ": " + error_text(errno);
      const std::string target = real;
      std::free(real);
      return in_writable_dir(path, parent_dir(target));
    }
    return in_writable_dir(path, parent_dir(path));
  }
  const int e = errno;
  if (e != ENOENT) return "cannot write " + quote(path) + ": " + error_text(e);
  if (is_symlink(path)) return quote(path) + " is a symbolic link to a missing file";
  const std::string parent = parent_dir(path);
  if (::stat(parent.c_str(), &st) != 0) {
    if (errno == ENOENT) return "cannot write " + quote(path) + ": directory " + quote(parent) + " does not exist";
    return "cannot write " + quote(path) + ": " + error_text(errno);
  }
  if (!S_ISDIR(st.st_mode)) return "cannot write " + quote(path) + ": " + quote(parent) + " is not a directory";
  return in_writable_dir(path, parent);
}

std::string check_output_dir(const std::string& dir) {
  if (dir.empty()) return "no directory name given";
  // The directory, or the nearest ancestor that exists (the rest is created later).
  fs::path p = dir;
  for (;;) {
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0) {
      if (!S_ISDIR(st.st_mode)) return quote(p.string()) + " is not a directory";
      return check_writable_dir(p.string());
    }
    if (errno != ENOENT && errno != ENOTDIR) return "cannot use " + quote(p.string()) + ": " + error_text(errno);
    fs::path up = p.parent_path();
    if (up.empty()) up = ".";
    if (up == p) return "cannot use " + quote(dir) + ": " + error_text(ENOENT);
    p = up;
  }
}

std::string output_identity(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) p = fs::absolute(path).lexically_normal();
  while (!p.empty() && !p.has_filename() && p != p.root_path()) p = p.parent_path();  // "dir/" is "dir"
  return p.string();
}

std::string same_output(std::initializer_list<std::pair<std::string_view, std::string>> outputs) {
  std::vector<std::pair<std::string_view, fs::path>> seen;
  for (const auto& [option, path] : outputs) {
    if (path.empty()) continue;
    struct stat st {};
    // A device (/dev/null) takes every output written into it: no output is lost there.
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) continue;
    const fs::path p = output_identity(path);
    for (const auto& [other, q] : seen)
      if (q == p) return std::string(other) + " and " + std::string(option) + " both name " + quote(path);
    seen.emplace_back(option, p);
  }
  return {};
}

std::string write_output_file(const std::string& path, std::string_view bytes) {
  if (path.empty()) return "no file name given";
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int e = errno;
    if (e != ENOENT) return "cannot write " + quote(path) + ": " + error_text(e);
    if (is_symlink(path)) return quote(path) + " is a symbolic link to a missing file";
    return replace_file(path, path, bytes, nullptr);
  }
  if (S_ISDIR(st.st_mode)) return quote(path) + " is a directory (give a file name)";
  if (!S_ISREG(st.st_mode)) return write_in_place(path, bytes);
  if (!is_symlink(path)) return replace_file(path, path, bytes, &st);
  char* real = ::realpath(path.c_str(), nullptr);
  if (!real) return "cannot write " + quote(path) + ": " + error_text(errno);
  const std::string target = real;
  std::free(real);
  return replace_file(path, target, bytes, &st);
}

}  // namespace clothsim::io
