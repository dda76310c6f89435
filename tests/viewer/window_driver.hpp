// Runs programs for the window tests and drives a program's window on the test's X server:
// waits for the window to be visible and focused (observable conditions, each with a
// deadline), then sends input through XTEST (xdotool), which the server delivers to the focused
// window in order and which never names a window that a key (Q) may have closed. A wait that
// fails says whose fault it is: the program's (it exited) or the X server's (it does not answer).
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace viewer_test {

struct Result {
  int code = -1;
  std::string output;  // stdout + stderr
};

// A shell command run to its end.
inline Result run(const std::string& command) {
  Result r;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  std::array<char, 512> buf{};
  while (fgets(buf.data(), buf.size(), p)) r.output += buf.data();
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Quoted for the shell. (Built with append: GCC 12's -Wrestrict misfires on "'" + s + "'".)
inline std::string q(const std::filesystem::path& p) {
  std::string s(1, '\'');
  s.append(p.string()).push_back('\'');
  return s;
}

// A program running in the background in its own folder, its output (stdout + stderr)
// collected; killed when the object dies, so that a failed test leaves no window behind.
class Program {
 public:
  Program(const std::vector<std::string>& argv, const std::filesystem::path& cwd) {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[1], 1);
      dup2(fds[1], 2);
      const int null = open("/dev/null", O_RDONLY);
      if (null >= 0) dup2(null, 0);
      if (chdir(cwd.c_str()) != 0) _exit(126);
      std::vector<char*> args;
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
    close(fds[1]);
    fd_ = fds[0];
    if (pid_ < 0) finish(-1);
  }
  ~Program() {
    if (running(0)) {
      kill(pid_, SIGKILL);
      wait(5.0);
    }
    if (fd_ >= 0) close(fd_);
  }
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  // Whether it still runs, after collecting its output for up to `wait_ms` milliseconds (it
  // has exited once its output ends).
  bool running(int wait_ms) {
    if (done_) return false;
    pollfd pfd{fd_, POLLIN, 0};
    if (poll(&pfd, 1, wait_ms) <= 0) return true;
    char buf[4096];
    const ssize_t n = read(fd_, buf, sizeof buf);
    if (n > 0) {
      output_.append(buf, static_cast<std::size_t>(n));
      return true;
    }
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {}
    finish(WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    return false;
  }

  // Its exit code and output, once it exits; past `seconds` it is killed and the output
  // says so (a bound on a hang, not a synchronisation).
  Result wait(double seconds) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (running(50))
      if (std::chrono::steady_clock::now() > deadline && !killed_) {
        kill(pid_, SIGKILL);
        killed_ = true;
        output_ += "\n[killed: still running after " + std::to_string(seconds) + " s]\n";
      }
    return {code_, output_};
  }

  const std::string& output() const { return output_; }

 private:
  void finish(int code) {
    done_ = true;
    code_ = code;
  }

  pid_t pid_ = -1;
  int fd_ = -1;
  bool done_ = false, killed_ = false;
  int code_ = -1;
  std::string output_;
};

// Empty when the X server answers, else why not.
inline std::string x_server_trouble() {
  const Result r = run("xdotool getdisplaygeometry");
  if (r.code == 0) return {};
  const char* display = std::getenv("DISPLAY");
  return "the X server (DISPLAY=" + std::string(display ? display : "") + ") does not answer: " + r.output;
}

// One xdotool command line; empty when it succeeded, else the error (the X server's, when it
// does not answer). `out` receives what it printed.
inline std::string xdo(const std::string& args, std::string* out = nullptr) {
  const Result r = run("xdotool " + args);
  if (out) *out = r.output;
  if (r.code == 0) return {};
  if (std::string x = x_server_trouble(); !x.empty()) return "xdotool " + args + ": " + x;
  return "xdotool " + args + " failed (" + std::to_string(r.code) + "): " + r.output;
}

// Waits until `program` shows a visible (mapped) window whose title matches `title` (an
// xdotool regular expression); `id` receives the window's id. Empty when it did, else why not.
inline std::string wait_for_window(Program& program, const std::string& title, std::string& id,
                                   double seconds = 30.0) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    const Result r = run("xdotool search --onlyvisible --name " + q(title));
    if (r.code == 0 && !r.output.empty()) {
      id = r.output.substr(0, r.output.find('\n'));
      return {};
    }
    if (std::string x = x_server_trouble(); !x.empty()) return x;
    if (!program.running(50))
      return "the program exited before a window titled '" + title + "' appeared: " + program.output();
    if (std::chrono::steady_clock::now() > deadline)
      return "no visible window titled '" + title + "' after " + std::to_string(seconds) +
             " s (the program still runs): " + program.output();
  }
}

// Gives the window the input focus (there is no window manager) and waits until it has it.
inline std::string focus_window(Program& program, const std::string& id, double seconds = 10.0) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  if (std::string err = xdo("windowfocus " + id); !err.empty()) return err;
  for (;;) {
    std::string focused;
    if (std::string err = xdo("getwindowfocus -f", &focused); !err.empty()) return err;
    if (focused.substr(0, focused.find('\n')) == id) return {};
    if (!program.running(20)) return "the program exited before its window had the focus: " + program.output();
    if (std::chrono::steady_clock::now() > deadline)
      return "window " + id + " does not get the focus (it has " + focused + ")";
  }
}

}  // namespace viewer_test
