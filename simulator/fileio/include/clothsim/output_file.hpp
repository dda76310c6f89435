// The one rule for every file the simulator writes (the --report JSON, PNGs from --screenshot,
// --frames and the P key, --export-obj OBJ files, clothsim_wp's CSV and SVG):
//
//   the target is a directory          -> refused, with a message naming it;
//   it exists and is no regular file   -> written in place, never replaced (/dev/null works,
//   (a character device, a FIFO, ...)     /dev/full is an I/O error; a FIFO without a reader
//                                         is an error, not a hang);
//   a regular file, or nothing yet     -> a temporary file in the same directory, renamed over
//                                         it: a reader sees the old file or the new one. Any
//                                         failure (open, write, close, rename) is reported and
//                                         leaves the old file untouched and no temporary file.
//                                         A symbolic link to a regular file stays a link: the
//                                         file it names is replaced.
//
// The checks run before a (possibly long) simulation so a bad path is bad input (exit 2)
// found at once; the writes repeat them, since the file system may change meanwhile.
// Messages are one line, name the file, and carry no program or option prefix.
#pragma once

#include <initializer_list>
#include <string>
#include <utility>
#include <string_view>

namespace clothsim::io {

/// While alive: `handler` (SIG_IGN, or a function) for the two signals `a` and `b`; the
/// previous handlers come back at destruction. (Writes ignore SIGPIPE and SIGXFSZ with it; the
/// app catches SIGINT and SIGTERM during a headless run.)
class SignalHandlers {
 public:
  SignalHandlers(int a, int b, void (*handler)(int));
  ~SignalHandlers();
  SignalHandlers(const SignalHandlers&) = delete;
  SignalHandlers& operator=(const SignalHandlers&) = delete;

 private:
  int sig_[2];
  struct Saved;
  Saved* saved_;  // the previous handlers (struct sigaction is POSIX; kept out of this header)
};

/// Before a run: can `path` be written by write_output_file()? Empty, or why not: a
/// directory, a socket, a missing or unwritable parent directory, a dangling symbolic link.
std::string check_output_file(const std::string& path);

/// Before a run: can files be written into directory `dir` (created later when missing)?
/// Empty, or why not: it (or the nearest existing ancestor) is no directory, or not writable.
std::string check_output_dir(const std::string& dir);

/// Before a run: do two of the outputs (option name, path; an empty path: not given) name the
/// same file or directory (after `.`, `..` and symbolic links)? Empty, or "--a and --b both
/// name 'path'": the first output written would be lost to the second, or stop it.
std::string same_output(std::initializer_list<std::pair<std::string_view, std::string>> outputs);

/// The absolute path an output names, after `.`, `..` and symbolic links (of the part that
/// exists), without a trailing '/': two outputs with the same identity are one file.
std::string output_identity(const std::string& path);

/// Writes `bytes` to `path` by the rule above. Empty on success, else a one-line error.
/// SIGPIPE and SIGXFSZ are ignored while writing: a closed pipe or a file size limit is an
/// error message, not a killed process.
std::string write_output_file(const std::string& path, std::string_view bytes);

}  // namespace clothsim::io
