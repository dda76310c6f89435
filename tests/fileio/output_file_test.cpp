// clothsim::io, the rule for every file the simulator writes. Device nodes are made here
// (mknod), never /dev/null or /dev/full themselves; without the permission the test skips.
#include <clothsim/output_file.hpp>

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using clothsim::io::check_output_dir;
using clothsim::io::check_output_file;
using clothsim::io::write_output_file;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("clothsim_fileio_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void spit(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

long entries(const fs::path& d) { return std::distance(fs::directory_iterator(d), fs::directory_iterator{}); }

// A character device like /dev/null (1, 3) or /dev/full (1, 7) at `p`; false if not permitted.
bool make_char_device(const fs::path& p, unsigned minor) {
  return ::mknod(p.c_str(), S_IFCHR | 0666, makedev(1, minor)) == 0;
}

TEST(OutputFile, NewFileIsWrittenWithNoTemporaryLeft) {
  const fs::path d = fresh_dir("new");
  EXPECT_EQ(check_output_file((d / "r.json").string()), "");
  EXPECT_EQ(write_output_file((d / "r.json").string(), "hello\n"), "");
  EXPECT_EQ(slurp(d / "r.json"), "hello\n");
  EXPECT_EQ(entries(d), 1);
  // the usual permissions of a new file (umask applied), not mkstemp's 0600
  const mode_t mask = ::umask(0);
  ::umask(mask);
  EXPECT_EQ(fs::status(d / "r.json").permissions(), static_cast<fs::perms>(0666 & ~mask));
}

// A folder where the permission bits say "writable" but no file can be made (/proc, as
// root): refused before the run (not after the whole run), and the check leaves nothing behind
// where it can write.
TEST(OutputFile, AFolderWhereNoFileCanBeMadeIsRefusedBeforeTheRun) {
  if (!fs::is_directory("/proc/self")) GTEST_SKIP() << "no /proc";
  const std::string why = check_output_file("/proc/r.json");
  EXPECT_NE(why.find("cannot write '/proc/r.json'"), std::string::npos) << why;
  EXPECT_NE(check_output_dir("/proc/frames").find("cannot create a file in '/proc'"), std::string::npos)
      << check_output_dir("/proc/frames");
  const fs::path d = fresh_dir("probe");
  EXPECT_EQ(check_output_file((d / "r.json").string()), "");
  EXPECT_EQ(check_output_dir((d / "frames").string()), "");
  EXPECT_EQ(entries(d), 0);
}

TEST(OutputFile, RegularFileIsReplacedAndKeepsItsPermissions) {
  const fs::path d = fresh_dir("replace");
  spit(d / "r.json", "old contents, longer than the new ones\n");
  fs::permissions(d / "r.json", static_cast<fs::perms>(0640));
  EXPECT_EQ(write_output_file((d / "r.json").string(), "new\n"), "");
  EXPECT_EQ(slurp(d / "r.json"), "new\n");
  EXPECT_EQ(fs::status(d / "r.json").permissions(), static_cast<fs::perms>(0640));
  EXPECT_EQ(entries(d), 1);
}

TEST(OutputFile, DirectoryIsRefusedBeforeAndAtTheWrite) {
  const fs::path d = fresh_dir("dir");
  fs::create_directory(d / "sub");
  for (const std::string& p : {(d / "sub").string(), (d / "sub").string() + "/", d.string() + "/sub/."}) {
    SCOPED_TRACE(p);
    const std::string before = check_output_file(p);
    EXPECT_NE(before.find("is a directory"), std::string::npos) << before;
    EXPECT_NE(before.find(p), std::string::npos) << "names the path: " << before;
    const std::string at = write_output_file(p, "x");
    EXPECT_NE(at.find("is a directory"), std::string::npos) << at;
  }
  EXPECT_TRUE(fs::is_directory(d / "sub"));
  EXPECT_TRUE(fs::is_empty(d / "sub"));
  EXPECT_EQ(entries(d), 1);  // no temporary file beside it either
}

TEST(OutputFile, CharacterDeviceIsWrittenInPlaceNeverReplaced) {
  const fs::path d = fresh_dir("null");
  if (!make_char_device(d / "mynull", 3)) GTEST_SKIP() << "mknod not permitted: " << std::strerror(errno);
  EXPECT_EQ(check_output_file((d / "mynull").string()), "");
  EXPECT_EQ(write_output_file((d / "mynull").string(), "report\n"), "");
  struct stat st {};
  ASSERT_EQ(::stat((d / "mynull").c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device was replaced by a regular file";
  EXPECT_EQ(entries(d), 1);
}

TEST(OutputFile, FullDeviceIsAnIoErrorNamingIt) {
  const fs::path d = fresh_dir("full");
  if (!make_char_device(d / "myfull", 7)) GTEST_SKIP() << "mknod not permitted: " << std::strerror(errno);
  const std::string err = write_output_file((d / "myfull").string(), "report\n");
  EXPECT_NE(err.find("myfull"), std::string::npos) << err;
  EXPECT_NE(err.find("No space left"), std::string::npos) << err;
  struct stat st {};
  ASSERT_EQ(::stat((d / "myfull").c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  EXPECT_EQ(entries(d), 1);
}

TEST(OutputFile, FifoWithoutAReaderIsAnErrorNotAHang) {
  const fs::path d = fresh_dir("fifo");
  ASSERT_EQ(::mkfifo((d / "f").c_str(), 0666), 0);
  EXPECT_EQ(check_output_file((d / "f").string()), "");
  const std::string err = write_output_file((d / "f").string(), "x");
  EXPECT_NE(err.find("no reader"), std::string::npos) << err;
  EXPECT_TRUE(fs::is_fifo(d / "f"));
}

TEST(OutputFile, FifoWithAReaderGetsTheBytes) {
  const fs::path d = fresh_dir("fifo_reader");
  ASSERT_EQ(::mkfifo((d / "f").c_str(), 0666), 0);
  const int reader = ::open((d / "f").c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  EXPECT_EQ(write_output_file((d / "f").string(), "through\n"), "");
  char buf[32] = {};
  EXPECT_EQ(::read(reader, buf, sizeof buf), 8);
  EXPECT_STREQ(buf, "through\n");
  ::close(reader);
  EXPECT_TRUE(fs::is_fifo(d / "f"));
}

// A write that fails half way (a file size limit: EFBIG) leaves the old file and nothing else.
// In a child process: the limit and the signal it raises must not touch the test runner.
TEST(OutputFile, FailedWriteLeavesTheOldFileAndNoTemporary) {
  const fs::path d = fresh_dir("efbig");
  spit(d / "r.json", "old\n");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const rlimit limit{8, 8};  // bytes
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(3);
    const std::string err = write_output_file((d / "r.json").string(), std::string(1000, 'x'));
    const bool named = err.find("r.json") != std::string::npos && err.find("too large") != std::string::npos;
    ::_exit(err.empty() ? 1 : named ? 0 : 2);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: no error reported, 2: the message lacks the name or the cause";
  EXPECT_EQ(slurp(d / "r.json"), "old\n");
  EXPECT_EQ(entries(d), 1);
}

TEST(OutputFile, SymbolicLinkStaysALinkAndItsTargetIsReplaced) {
  const fs::path d = fresh_dir("link");
  fs::create_directory(d / "real");
  spit(d / "real" / "r.json", "old\n");
  fs::create_symlink(d / "real" / "r.json", d / "link.json");
  EXPECT_EQ(check_output_file((d / "link.json").string()), "");
  EXPECT_EQ(write_output_file((d / "link.json").string(), "new\n"), "");
  EXPECT_TRUE(fs::is_symlink(d / "link.json"));
  EXPECT_EQ(slurp(d / "real" / "r.json"), "new\n");
  EXPECT_EQ(entries(d / "real"), 1);
  fs::create_symlink(d / "nowhere", d / "dangling");
  EXPECT_NE(check_output_file((d / "dangling").string()).find("missing"), std::string::npos);
  EXPECT_NE(write_output_file((d / "dangling").string(), "x").find("missing"), std::string::npos);
  EXPECT_FALSE(fs::exists(d / "nowhere"));
}

TEST(OutputFile, MissingOrNonDirectoryParentIsNamed) {
  const fs::path d = fresh_dir("parent");
  spit(d / "file", "x");
  const std::string missing = check_output_file((d / "no" / "r.json").string());
  EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;
  const std::string under_file = check_output_file((d / "file" / "r.json").string());
  EXPECT_NE(under_file.find("file"), std::string::npos) << under_file;
  EXPECT_NE(check_output_file(""), "");
  EXPECT_NE(write_output_file((d / "no" / "r.json").string(), "x"), "");
  EXPECT_EQ(entries(d), 1);
}

TEST(OutputDir, ExistingFileInPlaceOfTheDirectoryIsRefused) {
  const fs::path d = fresh_dir("outdir");
  spit(d / "file", "x");
  EXPECT_EQ(check_output_dir(d.string()), "");
  EXPECT_EQ(check_output_dir((d / "new" / "deeper").string()), "");  // created later
  EXPECT_NE(check_output_dir((d / "file").string()).find("not a directory"), std::string::npos);
  EXPECT_NE(check_output_dir((d / "file" / "sub").string()).find("not a directory"), std::string::npos);
  EXPECT_NE(check_output_dir(""), "");
}

}  // namespace


TEST(SameOutput, OnePathNamedTwiceIsFoundHoweverItIsWritten) {
  const fs::path d = fresh_dir("same");
  fs::create_directories(d / "out");
  fs::create_directory_symlink(d / "out", d / "link");
  const std::string a = (d / "out" / "x").string();
  using clothsim::io::same_output;
  EXPECT_EQ(same_output({{"--a", a}, {"--b", (d / "out" / "y").string()}}), "");
  EXPECT_EQ(same_output({{"--a", a}, {"--b", ""}, {"--c", ""}}), "");  // empty: not given
  for (const std::string& b : {a, a + "/", (d / "out" / "." / "x").string(), (d / "out" / ".." / "out" / "x").string(),
                               (d / "link" / "x").string()}) {
    const std::string why = same_output({{"--a", a}, {"--b", b}});
    EXPECT_NE(why.find("--a and --b both name"), std::string::npos) << b << ": " << why;
  }
  // the third of three against the first
  EXPECT_NE(same_output({{"--a", a}, {"--b", (d / "z").string()}, {"--c", a}}).find("--a and --c"), std::string::npos);
}

TEST(SameOutput, ADeviceTakesEveryOutput) {
  const fs::path d = fresh_dir("same_device");
  if (!make_char_device(d / "mynull", 3)) GTEST_SKIP() << "mknod not permitted: " << std::strerror(errno);
  const std::string dev = (d / "mynull").string();
  EXPECT_EQ(clothsim::io::same_output({{"--report", dev}, {"--screenshot", dev}}), "");
}

