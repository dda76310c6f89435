// What the command-line tests share: running a program as a user would (its exit code and
// output), fresh folders, and reading what it wrote.
#pragma once

#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace clothsim::testing {

namespace fs = std::filesystem;

struct Result {
  int code = -1;
  std::string output;  // stdout + stderr
};

// `exe` with `args`; `shell_prefix`: shell commands run first (e.g. "cd DIR && ", "ulimit -f 0; ").
Result run_program(const std::string& exe, const std::string& args, const std::string& shell_prefix = "") {
  const std::string cmd = shell_prefix + "'" + exe + "' " + args + " 2>&1";
  Result r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), p)) r.output += buf.data();
  const int status = ::pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}


fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("clothsim_cli_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::string text, line;
  while (std::getline(in, line)) text += line + "\n";
  return text;
}

long entries(const fs::path& d) { return std::distance(fs::directory_iterator(d), fs::directory_iterator{}); }

// 'p' for the shell (built in steps: g++ 12 warns falsely on "'" + p.string() + "'")
std::string q(const fs::path& p) {
  std::string s = p.string();
  s.insert(0, 1, '\'');
  s += '\'';
  return s;
}

// A character device like /dev/null (minor 3) or /dev/full (minor 7) of our own; the tests
// never touch the real ones. False when mknod is not permitted.
bool make_char_device(const fs::path& p, unsigned minor) {
  return ::mknod(p.c_str(), S_IFCHR | 0666, makedev(1, minor)) == 0;
}

bool is_char_device(const fs::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace clothsim::testing
