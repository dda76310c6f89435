// The executable: exit codes, one clear message naming the file (and line), no files on error.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include "support.hpp"

namespace {

using namespace b2o::test;

struct Bad {
  const char* file;
  const char* expect;  // part of the message after the file name (line included when known)
};

TEST(Cli, BadInputGivesOneLineExitOneNoFiles) {
  const auto out = scratch("cli_bad");
  const std::vector<Bad> cases = {
      {"bad/empty.obj", ": no vertices"},
      {"bad/garbage.obj", ":1: binary data"},
      {"bad/truncated.obj", ":5: 'v' needs 3 coordinates"},
      {"bad/nan.obj", ":2: non-finite number 'nan'"},
      {"bad/inf.obj", ":3: non-finite number 'inf'"},
      {"bad/out_of_range.obj", ":4: vertex index 4 out of range"},
      {"bad/two_vertex_face.obj", ":4: 'f' needs at least 3 vertices"},
      {"bad/no_such_file.obj", ": no such file"},
      {"bad", ": is a directory"},
      {"grid.obj/inside.obj", ": no such file"},  // a path through a file
  };
  for (const Bad& c : cases) {
    const std::string path = (std::string(c.file) == "grid.obj/inside.obj" ? fixture("grid.obj") / "inside.obj"
                                                                           : fixture(c.file)).string();
    const auto r = run_converter({"-t", (out / "x").string(), path});
    EXPECT_EQ(r.exit_code, 1) << c.file << "\n" << r.output;
    EXPECT_NE(r.output.find(path + c.expect), std::string::npos) << c.file << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(out / "x")) << c.file;
  }
}

TEST(Cli, UnreadableFile) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads every file";
  const auto dir = scratch("cli_unreadable");
  write_file(dir / "locked.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ::chmod((dir / "locked.obj").c_str(), 0);
  const auto r = run_converter({(dir / "locked.obj").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find((dir / "locked.obj").string()), std::string::npos);
}

TEST(Cli, UsageErrorsExitTwo) {
  for (const std::vector<std::string>& args :
       std::vector<std::vector<std::string>>{{},
                                             {"--bogus", fixture("grid.obj").string()},
                                             {"-t"},
                                             {"a.obj", "b.obj"},
                                             {"-p", "Cloth", fixture("grid.obj").string()},
                                             {"-t", "", fixture("grid.obj").string()},
                                             {"-p", "Cloth:1,2", fixture("grid.obj").string()},
                                             {"--param", "dt", fixture("grid.obj").string()},
                                             {"--param", "dt=", fixture("grid.obj").string()},
                                             {"--param", "dt=0 1", fixture("grid.obj").string()},
                                             {"--param", "dt=1", "--param", "dt=2", fixture("grid.obj").string()},
                                             // one value each: given twice is an error
                                             {"-t", "a", "-t", "b", fixture("grid.obj").string()},
                                             {"-n", "a", "-n", "b", fixture("grid.obj").string()},
                                             {"-c", "-s", fixture("grid.obj").string()},
                                             {"--depfile", "a.d", "--depfile", "b.d", fixture("grid.obj").string()},
                                             {"--param", "dt=\"1\"", fixture("grid.obj").string()}}) {
    const auto r = run_converter(args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--help"), std::string::npos) << r.output;
  }
  EXPECT_NE(run_converter({"-c", "-s", fixture("grid.obj").string()}).output.find("-s and -c given together"),
            std::string::npos);
  EXPECT_NE(run_converter({"--param", "dt=0 1", fixture("grid.obj").string()}).output.find("one word of printable"),
            std::string::npos);
  // after "--" every argument is a file: a model named -m.obj
  const auto dir = scratch("cli_dashdash");
  write_file(dir / "-m.obj", "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const auto r = run_converter({"-t", (dir / "out").string(), "--", (dir / "-m.obj").string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "m.h")) << r.output;
}

TEST(Cli, HelpVersionAndStatistics) {
  for (const char* h : {"-h", "-?", "--help"}) {
    const auto r = run_converter({h});
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.output.find("--cloth"), std::string::npos);
    EXPECT_NE(r.output.find("_pins"), std::string::npos);
    EXPECT_NE(r.output.find(".fbx"), std::string::npos);
  }
  EXPECT_NE(run_converter({"--version"}).output.find(b2o::conv::kVersion), std::string::npos);
  const auto out = scratch("cli_stats");
  const auto r = run_converter({"-v", "-a", "Cloth", "-o", "-t", out.string(), fixture("grid.obj").string()});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* k : {"objects    2", "vertices   13", "triangles  10", "masses     9",
                        "springs    24 (16 structural, 8 bend)", "pins       2", "warnings   0", "time"})
    EXPECT_NE(r.output.find(k), std::string::npos) << k << "\n" << r.output;
  // default target: the input's folder; -n names the files
  const auto in = scratch("cli_default_target");
  fs::copy_file(fixture("plain.obj"), in / "plain.obj");
  ASSERT_EQ(run_converter({"--allow-missing", "-n", "flat", (in / "plain.obj").string()}).exit_code, 0);
  EXPECT_TRUE(fs::exists(in / "flat.h"));
  EXPECT_TRUE(fs::exists(in / "flat.cpp"));
  EXPECT_TRUE(fs::exists(in / "flat.S"));
  int bins = 0;
  for (const auto& e : fs::directory_iterator(in)) bins += e.path().extension() == ".bin";
  EXPECT_EQ(bins, 1);
}

// Blender's `o My Cloth` + `o My Cloth_pins`: `-a "My Cloth"` selects it
// and the helper pins it (never "0 pins, warnings 0").
TEST(Cli, ObjectNamesWithSpacesSelectAndPin) {
  const auto dir = scratch("cli_space_names");
  write_file(dir / "m.obj", "o My Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n"
                            "o My Cloth_pins\nv 0 1 0\nv 1 1 0\n"
                            "o My Floor\nv 0 -1 0\nv 1 -1 0\nv 0 -1 1\nf 7 8 9\n");
  const auto r = run_converter({"-v", "-a", "My Cloth", "-t", (dir / "out").string(), (dir / "m.obj").string()});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* k : {"objects    2", "cloths     1", "masses     4", "pins       2", "warnings   0",
                        "cloth My Cloth: 4 masses"})
    EXPECT_NE(r.output.find(k), std::string::npos) << k << "\n" << r.output;
  const std::string h = read_file(dir / "out" / "m.h");
  EXPECT_NE(h.find("My_Cloth = 0"), std::string::npos) << h;
  EXPECT_NE(h.find("My_Floor = 1"), std::string::npos) << h;
  // the first word alone is no object: an error listing the names
  const auto bad = run_converter({"-a", "My", "-t", (dir / "out2").string(), (dir / "m.obj").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("no object 'My'"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("'My Cloth', 'My Floor'"), std::string::npos) << bad.output;
}


// assimp 5.2.5 crashes on a .mtl statement before the first newmtl: refused with file:line.
TEST(Cli, MtlProblemsAreRefusedWithTheirFileAndLine) {
  const auto dir = scratch("cli_mtl");
  write_file(dir / "a.obj", "mtllib a.mtl\no Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\n");
  write_file(dir / "a.mtl", "# comment\nmap_Kd tex.png\nnewmtl M\n");
  auto r = run_converter({"-t", (dir / "out").string(), (dir / "a.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "a.mtl").string() + ":2: 'map_Kd' before any 'newmtl'"), std::string::npos) << r.output;
  write_file(dir / "a.mtl", "newmtl M\nKd 1 nan 0\n");
  r = run_converter({"-t", (dir / "out").string(), (dir / "a.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "a.mtl").string() + ":2: non-finite value 'nan'"), std::string::npos) << r.output;
  fs::remove(dir / "a.mtl");
  fs::create_directory(dir / "a.mtl");
  r = run_converter({"-t", (dir / "out").string(), (dir / "a.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "a.obj").string() + ":1: material library 'a.mtl' is not a readable file"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// A missing .mtl or texture: an error at its mtllib / map_Kd line (exit 1, nothing written);
// --allow-missing turns both into warnings and converts without them.
TEST(Cli, MissingMtlAndTextureAreErrorsUnlessAllowed) {
  const auto dir = scratch("cli_allow_missing");
  write_file(dir / "m.obj", "# made here\nmtllib lost.mtl\no Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\n");
  auto r = run_converter({"-t", (dir / "out").string(), (dir / "m.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "m.obj").string() + ":2: material library 'lost.mtl' not found (" +
                          (dir / "lost.mtl").string() + ")"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
  r = run_converter({"--allow-missing", "-t", (dir / "out").string(), (dir / "m.obj").string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: " + (dir / "m.obj").string() + ":2: material library 'lost.mtl' not found"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "m.h"));

  write_file(dir / "t.obj", "mtllib t.mtl\no Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\n");
  write_file(dir / "t.mtl", "newmtl M\nKd 1 0 0\n\nmap_Kd -s 1 1 1 img/lost.png\n");
  r = run_converter({"-t", (dir / "out2").string(), (dir / "t.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "t.mtl").string() + ":4: texture 'img/lost.png' of material 'M' not found (" +
                          (dir / "img" / "lost.png").string()),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out2"));
  // unreadable (a folder in its place) is refused the same way
  fs::create_directories(dir / "img" / "lost.png");
  r = run_converter({"-t", (dir / "out2").string(), (dir / "t.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "t.mtl").string() + ":4: texture 'img/lost.png' of material 'M' is not a readable file"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out2"));
  r = run_converter({"--allow-missing", "-t", (dir / "out2").string(), (dir / "t.obj").string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: " + (dir / "t.mtl").string() + ":4: texture 'img/lost.png'"), std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::exists(dir / "out2" / "t.h"));
  EXPECT_EQ(run_converter({"--allow-missing=yes", (dir / "t.obj").string()}).exit_code, 2);
  EXPECT_NE(run_converter({"--help"}).output.find("--allow-missing"), std::string::npos);
}

// assimp reads <model>.mtl when the named library is missing, and ends a line at a lone '\r';
// both would let text reach assimp unchecked.
TEST(Cli, FallbackMtlAndLoneCarriageReturnAreChecked) {
  const auto dir = scratch("cli_fallback");
  write_file(dir / "b.obj", "mtllib gone.mtl\no Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\n");
  write_file(dir / "b.mtl", "Kd 1 1 1\nnewmtl M\n");
  // (the fallback is only taken when a missing library is allowed)
  auto r = run_converter({"--allow-missing", "-t", (dir / "out").string(), (dir / "b.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "b.mtl").string() + ":1: 'Kd' before any 'newmtl'"), std::string::npos) << r.output;
  write_file(dir / "b.mtl", "newmtl M\nKd 1 0.5 0\n");
  r = run_converter({"-t", (dir / "out").string(), (dir / "b.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "b.obj").string() + ":1: material library 'gone.mtl' not found"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
  r = run_converter({"--allow-missing", "-t", (dir / "out").string(), (dir / "b.obj").string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("assimp reads 'b.mtl' instead"), std::string::npos) << r.output;
  write_file(dir / "c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n# note\rf 1 2 3\n");
  r = run_converter({"-t", (dir / "out2").string(), (dir / "c.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "c.obj").string() + ":4: carriage return inside a line"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out2"));
}

TEST(Cli, FolderInAnOutputsPlaceChangesNothing) {
  const auto dir = scratch("cli_taken");
  ASSERT_EQ(run_converter({"--allow-missing", "-t", dir.string(), fixture("plain.obj").string()}).exit_code, 0);
  fs::remove(dir / "plain.S");
  fs::create_directory(dir / "plain.S");
  const auto before = snapshot(dir);
  const auto r = run_converter({"--allow-missing", "-a", "plain", "-t", dir.string(), fixture("plain.obj").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find((dir / "plain.S").string() + ": cannot write"), std::string::npos) << r.output;
  EXPECT_EQ(snapshot(dir), before);
}


const char* kTriangle = "o Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
const char* kTriangle2 = "o Cloth\nv 0 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\n";

// A depfile that cannot be written (a folder in its place, a folder where no file can be made)
// fails the run before anything is committed: the old outputs stay, nothing is created.
TEST(Cli, DepfileFailureChangesNothing) {
  const auto dir = scratch("cli_depfile_fail");
  write_file(dir / "m.obj", kTriangle);
  ASSERT_EQ(run_converter({"-a", "Cloth", "-t", (dir / "out").string(), (dir / "m.obj").string()}).exit_code, 0);
  write_file(dir / "m.obj", kTriangle2);
  fs::create_directory(dir / "dd2");
  const auto before = snapshot(dir);
  for (const fs::path& dep : {dir / "dd2", fs::path("/proc/b2o_no_such.d"), dir / "m.obj" / "x.d"}) {
    const auto r = run_converter({"-a", "Cloth", "--depfile", dep.string(), "-t", (dir / "out").string(),
                                  (dir / "m.obj").string()});
    EXPECT_EQ(r.exit_code, 1) << dep << "\n" << r.output;
    EXPECT_NE(r.output.find(dep.string() + ": cannot write"), std::string::npos) << r.output;
    EXPECT_TRUE(snapshot(dir) == before) << dep;
    int entries = 0;
    for (const auto& e : fs::directory_iterator(dir / "out")) entries += e.path().filename() != "";
    EXPECT_EQ(entries, 4) << dep;  // no temp file left
  }
  // a depfile in a missing folder: the folder is made with the outputs
  const auto r = run_converter({"-a", "Cloth", "--depfile", (dir / "deps" / "m.d").string(), "-t",
                                (dir / "out").string(), (dir / "m.obj").string()});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(read_file(dir / "deps" / "m.d").find((dir / "m.obj").string()), std::string::npos);
}

// -n is used as given or refused (exit 2, nothing written): a build asking for NAME.h would not
// find the files of a cleaned name (class_.h), and a namespace b2o::gen::std hides ::std.
TEST(Cli, SceneNameThatWouldChangeIsRefused) {
  const auto dir = scratch("cli_bad_name");
  write_file(dir / "m.obj", kTriangle);
  for (const char* name : {"class", "flag_", "std", "b2o", "my scene", "2d", "a__b", "scene", "linux", "unix", "SIZE_MAX",
                           "INT64_MAX"}) {
    const auto r = run_converter({"-n", name, "-t", (dir / "out").string(), (dir / "m.obj").string()});
    EXPECT_EQ(r.exit_code, 2) << name << "\n" << r.output;
    EXPECT_NE(r.output.find("not usable as a scene name"), std::string::npos) << name << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir / "out")) << name;
  }
  EXPECT_EQ(run_converter({"-n", "my_scene2", "-t", (dir / "out").string(), (dir / "m.obj").string()}).exit_code, 0);
  EXPECT_TRUE(fs::exists(dir / "out" / "my_scene2.h"));
}

// A depfile named as one of the generated files (the header, the sources, the .S) would
// replace it with Makefile text: bad usage (exit 2) before anything is written, on the first
// run and on a second one (when the file exists).
TEST(Cli, DepfileThatIsAnOutputIsRefused) {
  const auto dir = scratch("cli_depfile_output");
  write_file(dir / "m.obj", kTriangle);
  for (const char* name : {"m.h", "m.cpp", "m.S"}) {
    const auto r = run_converter({"-a", "Cloth", "--depfile", (dir / "out" / name).string(), "-t",
                                  (dir / "out").string(), (dir / "m.obj").string()});
    EXPECT_EQ(r.exit_code, 2) << name << "\n" << r.output;
    EXPECT_NE(r.output.find("--depfile names a file the bake writes"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out")) << name;
  }
  ASSERT_EQ(run_converter({"-a", "Cloth", "-t", (dir / "out").string(), (dir / "m.obj").string()}).exit_code, 0);
  const std::string header = read_file(dir / "out" / "m.h");
  const auto r = run_converter({"-a", "Cloth", "--depfile", (dir / "out" / "." / "m.h").string(), "-t",
                                (dir / "out").string(), (dir / "m.obj").string()});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(read_file(dir / "out" / "m.h"), header);
}

// `--depfile /dev/null` (and any character device or FIFO in an output's place) is written
// into, never replaced by a regular file. (Tested with a device node of its own, not the real
// /dev/null.)
TEST(Cli, CharacterDeviceOutputIsWrittenIntoNotReplaced) {
  const auto dir = scratch("cli_devnull");
  const fs::path null = dir / "mynull";
  if (run_command("mknod -m 666 " + shell_quote(null.string()) + " c 1 3").exit_code != 0 ||
      !fs::is_character_file(null))
    GTEST_SKIP() << "mknod not permitted";
  write_file(dir / "m.obj", kTriangle);
  auto r = run_converter({"-a", "Cloth", "--depfile", null.string(), "-t", (dir / "out").string(),
                          (dir / "m.obj").string()});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_character_file(fs::symlink_status(null)));
  EXPECT_TRUE(fs::exists(dir / "out" / "m.h"));
  // the same for a generated file: the device stays, the others are written
  fs::remove(dir / "out" / "m.S");
  ASSERT_EQ(run_command("mknod -m 666 " + shell_quote((dir / "out" / "m.S").string()) + " c 1 3").exit_code, 0);
  write_file(dir / "m.obj", kTriangle2);
  r = run_converter({"-a", "Cloth", "-t", (dir / "out").string(), (dir / "m.obj").string()});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_character_file(fs::symlink_status(dir / "out" / "m.S")));
  for (const auto& e : fs::directory_iterator(dir / "out"))
    EXPECT_NE(e.path().filename().string()[0], '.') << "temp file left: " << e.path();
  fs::remove(null);
  fs::remove(dir / "out" / "m.S");
}


// An output that is one of the inputs (the model, its .mtl, a texture), by name or through a
// link, is refused before anything is written.
// The model named without a folder (run from its folder) and no -t: the outputs and the
// depfile go next to it (no "cannot make absolute path" for the depfile).
TEST(Cli, BareModelNameWithDepfile) {
  const auto dir = scratch("cli_bare_depfile");
  write_file(dir / "m.obj", "o Cloth\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  std::string cmd = "cd " + shell_quote(dir.string()) + " && " + shell_quote(B2O_CONVERTER) + " -a Cloth --depfile m.d m.obj";
  auto r = run_command(cmd);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "m.h"));
  EXPECT_NE(read_file(dir / "m.d").find((fs::absolute(dir) / "m.h").string() + ":"), std::string::npos);
  r = run_command("cd " + shell_quote(dir.string()) + " && " + shell_quote(B2O_CONVERTER) + " --depfile m.obj m.obj");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("an output would overwrite the input"), std::string::npos) << r.output;
}

TEST(Cli, OutputsNeverOverwriteInputs) {
  const auto dir = scratch("cli_output_is_input");
  const std::string obj = "mtllib m.h\no Cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\n";
  const std::string mtl = "newmtl M\nKd 1 0 0\nmap_Kd tex.png\n";
  write_file(dir / "m.obj", obj);
  write_file(dir / "m.h", mtl);  // the material library, named like the generated header
  write_file(dir / "tex.png", read_file(fixture("checker.png")));
  fs::create_symlink(dir / "m.obj", dir / "link.d");
  const auto before = snapshot(dir);
  auto check = [&](const std::vector<std::string>& args, const std::string& output, const std::string& input) {
    const auto r = run_converter(args);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(output + ": an output would overwrite the input " + input), std::string::npos) << r.output;
    EXPECT_TRUE(snapshot(dir) == before);
    EXPECT_EQ(read_file(dir / "m.obj"), obj);
    EXPECT_EQ(read_file(dir / "m.h"), mtl);
  };
  const std::string m = (dir / "m.obj").string();
  // the generated header in the model's folder is the .mtl
  check({m}, (dir / "m.h").string(), (dir / "m.h").string());
  check({"-t", dir.string(), m}, (dir / "m.h").string(), (dir / "m.h").string());
  // --depfile naming the model, a texture, or a link to the model
  check({"-n", "x", "--depfile", m, "-t", (dir / "out").string(), m}, m, m);
  check({"-n", "x", "--depfile", (dir / "tex.png").string(), "-t", (dir / "out").string(), m},
        (dir / "tex.png").string(), (dir / "tex.png").string());
  check({"-n", "x", "--depfile", (dir / "link.d").string(), "-t", (dir / "out").string(), m},
        (dir / "link.d").string(), m);
  EXPECT_FALSE(fs::exists(dir / "out"));
  // another name is fine
  const auto r = run_converter({"-n", "x", "--depfile", (dir / "x.d").string(), m});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_file(dir / "m.h"), mtl);
}


std::string three_objects(const char* first, const char* second, const char* third) {
  return std::string(first) + " A\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n" + second +
         " B\nv 5 5 5\nv 6 5 5\nv 6 6 5\nf 4 5 6\n" + third + " A\nv 9 9 9\nv 8 9 9\nv 8 8 9\nf 7 8 9\n";
}

// assimp gives the faces of a repeated `o` name (and of a `g` repeated after an `o`) to the
// object before it: refused at the repeated line. A `g` repeated after another group is a
// second object of that name (warned); choosing it by that name with -a is an error naming both
// lines, by its identifier it works.
TEST(Cli, RepeatedObjectNamesNeverMoveGeometry) {
  const auto dir = scratch("cli_repeated_names");
  write_file(dir / "o.obj", three_objects("o", "o", "o"));
  auto r = run_converter({"-a", "B", "-t", (dir / "out").string(), (dir / "o.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "o.obj").string() + ":11: object name 'A' repeated (first at line 1)"),
            std::string::npos)
      << r.output;
  write_file(dir / "m.obj", three_objects("g", "o", "g"));
  r = run_converter({"-a", "B", "-t", (dir / "out").string(), (dir / "m.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "m.obj").string() + ":11: group 'A' repeated (first at line 1) after object 'B'"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));

  write_file(dir / "g.obj", three_objects("g", "g", "g"));
  const std::string g = (dir / "g.obj").string();
  r = run_converter({"-a", "A", "-t", (dir / "out").string(), g});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(g + ": -a 'A': 2 objects are named 'A' (" + g + ":1, " + g + ":11)"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
  r = run_converter({"-a", "B", "-t", (dir / "out").string(), g});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: " + g + ":11: group 'A' repeated (first at line 1)"), std::string::npos) << r.output;

  // a repeat without a face while assimp's owner differs is harmless: accepted; a `g` that
  // continues the current object still sets assimp's active group
  write_file(dir / "ok.obj", three_objects("o", "g", "g") + "o B\ng A\nf 7 8 9\n");
  r = run_converter({"-a", "B", "-t", (dir / "out_ok").string(), (dir / "ok.obj").string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  write_file(dir / "ga.obj", "o A\ng A\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\no B\nf 3 2 1\ng A\nf 1 2 3\n");
  r = run_converter({"-t", (dir / "out").string(), (dir / "ga.obj").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "ga.obj").string() + ":9: group 'A' repeated (first at line 1) after object 'B'"),
            std::string::npos)
      << r.output;

  b2o::conv::Options opt;
  opt.input = dir / "g.obj";
  opt.cloth_objects = {"A_2"};
  const auto s = convert(opt);
  ASSERT_EQ(s.objects.size(), 3u);
  ASSERT_EQ(s.cloths.size(), 1u);
  EXPECT_EQ(s.cloths[0].object, 2u);
  EXPECT_EQ(s.cloths[0].rest_positions[0], 9.0f);
  opt.cloth_objects = {"B"};
  const auto sb = convert(opt);
  EXPECT_EQ(sb.cloths[0].triangles.size(), 3u);
  EXPECT_EQ(sb.cloths[0].rest_positions[0], 5.0f);
}


// Text on which assimp fails without a line (or blames the .obj for its .mtl) is refused by
// the pre-scan with file:line; a trailing comment on a v/f line is accepted (assimp gets the
// line without it).
TEST(Cli, StatementsAssimpMisreadsAreRefusedWithTheirLine) {
  const auto dir = scratch("cli_assimp_misreads");
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  struct Case {
    std::string obj, mtl, where, expect;
  };
  const std::string mtl_obj = "mtllib m.mtl\n" + tri + "usemtl M\nf 1 2 3\n";
  const std::vector<Case> cases = {
      {"v 0 0 0 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "", "m.obj:1: ", "'v' takes 3 coordinates"},
      {"v 0 0 0 1 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "", "m.obj:1: ", "'v' takes 3 coordinates (x y z), 4 (x y z w) or 6 (x y z r g b), found 8"},
      {"v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "", "m.obj:1: ", "'v' with w = 0"},
      {tri + "vt 0.5\nf 1/1 2/1 3/1\n", "", "m.obj:4: ", "'vt' takes 2 coordinates"},
      {tri + "vn 0 0 1 0\nf 1//1 2//1 3//1\n", "", "m.obj:4: ", "'vn' takes 3 coordinates"},
      {tri + "vt 0 0\nvn 0 0 1\nf 1/1/1/1 2/1/1 3/1/1\n", "", "m.obj:6: ", "malformed vertex reference '1/1/1/1'"},
      {"v 0 0 0 \\\n\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\n", "", "m.obj:1: ", "line continuation ('\\' at the end) followed by an empty line"},
      {mtl_obj, "newmtl M\nKd 1 0\n", "m.mtl:2: ", "'Kd' takes 3 numbers (r g b) or 1 (grey), found 2"},
      {mtl_obj, "newmtl M\nKd a b c\n", "m.mtl:2: ", "malformed number 'a' in 'Kd'"},
      {mtl_obj, "newmtl M\nNs\n", "m.mtl:2: ", "'Ns' takes 1 number, found 0"},
  };
  for (const Case& c : cases) {
    write_file(dir / "m.obj", c.obj);
    write_file(dir / "m.mtl", c.mtl);
    const auto r = run_converter({"-t", (dir / "out").string(), (dir / "m.obj").string()});
    EXPECT_EQ(r.exit_code, 1) << c.obj << r.output;
    EXPECT_NE(r.output.find((dir / c.where).string() + c.expect), std::string::npos) << c.obj << r.output;
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
  // a w other than 0 is accepted (assimp divides x, y, z by it)
  write_file(dir / "w.obj", "v 0 0 0 1\nv 2 0 0 2\nv 0 1 0 1.0\nf 1 2 3\n");
  const auto sw = b2o::conv::import_scene(dir / "w.obj", false);
  ASSERT_EQ(sw.positions.size(), 9u);
  EXPECT_EQ(sw.positions[3], 1.0f);
  // comments after numbers: accepted, the same geometry as without them
  write_file(dir / "c.obj", "v 0 0 0 # a b c\nv 1 0 0\nv 0 1 0\nf 1 2 3 # comment\r\nf 3 2 1#c\n");
  const auto s = b2o::conv::import_scene(dir / "c.obj", false);
  ASSERT_EQ(s.indices.size(), 6u);
  EXPECT_EQ(s.positions[0], 0.0f);
  EXPECT_EQ(s.positions[3], 1.0f);
}


// `usemtl` naming a material no library defines (or with no mtllib at all) gets assimp's
// invented grey material: a warning at its line, exit 0.
TEST(Cli, UsemtlWithoutDefinitionIsWarnedAtItsLine) {
  const auto dir = scratch("cli_usemtl_undefined");
  write_file(dir / "a.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\nusemtl Nothing\nf 3 2 1\n");
  write_file(dir / "a.mtl", "newmtl M\nKd 1 0 0\n");
  auto r = run_converter({"-t", (dir / "out").string(), (dir / "a.obj").string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: " + (dir / "a.obj").string() +
                          ":7: material 'Nothing' is defined in no material library"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find(":5: material 'M'"), std::string::npos) << r.output;
  write_file(dir / "b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl Nothing\nf 1 2 3\n");
  r = run_converter({"-t", (dir / "out").string(), (dir / "b.obj").string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: " + (dir / "b.obj").string() + ":4: material 'Nothing' used but no 'mtllib'"),
            std::string::npos)
      << r.output;
}

// MTL: one number is a grey (r = g = b), as the spec says (assimp alone reads (r, 0, 0));
// a material defined twice is merged by assimp: a warning at the second newmtl.
TEST(Cli, MtlGreyColorAndRepeatedMaterial) {
  const auto dir = scratch("cli_mtl_grey");
  write_file(dir / "a.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl M\nf 1 2 3\n");
  write_file(dir / "a.mtl", "newmtl M\nKd 1\r\nKs 0.5 # half\nNs 10\n\nnewmtl M\nKa 0.25\n");
  const auto s = b2o::conv::import_scene(dir / "a.obj", false);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].diffuse, (std::array<float, 3>{1.0f, 1.0f, 1.0f}));
  EXPECT_EQ(s.materials[0].specular, (std::array<float, 3>{0.5f, 0.5f, 0.5f}));
  EXPECT_EQ(s.materials[0].ambient, (std::array<float, 3>{0.25f, 0.25f, 0.25f}));
  EXPECT_EQ(s.materials[0].shininess, 10.0f);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find((dir / "a.mtl").string() + ":6: material 'M' defined again (first at line 1)"),
            std::string::npos)
      << s.warnings[0];
}


// A cloth whose triangles are all degenerate (a repeated vertex, collinear points) would get
// no springs: an error naming the object and the file, nothing written.
TEST(Cli, ClothWithoutUsableTriangleIsRefused) {
  const auto dir = scratch("cli_cloth_no_triangle");
  for (const std::string& obj : {std::string("o Cloth\nv 0 0 0\nf 1 1 1\n"),
                                 std::string("o Cloth\nv 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"
                                             "o Floor\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 4 5 6\n")}) {
    write_file(dir / "m.obj", obj);
    const auto r = run_converter({"-a", "Cloth", "-t", (dir / "out").string(), (dir / "m.obj").string()});
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find((dir / "m.obj").string() + ": cloth 'Cloth': no usable triangle"), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "out"));
    // (without -a the object is only drawn: accepted)
    EXPECT_EQ(run_converter({"-t", (dir / "out2").string(), (dir / "m.obj").string()}).exit_code, 0);
  }
}


// Formats without the pre-scan: assimp's OFF importer clamps a face index out of range to the
// last vertex (an error in its log, a wrong triangle): refused. Its other logged errors are
// warnings, not silent.
TEST(Cli, NonObjIndexOutOfRangeIsRefused) {
  const auto dir = scratch("cli_off_range");
  write_file(dir / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 99\n");
  auto r = run_converter({"-t", (dir / "out").string(), (dir / "bad.off").string()});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "bad.off").string() + ": cannot import: OFF: Vertex index is out of range"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
  write_file(dir / "good.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  r = run_converter({"-t", (dir / "out").string(), (dir / "good.off").string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, "");
}

}  // namespace
