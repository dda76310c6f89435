// The converter on bad input, from the outside: exit 1, one clear line naming the file, and
// nothing created or changed in the target folder (a snapshot of names, sizes, mtimes and
// hashes before and after). The corpus and its expectations are in corpus/EXPECTED.tsv; cases
// that need a file system shape or megabytes are made here.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "process.hpp"

namespace fs = std::filesystem;
using reliability::Result;
using reliability::TempDir;

namespace {

const std::string kExe = B2O_EXE;
const fs::path kCorpus = CORPUS_DIR;
const std::string kTriangle = "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

struct Case {
  std::string file;
  int exit_code = 1;
  std::string message;
  std::vector<std::string> args;
};

std::vector<Case> load_cases() {
  std::vector<Case> cases;
  std::ifstream in(kCorpus / "EXPECTED.tsv");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cols;
    std::stringstream ss(line);
    for (std::string col; std::getline(ss, col, '\t');) cols.push_back(col);
    if (cols.size() < 3) throw std::runtime_error("EXPECTED.tsv: bad line: " + line);
    Case c{cols[0], std::stoi(cols[1]), cols[2], {}};
    if (cols.size() > 3) {
      std::stringstream as(cols[3]);
      for (std::string a; as >> a;) c.args.push_back(a);
    }
    cases.push_back(c);
  }
  return cases;
}

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string l; std::getline(ss, l);) out.push_back(l);
  return out;
}

// A target folder that already holds a good conversion under the stem the bad input would
// write: a bad run must leave it exactly as it was.
void fill_with_old_outputs(const fs::path& target, const std::string& stem) {
  TempDir good("good");
  const fs::path model = good.path / (stem + ".obj");
  reliability::write_file(model, kTriangle);
  const Result r = reliability::run({kExe, "-t", target.string(), model.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

// Checks one failing run: exit 1, exactly one line, naming `names`, containing `message`.
void expect_one_line_error(const Result& r, const std::string& names, const std::string& message) {
  EXPECT_EQ(r.signal, 0) << "killed by signal " << r.signal << "\n" << r.err;
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const auto lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 1u) << "expected exactly one line on stderr, got:\n" << r.err;
  EXPECT_NE(lines[0].find(message), std::string::npos) << "expected '" << message << "' in: " << lines[0];
  EXPECT_NE(lines[0].find(names), std::string::npos) << "the message should name '" << names << "': " << lines[0];
  EXPECT_EQ(r.out, "");
}

TEST(BadInputCorpus, EachFileGetsItsMessageAndChangesNothing) {
  const auto cases = load_cases();
  ASSERT_GE(cases.size(), 30u);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    ASSERT_TRUE(fs::exists(kCorpus / c.file));
    TempDir work("bad");
    // Copy the input (and any .mtl it names) so the run reads nothing from the source tree
    // by accident and can write nothing there.
    for (const auto& e : fs::directory_iterator(kCorpus))
      if (e.path().extension() == ".mtl") fs::copy_file(e.path(), work.path / e.path().filename());
    fs::copy_file(kCorpus / c.file, work.path / c.file);
    const fs::path target = work.path / "target";
    const std::string stem = fs::path(c.file).stem().string();
    if (c.exit_code != 0) fill_with_old_outputs(target, stem);
    const auto before = reliability::snapshot(target);
    const auto inputs_before = reliability::snapshot(kCorpus);

    std::vector<std::string> argv = {kExe};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    argv.insert(argv.end(), {"-t", target.string(), (work.path / c.file).string()});
    const Result r = reliability::run(argv);

    EXPECT_EQ(reliability::snapshot(kCorpus), inputs_before) << "the corpus itself changed";
    if (c.exit_code != 0) {
      expect_one_line_error(r, c.file, c.message);
      EXPECT_EQ(reliability::snapshot(target), before) << "a failed run changed the target folder";
    } else {
      EXPECT_EQ(r.exit_code, 0) << r.err;
      EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(c.file), std::string::npos) << "the warning should name the file: " << r.err;
      EXPECT_TRUE(fs::exists(target / (stem + ".h")));
    }
  }
}

// Lines of a megabyte: made here, not committed.
TEST(BadInput, MegabyteLines) {
  const std::size_t mb = std::size_t{1} << 20;
  struct Big {
    std::string name, text, message;
  };
  const std::vector<Big> bigs = {
      {"long_face", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 " + std::string(mb, '3') + "\n", "malformed vertex reference"},
      {"long_slashes", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 " + [&] {
         std::string s;
         while (s.size() < mb) s += "3/";
         return s;
       }() + "\n", "out of range"},
      {"long_number", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1" + std::string(mb, '0') + " 0\nf 1 2 3\n", "number out of range"},
      {"long_garbage", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 " + std::string(mb, 'x') + "\nf 1 2 3\n", "malformed number"},
  };
  for (const Big& b : bigs) {
    SCOPED_TRACE(b.name);
    TempDir work("mb");
    const fs::path input = work.path / (b.name + ".obj");
    reliability::write_file(input, b.text);
    const fs::path target = work.path / "target";
    fill_with_old_outputs(target, b.name);
    const auto before = reliability::snapshot(target);
    const Result r = reliability::run({kExe, "-t", target.string(), input.string()});
    expect_one_line_error(r, b.name + ".obj:", b.message);
    EXPECT_EQ(reliability::snapshot(target), before);
  }
  // A megabyte comment is fine: the model after it is converted.
  TempDir work("mb");
  const fs::path input = work.path / "long_comment.obj";
  reliability::write_file(input, "#" + std::string(mb, 'c') + "\n" + kTriangle);
  const Result r = reliability::run({kExe, "-t", (work.path / "out").string(), input.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(work.path / "out" / "long_comment.h"));
}

TEST(BadInput, DirectoryGivenAsInput) {
  TempDir work("dir");
  const fs::path input = work.path / "model.obj";
  fs::create_directory(input);
  const fs::path target = work.path / "target";
  fill_with_old_outputs(target, "model");
  const auto before = reliability::snapshot(target);
  const Result r = reliability::run({kExe, "-t", target.string(), input.string()});
  expect_one_line_error(r, input.string(), "is a directory");
  EXPECT_EQ(reliability::snapshot(target), before);
}

TEST(BadInput, MissingInput) {
  TempDir work("missing");
  const fs::path input = work.path / "nothing_here.obj";
  const Result r = reliability::run({kExe, "-t", (work.path / "target").string(), input.string()});
  expect_one_line_error(r, input.string(), "no such file");
  EXPECT_FALSE(fs::exists(work.path / "target")) << "a failed run created the target folder";
}

// chmod does not stop root, so writes are made to fail by the shape of the path.
TEST(BadInput, UnwritableTarget) {
  TempDir work("target");
  const fs::path input = work.path / "model.obj";
  reliability::write_file(input, kTriangle);
  const fs::path file = work.path / "a_file";
  reliability::write_file(file, "not a folder");
  for (const fs::path& target : {file, file / "sub", file / "sub" / "deeper"}) {
    SCOPED_TRACE(target.string());
    const auto before = reliability::snapshot(work.path);
    const Result r = reliability::run({kExe, "-t", target.string(), input.string()});
    expect_one_line_error(r, file.string(), "");
    EXPECT_EQ(reliability::snapshot(work.path), before);
  }
}

// A folder in place of one output (the header, the set's commit point): refused before anything
// is replaced (a refusal after some renames would leave new files next to old ones).
TEST(BadInput, OutputNameTakenByFolderChangesNothing) {
  TempDir work("taken");
  const fs::path input = work.path / "model.obj";
  reliability::write_file(input, kTriangle);
  const fs::path target = work.path / "out";
  fill_with_old_outputs(target, "model");
  reliability::write_file(input, kTriangle + "o Second\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf 4 5 6\n");
  for (const char* taken : {"model.h", "model.cpp"}) {
    SCOPED_TRACE(taken);
    const std::string keep = reliability::read_file(target / taken);
    fs::remove(target / taken);
    fs::create_directory(target / taken);
    const auto before = reliability::snapshot(target);
    const Result r = reliability::run({kExe, "-t", target.string(), input.string()});
    expect_one_line_error(r, taken, "cannot write");
    EXPECT_EQ(reliability::snapshot(target), before);
    fs::remove(target / taken);
    reliability::write_file(target / taken, keep);
  }
}

// A .mtl or texture that cannot be read (a folder in its place) is refused like a missing one,
// at its mtllib / map_Kd line; --allow-missing converts without a texture it cannot read.
TEST(BadInput, UnreadableMtlAndTexture) {
  TempDir work("mtl");
  const fs::path input = work.path / "model.obj";
  reliability::write_file(input, "mtllib model.mtl\no Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\n");
  fs::create_directory(work.path / "model.mtl");
  fill_with_old_outputs(work.path / "out1", "model");
  auto before = reliability::snapshot(work.path / "out1");
  Result r = reliability::run({kExe, "-t", (work.path / "out1").string(), input.string()});
  expect_one_line_error(r, input.string() + ":1:", "material library 'model.mtl' is not a readable file");
  EXPECT_EQ(reliability::snapshot(work.path / "out1"), before);

  fs::remove(work.path / "model.mtl");
  reliability::write_file(work.path / "model.mtl", "newmtl M\nKd 1 0 0\nmap_Kd tex.png\n");
  fs::create_directory(work.path / "tex.png");
  before = reliability::snapshot(work.path / "out1");
  r = reliability::run({kExe, "-t", (work.path / "out1").string(), input.string()});
  expect_one_line_error(r, (work.path / "model.mtl").string() + ":3:", "texture 'tex.png' of material 'M' is not a readable file");
  EXPECT_EQ(reliability::snapshot(work.path / "out1"), before);
  r = reliability::run({kExe, "--allow-missing", "-t", (work.path / "out2").string(), input.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("tex.png"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(work.path / "out2" / "model.h"));
}

// Quoted input is clipped: a megabyte token gives a short line, not a megabyte one.
TEST(BadInput, QuotedTextIsClipped) {
  TempDir work("clip");
  const std::size_t mb = std::size_t{1} << 20;
  const fs::path input = work.path / "model.obj";
  reliability::write_file(input, "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 " + std::string(mb, 'x') + "\nf 1 2 3\n");
  Result r = reliability::run({kExe, "-t", (work.path / "out").string(), input.string()});
  expect_one_line_error(r, input.string() + ":4:", "malformed number '" + std::string(60, 'x') + "...'");
  EXPECT_LT(r.err.size(), input.string().size() + 200) << r.err.substr(0, 300);
  // the same for a name quoted by the bake (-a of an object that is not there)
  reliability::write_file(input, kTriangle);
  r = reliability::run({kExe, "-a", std::string(5000, 'N'), "-t", (work.path / "out").string(), input.string()});
  expect_one_line_error(r, input.string(), "no object '" + std::string(60, 'N') + "...'");
  EXPECT_LT(r.err.size(), input.string().size() + 300) << r.err.substr(0, 400);
  EXPECT_FALSE(fs::exists(work.path / "out"));
}

// assimp keeps names of at most 1023 bytes (aiString); a longer one would silently become "".
TEST(BadInput, ObjectNameOver1023BytesIsRefused) {
  TempDir work("longname");
  const fs::path input = work.path / "model.obj";
  for (const char* key : {"o", "g"}) {
    SCOPED_TRACE(key);
    reliability::write_file(input, std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\n") + key + " " + std::string(1024, 'n') +
                                       "\nf 1 2 3\n");
    const Result r = reliability::run({kExe, "-t", (work.path / "out").string(), input.string()});
    expect_one_line_error(r, input.string() + ":4:", "object name longer than 1023 bytes");
    EXPECT_FALSE(fs::exists(work.path / "out"));
  }
  // 1023 bytes is kept whole
  const std::string name(1023, 'n');
  reliability::write_file(input, "o " + name + "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Result r = reliability::run({kExe, "-t", (work.path / "out").string(), input.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(reliability::read_file(work.path / "out" / "model.h").find('"' + name + '"'), std::string::npos);
}

// Fuzz finding 9: finite coordinates near +-3e38 whose distance overflows a float.
TEST(BadInput, HugeCoordinatesOverflowingARestLengthAreRefused) {
  TempDir work("huge");
  const fs::path input = work.path / "model.obj";
  reliability::write_file(input, "o Sheet\nv -3e38 0 0\nv 3e38 0 0\nv 0 1 0\nf 1 2 3\n");
  const fs::path target = work.path / "target";
  fill_with_old_outputs(target, "model");
  const auto before = reliability::snapshot(target);
  Result r = reliability::run({kExe, "-a", "Sheet", "-t", target.string(), input.string()});
  expect_one_line_error(r, input.string() + ": cloth 'Sheet'", "coordinates too large: spring rest length overflows");
  EXPECT_EQ(reliability::snapshot(target), before);
  // 1e38 apart is still a float: accepted
  reliability::write_file(input, "o Sheet\nv -1e38 0 0\nv 1e38 0 0\nv 0 1 0\nf 1 2 3\n");
  r = reliability::run({kExe, "-a", "Sheet", "-t", target.string(), input.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(BadUsage, ExitsTwoWithOneLine) {
  TempDir work("usage");
  const fs::path input = work.path / "model.obj";
  reliability::write_file(input, kTriangle);
  const std::vector<std::vector<std::string>> bad = {
      {},
      {"--no-such-option", input.string()},
      {"-t"},
      {"-p", "Cloth:1,2", input.string()},
      {"-p", "Cloth:nan,0,0", "-a", "Cloth", input.string()},
      {"--param", "dt=", input.string()},
      {"--param", "dt=a b", input.string()},
      {"-n", "", input.string()},
  };
  for (const auto& args : bad) {
    std::vector<std::string> argv = {kExe};
    argv.insert(argv.end(), args.begin(), args.end());
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    SCOPED_TRACE(joined);
    const auto before = reliability::snapshot(work.path);
    const Result r = reliability::run(argv);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(r.signal, 0);
    EXPECT_GE(lines_of(r.err).size(), 1u);
    EXPECT_EQ(reliability::snapshot(work.path), before);
  }
}

}  // namespace

namespace {

// A folder named like the .mtl: the message names it (not assimp's "File read error").
TEST(BadInput, MtlFolderIsNamedInTheMessage) {
  TempDir work("mtl");
  const fs::path input = work.path / "model.obj";
  reliability::write_file(input, "mtllib model.mtl\no Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\n");
  fs::create_directory(work.path / "model.mtl");
  const Result r = reliability::run({kExe, "-t", (work.path / "out").string(), input.string()});
  EXPECT_NE(r.err.find("model.mtl"), std::string::npos) << r.err;
}

}  // namespace

namespace {

// A .mtl whose first statement is map_Kd (no `newmtl` before it) crashes assimp 5.2.5 in its
// material parser (SIGSEGV): the pre-scan refuses it with file:line.
TEST(BadInput, MtlStatementBeforeNewmtlIsRefused) {
  TempDir work("newmtl");
  for (const char* f : {"mtl_statement_before_newmtl.obj", "before_newmtl.mtl"})
    fs::copy_file(kCorpus / f, work.path / f);
  const fs::path input = work.path / "mtl_statement_before_newmtl.obj";
  const Result r = reliability::run({kExe, "-t", (work.path / "out").string(), input.string()});
  expect_one_line_error(r, "before_newmtl.mtl", "newmtl");
  EXPECT_FALSE(fs::exists(work.path / "out"));
}

}  // namespace

namespace {

// "\vnewmtl" is a newmtl to a scan that counts a vertical tab as blank, but not to assimp, so a
// statement after it crashes assimp 5.2.5 (SIGSEGV): the pre-scan refuses vertical tabs and
// form feeds in model and material files.
TEST(BadInput, VerticalTabBeforeNewmtlIsRefused) {
  TempDir work("vtab");
  for (const char* f : {"mtl_vertical_tab.obj", "vt.mtl"}) fs::copy_file(kCorpus / f, work.path / f);
  const fs::path input = work.path / "mtl_vertical_tab.obj";
  const Result r = reliability::run({kExe, "-t", (work.path / "out").string(), input.string()});
  expect_one_line_error(r, "vt.mtl", "byte 0x0b");
  EXPECT_FALSE(fs::exists(work.path / "out"));
}

}  // namespace
