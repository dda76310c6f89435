// The clothsim command line: help, bad values (exit 2, nothing written), the JSON report,
// OBJ export, the seed's aliases and a forced blow-up (finite: false, exit 1).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "program.hpp"

namespace {

using namespace clothsim::testing;

Result run(const std::string& args, const std::string& shell_prefix = "") {
  return run_program(CLOTHSIM_DICE_EXE, args, shell_prefix);
}

TEST(Cli, HelpExitsZeroAndListsDefaultsAndTheSceneValues) {
  const Result r = run("--help");
  EXPECT_EQ(r.code, 0) << r.output;
  for (const char* s : {"--headless", "--seconds", "--steps", "--dt", "--k-struct", "--k-rep", "--report",
                        "--export-obj", "--screenshot", "-step", "-wstiff", "600", "9.81"})
    EXPECT_NE(r.output.find(s), std::string::npos) << "help lacks " << s;
}

TEST(Cli, VersionExitsZero) {
  const Result r = run("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.output.find("clothsim"), std::string::npos);
}

TEST(Cli, BadValuesExitTwoWithAMessageAndWriteNothing) {
  const fs::path d = fresh_dir("bad");
  const std::string report = (d / "r.json").string();
  struct Case {
    const char* args;
    const char* says;
  } cases[] = {{"--dt 0", "dt"},           {"--dt -0.01", "dt"},     {"--dt nan", "dt"},
               {"--mass 0", "mass"},        {"--k-struct -5", "--k-struct"}, {"--damping inf", "damping"},
               {"--dt abc", "--dt"},        {"--bogus", "bogus"},     {"--seconds 1 --steps 5", "steps"},
               {"--seconds -2", "seconds"}, {"-step 0", "dt"},   {"--threads abc", "--threads"},
               {"--threads -1", "--threads"}, {"--threads 1025", "--threads"}, {"--threads Auto", "auto"},
               {"--gravity ''", "--gravity"}, {"--dt ''", "--dt needs a number"},
               {"--dt 0x10", "--dt takes a decimal number"}};
  for (const Case& c : cases) {
    const Result r = run(std::string("--headless --report '") + report + "' " + c.args);
    EXPECT_EQ(r.code, 2) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find("error"), std::string::npos) << c.args;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
    EXPECT_FALSE(fs::exists(report)) << c.args;
  }
  EXPECT_TRUE(fs::is_empty(d));
  // spaces around a number, at either end, are read alike ('0.005 ' is no "Could not convert")
  for (const char* dt : {"' 0.005'", "'0.005 '", "' 0.005\t'"})
    EXPECT_EQ(run(std::string("--headless --quiet --steps 1 --dt ") + dt).code, 0) << dt;
}

// Runs that would never end are refused before they start (exit 2, one line, the count):
// a tiny --dt (1e30 steps), a count above 2^64 (CLI11 reads it as 2^64-1), substeps on top.
TEST(Cli, AbsurdStepCountsAreRefusedAtOnce) {
  struct Case {
    const char* args;
    const char* says;
  } cases[] = {{"--seconds 1 --dt 1e-30", "1e+30 steps"},
               {"--seconds 1e300", "steps"},
               {"--steps 99999999999999999999", "--steps must be 1..1000000000"},
               {"--steps 18446744073709551615", "--steps must be 1..1000000000"},
               {"--steps 1000000001", "--steps must be 1..1000000000"},
               {"--steps 600000000 --dt 0.03", "substeps each is 1800000000 steps"},
               {"--steps 010", ""},  // decimal, not octal: runs 10 steps
               {"--steps 1e3", "whole number"}};
  for (const Case& c : cases) {
    const Result r = run(std::string("--headless --quiet ") + c.args, "timeout 20 ");
    if (std::string(c.says).empty()) {
      EXPECT_EQ(r.code, 0) << c.args << ": " << r.output;
      continue;
    }
    EXPECT_EQ(r.code, 2) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1) << c.args << ": " << r.output;
  }
  // without --quiet still one line; and a window timed by --seconds is refused the same way
  // (before the window opens: no display needed)
  for (const char* args : {"--headless --seconds 1 --dt 1e-30", "--seconds 1 --dt 1e-30"}) {
    const Result r = run(args, "timeout 20 ");
    EXPECT_EQ(r.code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find("1e+30 steps"), std::string::npos) << args << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1) << args << ": " << r.output;
  }
}

// The range message is readable (not DBL_MAX in 309 digits).
TEST(Cli, ExportEveryZeroSaysAtLeastOne) {
  const Result r = run("--headless --quiet --steps 5 --export-every 0");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--export-every must be >= 1 (got 0)"), std::string::npos) << r.output;
  EXPECT_LT(r.output.size(), 100u) << r.output;
}

// The viewer's window limits are bad input like any other option: exit 2, a readable range.
TEST(Cli, WindowSizeAndFpsOutsideTheirRangeAreBadInput) {
  for (const char* args : {"--width 0", "--width 100000", "--height 15", "--fps 0"}) {
    const Result r = run(std::string("--headless --quiet --steps 5 ") + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find("not in range"), std::string::npos) << r.output;
    EXPECT_LT(r.output.size(), 100u) << r.output;
  }
}

// Ctrl-C (SIGINT) in a long headless run: it stops after the step in progress, says where,
// and still writes its report, marked interrupted; exit 130 as a shell reports Ctrl-C. (The
// signal comes at 2 s, any time after start-up: the outcome is the same whenever it lands.)
TEST(Cli, InterruptedRunStillWritesItsReport) {
  const fs::path d = fresh_dir("interrupt");
  const fs::path report = d / "r.json";
  const Result r = run("--headless --quiet --seconds 1000000 --report '" + report.string() + "'",
                       "timeout --preserve-status -s INT 2 ");
  EXPECT_EQ(r.code, 130) << r.output;
  EXPECT_NE(r.output.find("interrupted after"), std::string::npos) << r.output;
  ASSERT_TRUE(fs::exists(report)) << r.output;
  const auto j = read_json(report);
  EXPECT_EQ(j["interrupted"], true);
  EXPECT_EQ(j["finite"], true);
  EXPECT_LT(j["steps"].get<double>(), 1e8);
  const double t = j["steps"].get<double>() * j["dt"].get<double>();
  EXPECT_NEAR(j["seconds_simulated"].get<double>(), t, 1e-9 * t + 1e-12);  // t summed step by step
}

TEST(Cli, ReportIntoAMissingFolderIsRefusedBeforeRunning) {
  const fs::path d = fresh_dir("missing");
  const Result r = run("--headless --report '" + (d / "no" / "r.json").string() + "'");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("does not exist"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::is_empty(d));
}

// A directory named as the report: refused before the run (exit 2), whichever way it is
// spelled, and left as it is (not exit 0 with no report and no word).
TEST(Cli, ReportIntoADirectoryIsRefusedBeforeRunning) {
  const fs::path d = fresh_dir("report_dir");
  fs::create_directory(d / "somedir");
  for (const std::string where : {"somedir", "somedir/", ".", "./somedir/."}) {
    const Result r = run("--headless --quiet --steps 50 --report '" + where + "'", "cd " + q(d) + " && ");
    EXPECT_EQ(r.code, 2) << where << ": " << r.output;
    EXPECT_NE(r.output.find(q(where) + " is a directory"), std::string::npos) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
  }
  EXPECT_TRUE(fs::is_empty(d / "somedir"));
  EXPECT_EQ(entries(d), 1);
}

// A device (our own /dev/null) is written into, not replaced by a regular file.
TEST(Cli, ReportIntoADeviceWritesThroughItAndKeepsIt) {
  const fs::path d = fresh_dir("report_null");
  if (!make_char_device(d / "mynull", 3)) GTEST_SKIP() << "mknod not permitted: " << std::strerror(errno);
  const Result r = run("--headless --quiet --steps 20 --report " + q(d / "mynull"));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(is_char_device(d / "mynull")) << "the device was replaced";
  EXPECT_EQ(entries(d), 1) << "a temporary file was left";
}

// A full device (our own /dev/full): an I/O error naming it, exit 1, the device kept.
TEST(Cli, ReportIntoAFullDeviceIsAnIoError) {
  const fs::path d = fresh_dir("report_full");
  if (!make_char_device(d / "myfull", 7)) GTEST_SKIP() << "mknod not permitted: " << std::strerror(errno);
  const Result r = run("--headless --quiet --steps 20 --report " + q(d / "myfull"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("myfull"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("No space left"), std::string::npos) << r.output;
  EXPECT_EQ(lines(r.output), 1) << r.output;
  EXPECT_TRUE(is_char_device(d / "myfull"));
  EXPECT_EQ(entries(d), 1);
}

// A write that fails (a file size limit of 0 blocks: EFBIG, and SIGXFSZ, which would kill the
// program) is reported; the old report stays and no temporary file is left.
TEST(Cli, FailedReportWriteKeepsTheOldReport) {
  const fs::path d = fresh_dir("report_efbig");
  { std::ofstream(d / "r.json") << "old\n"; }
  const Result r = run("--headless --quiet --steps 20 --report " + q(d / "r.json"), "ulimit -f 0; ");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("r.json"), std::string::npos) << r.output;
  EXPECT_EQ(lines(r.output), 1) << r.output;
  EXPECT_EQ(slurp(d / "r.json"), "old\n");
  EXPECT_EQ(entries(d), 1);
}

TEST(Cli, ReportHasTheKeys) {
  const fs::path d = fresh_dir("report");
  const Result r = run("--headless --quiet --steps 50 --report '" + (d / "r.json").string() + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = read_json(d / "r.json");
  for (const char* k : {"scene", "masses", "springs", "collider_triangles", "dt", "steps", "seconds_simulated",
                        "ms_per_step", "finite", "cloth_min", "cloth_max", "max_penetration", "kinetic_energy",
                        "options", "warnings"})
    EXPECT_TRUE(j.contains(k)) << k;
  // the dice's plane is an open mesh: no collider warnings (closed_mesh_test has the others)
  EXPECT_TRUE(j["warnings"].is_array() && j["warnings"].empty()) << j["warnings"];
  EXPECT_EQ(j["scene"], "dice");
  EXPECT_EQ(j["masses"], 16);
  EXPECT_EQ(j["pinned_masses"], 0);
  EXPECT_EQ(j["collider_triangles"], 2);
  EXPECT_EQ(j["steps"], 50);
  EXPECT_EQ(j["finite"], true);
  EXPECT_NEAR(j["seconds_simulated"].get<double>(), 50 * j["dt"].get<double>(), 1e-9);
  for (int c = 0; c < 3; ++c) EXPECT_LE(j["cloth_min"][c].get<double>(), j["cloth_max"][c].get<double>());
  EXPECT_GE(j["max_penetration"].get<double>(), 0.0);
  EXPECT_GT(j["kinetic_energy"].get<double>(), 0.0);  // the dice are falling at t = 0.5 s
  EXPECT_GE(j["ms_per_step"].get<double>(), 0.0);
  // nothing but the report in the folder (the temp file is renamed)
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 1);
}

// --seconds covers the time asked: a whole number of steps of dt when it is one (up to
// rounding), else one step more, never none for a positive time; a note says so.
TEST(Cli, SecondsAreCoveredByWholeSteps) {
  const fs::path d = fresh_dir("seconds");
  struct Case {
    const char* args;
    int steps;
    bool note;
  } cases[] = {{"--seconds 0.5 --dt 1.5", 1, true},  {"--seconds 0.4 --dt 0.3", 2, true},
               {"--seconds 0.3 --dt 0.1", 3, false}, {"--seconds 1 --dt 0.0004", 2500, false},
               {"--seconds 0 --dt 0.01", 0, false},  {"--seconds 0.011 --dt 0.01", 2, true},
               {"--seconds 20.0000001 --dt 0.0004", 50001, true}};
  for (const Case& c : cases) {
    const fs::path report = d / "r.json";
    const Result r = run(std::string("--headless --report ") + q(report) + " " + c.args);
    ASSERT_EQ(r.code, 0) << c.args << ": " << r.output;
    const auto j = read_json(report);
    EXPECT_EQ(j["steps"], c.steps) << c.args;
    EXPECT_EQ(r.output.find("is not a whole number of steps") != std::string::npos, c.note) << c.args << ": " << r.output;
  }
}

// Two outputs at one path are refused before the run (the second would replace the first or
// stop at it): also through ".." and a symbolic link (fileio_test: devices, "dir/").
TEST(Cli, TwoOutputsAtOnePathAreRefusedBeforeRunning) {
  const fs::path d = fresh_dir("same_output");
  fs::create_directories(d / "out");
  fs::create_directory_symlink(d / "out", d / "link");
  for (const std::string& args : {"--export-obj " + q(d / "out" / "x") + " --report " + q(d / "out" / "x"),
                                  "--export-obj " + q(d / "out" / "x") + " --report " + q(d / "out" / ".." / "out" / "x"),
                                  "--export-obj " + q(d / "link" / "x") + " --report " + q(d / "out" / "x")}) {
    const Result r = run("--headless --quiet --steps 20 " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find("--report and --export-obj both name"), std::string::npos) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
  }
  EXPECT_TRUE(fs::is_empty(d / "out"));
}

// A file output named as one of the files a folder output writes (the report as the step-0
// OBJ) would replace it, or be replaced: refused before the run, also through ".."; another
// name in that folder is fine. (--screenshot among --frames: tests/viewer.)
TEST(Cli, AFileOutputAmongTheExportedFilesIsRefused) {
  const fs::path d = fresh_dir("among_exported");
  fs::create_directories(d / "exp");  // (a report's folder must exist)
  for (const std::string& report : {(d / "exp" / "dice_000000.obj").string(), (d / "exp" / ".." / "exp" / "dice_000010.obj").string(),
                                    (d / "exp" / "dice_1234567.obj").string()}) {
    const Result r = run("--headless --quiet --steps 20 --export-obj " + q(d / "exp") + " --report " + q(report));
    EXPECT_EQ(r.code, 2) << report << ": " << r.output;
    EXPECT_NE(r.output.find("is one of the files --export-obj writes (dice_NNNNNN.obj)"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::is_empty(d / "exp")) << report;
  }
  for (const char* name : {"dice.json", "dice_00001.obj", "dice_000000.json", "hanging_000000.obj"}) {
    const Result r = run("--headless --quiet --steps 20 --export-obj " + q(d / "exp") + " --report " + q(d / "exp" / name));
    EXPECT_EQ(r.code, 0) << name << ": " << r.output;
    EXPECT_TRUE(fs::exists(d / "exp" / "dice_000000.obj"));
    EXPECT_TRUE(fs::exists(d / "exp" / name));
    fs::remove_all(d / "exp");
    fs::create_directories(d / "exp");
  }
}

// A finite state whose kinetic energy overflows a double (the summary would say "inf J", the
// report null): a failure (exit 1) that says why, in the report's warnings too.
TEST(Cli, KineticEnergyOverflowIsAFailure) {
  const fs::path d = fresh_dir("ke_overflow");
  const Result r = run("--headless --seconds 1 --mass 1e306 --report " + q(d / "r.json"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("error: the kinetic energy overflows a double at t = 1 s"), std::string::npos) << r.output;
  const auto j = read_json(d / "r.json");
  EXPECT_TRUE(j["kinetic_energy"].is_null());
  EXPECT_NE(j["warnings"].back().get<std::string>().find("kinetic energy overflows"), std::string::npos) << j["warnings"];
  EXPECT_EQ(run("--headless --quiet --seconds 1 --mass 1e300").code, 0);  // large, but in range
}

// fast-mass-spring and XPBD take velocities from position differences: a step whose motion
// g h^2 is near the positions' rounding gives velocities of rounding (XPBD at dt 1e-15 loses
// gravity): warned, with the smallest sound step; a sound step is not warned.
TEST(Cli, PositionBasedMethodsWarnOfStepsBelowThePositionsRounding) {
  for (const char* method : {"fast-mass-spring", "xpbd"}) {
    const Result tiny = run(std::string("--headless --quiet --steps 2 --dt 1e-9 --integrator ") + method);
    EXPECT_EQ(tiny.code, 0) << tiny.output;
    EXPECT_NE(tiny.output.find(std::string("warning: ") + method + " takes velocities from position differences"),
              std::string::npos) << tiny.output;
    EXPECT_EQ(run(std::string("--headless --quiet --steps 2 --dt 1e-4 --integrator ") + method).output, "") << method;
  }
  EXPECT_EQ(run("--headless --quiet --steps 2 --dt 1e-9").output, "");  // symplectic Euler keeps v itself
}

TEST(Cli, ExportEveryWithoutExportObjIsBadInput) {
  const Result r = run("--headless --quiet --steps 5 --export-every 5");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--export-every needs --export-obj"), std::string::npos) << r.output;
}

// --threads: auto (the default) or a count; the report says which, and how many steps each
// count took (a small model such as the dice's never splits: all on one thread).
TEST(Cli, ThreadsAutoOrACountReachTheReport) {
  const fs::path d = fresh_dir("threads");
  const struct {
    const char* args;
    nlohmann::json threads, steps;
  } cases[] = {{"", "auto", {{"1", 40}}},
               {"--threads auto", "auto", {{"1", 40}}},
               {"--threads 2", 2, {{"1", 40}}},  // asked, but 16 masses do not split
               {"--threads 1", 1, {{"1", 40}}}};
  for (const auto& c : cases) {
    const Result r = run("--headless --quiet --steps 40 --report " + q(d / "r.json") + " " + c.args);
    ASSERT_EQ(r.code, 0) << c.args << ": " << r.output;
    const auto j = read_json(d / "r.json");
    EXPECT_EQ(j["threads"], c.threads) << c.args;
    EXPECT_EQ(j["thread_steps"], c.steps) << c.args;
  }
}

// docs/scenes.md documents every field the report has, the options' fields too.
TEST(Cli, EveryReportFieldIsDocumented) {
  const fs::path d = fresh_dir("report_doc");
  // a blow-up, so that failed_step is there too, and --check-crossings for its keys
  const Result r =
      run("--headless --quiet --dt 0.5 --substeps 1 --seconds 1000 --check-crossings --report " + q(d / "r.json"));
  ASSERT_EQ(r.code, 1) << r.output;
  const auto j = read_json(d / "r.json");
  EXPECT_TRUE(j["self_crossings"].is_null()) << j["self_crossings"];  // a failed run's state is no mesh
  EXPECT_TRUE(j.contains("max_self_crossings") && j.contains("max_self_crossings_t"));
  const std::string doc = slurp(CLOTHSIM_SCENES_DOC);
  const std::string report_section = doc.substr(doc.find("**The report**"));
  ASSERT_GT(report_section.size(), 100u);
  for (const auto& [k, v] : j.items())
    EXPECT_NE(report_section.find("`" + k + "`"), std::string::npos) << "undocumented report field " << k;
  for (const auto& [k, v] : j["options"].items())
    EXPECT_NE(report_section.find("`" + k + "`"), std::string::npos) << "undocumented option field " << k;
  // max_penetration is not read as a depth: the docs say what it is
  EXPECT_NE(report_section.find("behind a surface, as far as the search reaches (2 eps)"), std::string::npos);
  EXPECT_NE(report_section.find("before the run"), std::string::npos);  // tunnelling_warning is an estimate
}

// A die that falls through its plane (k_rep almost 0): max_penetration is what the search saw,
// at most 2 eps; the report and the summary say so instead of passing it off as a depth.
TEST(Cli, MaxPenetrationPastTheBandIsLabelled) {
  const fs::path d = fresh_dir("penetration");
  const Result r = run("--headless --steps 300 --k-rep 0.001 --report " + q(d / "r.json"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = read_json(d / "r.json");
  EXPECT_DOUBLE_EQ(j["max_penetration_reach"].get<double>(), 0.2);
  EXPECT_GT(j["max_penetration"].get<double>(), 0.1);
  EXPECT_LE(j["max_penetration"].get<double>(), 0.2);
  EXPECT_EQ(j["max_penetration_past_eps"], true);
  EXPECT_NE(r.output.find("(behind a surface, as far as the search reaches: 2 eps = 0.2 m; past eps the contact "
                          "lets go, masses may be deeper or through)"),
            std::string::npos)
      << r.output;
  // the baked dice for 0.5 s (falling, nothing behind the plane): no label
  const Result rest = run("--headless --steps 50 --report " + q(d / "r2.json"));
  ASSERT_EQ(rest.code, 0) << rest.output;
  EXPECT_EQ(read_json(d / "r2.json")["max_penetration_past_eps"], false);
  EXPECT_EQ(rest.output.find("search reaches"), std::string::npos) << rest.output;
}

TEST(Cli, SeedAliasesAndPhysicalOptionsReachTheReport) {
  const fs::path d = fresh_dir("alias");
  const Result r = run("--headless --quiet --steps 10 -step 0.005 -mass 0.2 -stiff 300 -wstiff 40 -damp 0.3 "
                       "--k-rep 800 --gravity 1 --report '" + (d / "r.json").string() + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto o = read_json(d / "r.json")["options"];
  EXPECT_DOUBLE_EQ(o["dt"].get<double>(), 0.005);
  EXPECT_DOUBLE_EQ(o["mass"].get<double>(), 0.2);
  EXPECT_DOUBLE_EQ(o["k_struct"].get<double>(), 300);
  EXPECT_DOUBLE_EQ(o["k_bend"].get<double>(), 40);
  EXPECT_DOUBLE_EQ(o["damping"].get<double>(), 0.3);
  EXPECT_DOUBLE_EQ(o["k_rep"].get<double>(), 800);
  EXPECT_DOUBLE_EQ(o["gravity_y"].get<double>(), -1.0);
}

TEST(Cli, ExportObjWritesEveryKSteps) {
  const fs::path d = fresh_dir("obj");
  const Result r = run("--headless --quiet --steps 20 --export-every 5 --export-obj '" + (d / "frames").string() + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  int files = 0;
  for (const auto& e : fs::directory_iterator(d / "frames")) {
    ++files;
    std::ifstream in(e.path());
    std::string text, line;
    while (std::getline(in, line)) text += line + "\n";
    EXPECT_NE(text.find("o RollingDie"), std::string::npos);
    EXPECT_NE(text.find("o Die"), std::string::npos);
    EXPECT_GE(std::count(text.begin(), text.end(), '\n'), 16 + 24);  // 16 vertices + 24 triangles
    // the render mesh: texture coordinates, faces v/vt, as many vt as v
    EXPECT_NE(text.find("\nvt "), std::string::npos);
    EXPECT_NE(text.find("\nf 1/1 "), std::string::npos) << text.substr(0, 400);
    std::istringstream lines(text);
    int v = 0, vt = 0;
    for (std::string l; std::getline(lines, l);) {
      if (l.rfind("v ", 0) == 0) ++v;
      if (l.rfind("vt ", 0) == 0) ++vt;
    }
    EXPECT_EQ(v, vt);
  }
  EXPECT_EQ(files, 5);  // steps 0, 5, 10, 15, 20
  EXPECT_TRUE(fs::exists(d / "frames" / "dice_000020.obj"));
  // positions exactly: at step 0 every coordinate is the model's float, read back bit for bit
  // (6 significant digits would write 0.0182616 for 0.018261615244430603)
  std::ifstream in(d / "frames" / "dice_000000.obj");
  int checked = 0;
  for (std::string l; std::getline(in, l);)
    if (l.rfind("v ", 0) == 0) {
      std::istringstream w(l.substr(2));
      for (double c; w >> c; ++checked) EXPECT_EQ(c, static_cast<double>(static_cast<float>(c))) << l;
    }
  EXPECT_GE(checked, 3 * 16);
}

// A file where the OBJ directory should be: bad input before the run (exit 2).
TEST(Cli, ExportObjIntoAFileIsRefusedBeforeRunning) {
  const fs::path d = fresh_dir("obj_file");
  { std::ofstream(d / "frames") << "not a directory\n"; }
  for (const fs::path& where : {d / "frames", d / "frames" / "sub"}) {
    const Result r = run("--headless --quiet --steps 20 --export-obj " + q(where));
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("is not a directory"), std::string::npos) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
  }
  EXPECT_EQ(slurp(d / "frames"), "not a directory\n");
}

// An OBJ name taken by a directory: exit 1 and a message naming that file.
TEST(Cli, ExportObjNamesTheFileItCannotWrite) {
  const fs::path d = fresh_dir("obj_taken");
  fs::create_directories(d / "frames" / "dice_000010.obj");
  const Result r = run("--headless --quiet --steps 20 --export-every 5 --export-obj " + q(d / "frames"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("dice_000010.obj' is a directory"), std::string::npos) << r.output;
  EXPECT_EQ(lines(r.output), 1) << r.output;
  EXPECT_TRUE(fs::is_empty(d / "frames" / "dice_000010.obj"));
  EXPECT_EQ(entries(d / "frames"), 3);  // steps 0 and 5 written, then the stop
}

// The viewer's outputs are checked before the window opens (no display needed to see it):
// a directory as the --screenshot PNG, a file as the --frames directory.
TEST(Cli, ScreenshotOrFramesPathsAreCheckedBeforeRunning) {
  const fs::path d = fresh_dir("viewer_paths");
  fs::create_directory(d / "shot.png");
  { std::ofstream(d / "frames") << "not a directory\n"; }
  const Result shot = run("--seconds 1 --screenshot " + q(d / "shot.png"));
  EXPECT_EQ(shot.code, 2) << shot.output;
  EXPECT_NE(shot.output.find("shot.png' is a directory"), std::string::npos) << shot.output;
  EXPECT_EQ(lines(shot.output), 1) << shot.output;
  const Result frames = run("--seconds 1 --frames " + q(d / "frames"));
  EXPECT_EQ(frames.code, 2) << frames.output;
  EXPECT_NE(frames.output.find("is not a directory"), std::string::npos) << frames.output;
  EXPECT_EQ(lines(frames.output), 1) << frames.output;
  EXPECT_TRUE(fs::is_empty(d / "shot.png"));
  EXPECT_EQ(entries(d), 2);
}

// --headless has no viewer to render with: --screenshot/--frames are refused (exit 2) rather
// than exit 0 with no picture; nothing written.
TEST(Cli, HeadlessScreenshotOrFramesIsRefused) {
  const fs::path d = fresh_dir("headless_shot");
  const Result shot = run("--headless --quiet --steps 5 --screenshot " + q(d / "x.png"));
  EXPECT_EQ(shot.code, 2) << shot.output;
  EXPECT_NE(shot.output.find("--screenshot"), std::string::npos) << shot.output;
  EXPECT_NE(shot.output.find("--headless"), std::string::npos) << shot.output;
  EXPECT_EQ(lines(shot.output), 1) << shot.output;
  const Result frames = run("--headless --quiet --seconds 0.1 --frames " + q(d / "frames"));
  EXPECT_EQ(frames.code, 2) << frames.output;
  EXPECT_NE(frames.output.find("--frames"), std::string::npos) << frames.output;
  EXPECT_TRUE(fs::is_empty(d));
}

// The guard's refusal says what is true: with damping 0.1 it never says "no damping".
TEST(Cli, UnstableIntegratorMessageTellsTheTruthAboutDamping) {
  const Result heavy = run("--headless --quiet --steps 5 --integrator symplectic-euler --mass 1e-45");
  EXPECT_EQ(heavy.code, 2) << heavy.output;
  EXPECT_EQ(heavy.output.find("no damping"), std::string::npos) << heavy.output;
  EXPECT_NE(heavy.output.find("substeps"), std::string::npos) << heavy.output;  // dt_stable is tiny
  EXPECT_EQ(lines(heavy.output), 1) << heavy.output;
  const Result none = run("--headless --quiet --steps 5 --integrator explicit-euler --damping 0");
  EXPECT_EQ(none.code, 2) << none.output;
  EXPECT_NE(none.output.find("(damping 0)"), std::string::npos) << none.output;
  // a stiffness whose k / m overflows: refused as well (Lanczos would say 0 rad/s)
  for (const char* k : {"1e305", "1e308"}) {
    const Result stiff = run(std::string("--headless --quiet --steps 5 --k-struct ") + k);
    EXPECT_EQ(stiff.code, 2) << k << ": " << stiff.output;
    EXPECT_NE(stiff.output.find("overflows"), std::string::npos) << stiff.output;
  }
  const Result light = run("--headless --quiet --steps 5 --mass 1e-320");
  EXPECT_EQ(light.code, 2) << light.output;
  EXPECT_NE(light.output.find("too light"), std::string::npos) << light.output;
  EXPECT_EQ(lines(light.output), 1) << light.output;
}

// dice: dt_stable 0.01255 s, safe step 0.9 x that = 0.0113 s. dt 0.012 is below dt_stable but
// above the safe step: auto takes 2 substeps and says so truthfully; off refuses, as the note
// says ("--substeps off to refuse instead").
TEST(Cli, SubstepNoteAndOffAgree) {
  const Result a = run("--headless --steps 3 --dt 0.012");
  EXPECT_EQ(a.code, 0) << a.output;
  EXPECT_EQ(a.output.find("exceeds"), std::string::npos) << a.output;
  EXPECT_NE(a.output.find("dt 0.012 s is above the safe step 0.01"), std::string::npos) << a.output;
  EXPECT_NE(a.output.find(" s (0.9 x dt_stable 0.01255 s): taking 2 substeps"), std::string::npos) << a.output;
  const Result off = run("--headless --quiet --steps 3 --dt 0.012 --substeps off");
  EXPECT_EQ(off.code, 2) << off.output;
  EXPECT_NE(off.output.find("above the safe step"), std::string::npos) << off.output;
  EXPECT_NE(off.output.find("--substeps 2"), std::string::npos) << off.output;
  EXPECT_EQ(lines(off.output), 1) << off.output;
  // below the safe step: no note, and off runs
  const Result below = run("--headless --steps 3 --dt 0.011 --substeps off");
  EXPECT_EQ(below.code, 0) << below.output;
  EXPECT_EQ(below.output.find("note"), std::string::npos) << below.output;
}

// Steps are the user's steps of dt everywhere: the console, the report and the OBJ file
// numbers (not substeps: "6 steps", drape_000600.obj at t = 3 s); the substeps are reported
// separately.
TEST(Cli, StepsCountStepsOfDtWhenSubstepping) {
  const fs::path d = fresh_dir("substep_counts");
  const Result r = run("--headless --steps 20 --dt 0.012 --export-every 5 --export-obj " + q(d / "frames") +
                       " --report " + q(d / "r.json"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("dice: 20 steps of 0.012 s (2 substeps of 0.006 s each)"), std::string::npos) << r.output;
  const auto j = read_json(d / "r.json");
  EXPECT_EQ(j["steps"], 20);
  EXPECT_EQ(j["substeps"], 2);
  EXPECT_DOUBLE_EQ(j["substep_dt"].get<double>(), 0.006);
  EXPECT_NEAR(j["seconds_simulated"].get<double>(), 20 * 0.012, 1e-9);
  EXPECT_EQ(entries(d / "frames"), 5);  // steps 0, 5, 10, 15, 20
  for (const char* f : {"dice_000000.obj", "dice_000005.obj", "dice_000020.obj"})
    EXPECT_TRUE(fs::exists(d / "frames" / f)) << f;
  EXPECT_FALSE(fs::exists(d / "frames" / "dice_000040.obj"));
  EXPECT_NE(slurp(d / "frames" / "dice_000020.obj").find("t = 0.24 s, step 20 of dt 0.012 s"), std::string::npos)
      << slurp(d / "frames" / "dice_000020.obj").substr(0, 100);
}

TEST(Cli, BlowUpReportsFiniteFalseAndExitsOne) {
  const fs::path d = fresh_dir("blowup");
  // --substeps 1: take the step as asked (the default, auto, would substep under the limit)
  const Result r = run("--headless --quiet --dt 0.5 --substeps 1 --seconds 1000 --report '" + (d / "r.json").string() + "'");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("non-finite at step"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("stability"), std::string::npos) << r.output;
  const auto j = read_json(d / "r.json");
  EXPECT_EQ(j["finite"], false);
  EXPECT_LT(j["steps"].get<int>(), 2000);  // stopped at once, not after 1000 s
  EXPECT_GT(j["stable_dt_estimate"].get<double>(), 0.0);
  // the report agrees with itself: the time of the steps that completed (not the failed one),
  // and no box around a non-finite state
  EXPECT_DOUBLE_EQ(j["seconds_simulated"].get<double>(), j["steps"].get<int>() * 0.5);
  EXPECT_EQ(j["failed_step"].get<int>(), j["steps"].get<int>() + 1);
  EXPECT_TRUE(j["cloth_min"][1].is_null()) << j["cloth_min"];
  // the start-up warning that it would blow up is shown under --quiet and listed
  EXPECT_NE(r.output.find("warning: "), std::string::npos) << r.output;
  ASSERT_FALSE(j["warnings"].empty());
  EXPECT_NE(j["warnings"][0].get<std::string>().find("blow up"), std::string::npos) << j["warnings"];
  // a step within the limits whose forces overflow is not blamed on the step
  const Result big = run("--headless --quiet --gravity 1e307 --steps 3000");  // overflows at t = 18 s
  EXPECT_EQ(big.code, 1) << big.output;
  EXPECT_EQ(big.output.find("is above the stability limit"), std::string::npos) << big.output;
  EXPECT_NE(big.output.find("a force too large for double precision"), std::string::npos) << big.output;
}

// An epsilon as large as the scene puts every mass deep in the floor's band: warned (the
// cloth flies 100 m up), also under --quiet, and listed in the report.
TEST(Cli, MassesThrownOutOfTheBandAreWarned) {
  const fs::path d = fresh_dir("band_launch");
  const Result r = run("--headless --quiet --steps 2 --epsilon 3 --report " + q(d / "r.json"));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("start within the contact band of collider"), std::string::npos) << r.output;
  const auto j = read_json(d / "r.json");
  ASSERT_EQ(j["warnings"].size(), 1u) << j["warnings"];
  EXPECT_NE(j["warnings"][0].get<std::string>().find("use a smaller --epsilon"), std::string::npos);
  EXPECT_EQ(run("--headless --quiet --steps 2").output, "");  // the scene as baked: no warning
}

// The viewer's options without a viewer, and --fps without --frames, would do nothing: bad
// input, as --export-every without --export-obj is. A screenshot is a PNG whatever its name
// says (a.jpg would hold PNG bytes): the name must say .png.
TEST(Cli, ViewerOptionsThatWouldDoNothingAreBadInput) {
  const fs::path d = fresh_dir("viewer_options");
  for (const char* args : {"--headless --fps 10", "--headless --width 100", "--headless --height 100",
                           "--headless --paused", "--headless --no-vsync", "--headless --lookahead 1",
                           "--fps 10 --seconds 1", "--lookahead -1", "--lookahead 61", "--lookahead x",
                           "--lookahead nan", "--lookahead 0.1", "--lookahead 1e-300", "--lookahead 1e-400"}) {
    const Result r = run(std::string("--quiet --steps 5 --report ") + q(d / "r.json") + " " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
  }
  // --frames records up to --seconds (or --steps): without either it is an option mistake, found
  // before the model is built (not exit 1 after the stability analysis)
  const Result frames = run("--frames " + q(d / "f"));
  EXPECT_EQ(frames.code, 2) << frames.output;
  EXPECT_NE(frames.output.find("error: --frames needs --seconds T"), std::string::npos) << frames.output;
  EXPECT_EQ(frames.output.find("stability"), std::string::npos) << frames.output;
  // the look-ahead paces the window only: with a screenshot or frames it would do nothing
  for (const std::string& out : {"--screenshot " + q(d / "a.png"), "--frames " + q(d / "f")}) {
    const Result la = run("--seconds 0.1 --lookahead 1 " + out);
    EXPECT_EQ(la.code, 2) << la.output;
    EXPECT_NE(la.output.find("--lookahead paces the window"), std::string::npos) << la.output;
  }
  const Result jpg = run("--seconds 0.1 --screenshot " + q(d / "a.jpg"));
  EXPECT_EQ(jpg.code, 2) << jpg.output;
  EXPECT_NE(jpg.output.find("name it *.png"), std::string::npos) << jpg.output;
  EXPECT_TRUE(fs::is_empty(d));
}

// The report's self_crossings (at the end) is always there, an integer; --check-crossings adds
// max_self_crossings, an integer, and max_self_crossings_t, the time of a counted frame (every
// 0.05 s) within the run, which the closing line then says too.
TEST(Cli, SelfCrossingsReachTheReport) {
  const fs::path d = fresh_dir("self_crossings");
  const Result plain = run("--headless --steps 12 --report " + q(d / "plain.json"));
  ASSERT_EQ(plain.code, 0) << plain.output;
  const auto p = read_json(d / "plain.json");
  ASSERT_TRUE(p.contains("self_crossings"));
  EXPECT_TRUE(p["self_crossings"].is_number_unsigned()) << p["self_crossings"];
  EXPECT_FALSE(p.contains("max_self_crossings"));
  EXPECT_FALSE(p.contains("max_self_crossings_t"));

  const Result checked = run("--headless --steps 12 --check-crossings --report " + q(d / "checked.json"));
  ASSERT_EQ(checked.code, 0) << checked.output;
  const auto j = read_json(d / "checked.json");
  ASSERT_TRUE(j.contains("max_self_crossings")) << j.dump();
  EXPECT_TRUE(j["self_crossings"].is_number_unsigned()) << j["self_crossings"];
  EXPECT_TRUE(j["max_self_crossings"].is_number_unsigned()) << j["max_self_crossings"];
  EXPECT_EQ(j["self_crossings"], p["self_crossings"]);  // (counting changes nothing)
  const double t = j["max_self_crossings_t"].get<double>(), dt = j["dt"].get<double>();
  EXPECT_GE(t, 0.0);
  EXPECT_LE(t, j["seconds_simulated"].get<double>());
  EXPECT_NEAR(t / dt, std::round(t / dt), 1e-6);  // the time of a step
  EXPECT_NE(checked.output.find("self-crossings " + std::to_string(j["self_crossings"].get<long>()) + " (most "),
            std::string::npos)
      << checked.output;
  // without the flag the closing line is as it was
  EXPECT_EQ(plain.output.find("self-crossings"), std::string::npos) << plain.output;
}

#ifdef CLOTHSIM_HEAP_EXE
// --self-collision decides whether a strip falling into a heap passes through itself: off, the
// frames every 0.05 s show crossings; on (the default), none; the report and --help say which.
TEST(Cli, SelfCollisionSwitchDecidesWhetherTheHeapPassesThroughItself) {
  const fs::path d = fresh_dir("self_collision");
  for (const char* state : {"off", "on"}) {
    const std::string report = q(d / (std::string(state) + ".json"));
    const std::string flag = std::string(state) == "off" ? " --self-collision off" : "";
    const Result r = run_program(CLOTHSIM_HEAP_EXE, "--headless --quiet --seconds 1.2 --check-crossings" + flag +
                                                        " --report " + report);
    ASSERT_EQ(r.code, 0) << r.output;
    const auto j = read_json(d / (std::string(state) + ".json"));
    EXPECT_EQ(j["options"]["self_collision"], state);
    if (std::string(state) == "off") {
      EXPECT_GT(j["max_self_crossings"].get<long>(), 0) << "the heap never folded through itself";
      EXPECT_TRUE(j["self_detections"].is_null() && j["self_list_builds"].is_null() &&
                  j["self_pin_overruns"].is_null() && j["self_split_steps"].is_null())
          << j.dump();
    } else {
      EXPECT_EQ(j["max_self_crossings"].get<long>(), 0);
      // the stage ran: detections, and at least one list build among them but fewer than detections
      EXPECT_GT(j["self_detections"].get<long>(), 0);
      EXPECT_GE(j["self_list_builds"].get<long>(), 1);
      EXPECT_LT(j["self_list_builds"].get<long>(), j["self_detections"].get<long>());
      EXPECT_EQ(j["self_pin_overruns"].get<long>(), 0) << "no pins";
      EXPECT_EQ(j["self_split_steps"].get<long>(), 0) << "no pins";
    }
  }
  const Result help = run_program(CLOTHSIM_HEAP_EXE, "--help");
  EXPECT_NE(help.output.find("--self-collision"), std::string::npos) << help.output;
}
#endif

#ifdef CLOTHSIM_TWIST_EXE
// The twist's pins turned 60 times as fast move further in a step than 8 parts of it would
// cover: the run says so (a warning, in the report's warnings too) and counts them. Turned at
// 8 rad/s over 0.5 s they would pass some gaps in one step: those steps run in parts, and no
// pin passes a gap. At the scene's own rate its first 0.1 s needs neither.
TEST(Cli, PinsTurningPastTheClothsGapsAreWarned) {
  const fs::path d = fresh_dir("pin_overruns");
  struct Case {
    const char *spin, *seconds;
    bool warned, split;
  };
  for (const Case c : {Case{"62.8", "0.1", true, false}, Case{"8", "0.5", false, true},
                       Case{"1.0471975511965976", "0.1", false, false}}) {
    const fs::path report = d / (std::string(c.spin) + ".json");
    const Result r = run_program(CLOTHSIM_TWIST_EXE, "--headless --quiet --seconds " + std::string(c.seconds) +
                                                         " --pin-spin " + c.spin + " --report " + q(report));
    ASSERT_EQ(r.code, 0) << r.output;
    const auto j = read_json(report);
    const std::string warning = "warning: a turning pin came nearer to the cloth than its move over one step";
    EXPECT_EQ(r.output.find(warning) != std::string::npos, c.warned) << c.spin << r.output;
    EXPECT_EQ(j["self_pin_overruns"].get<long>() > 0, c.warned) << j.dump();
    EXPECT_EQ(j["warnings"].dump().find(warning) != std::string::npos, c.warned) << j.dump();
    if (!c.warned) {
      EXPECT_EQ(j["self_split_steps"].get<long>() > 0, c.split) << c.spin << j.dump();
    }
  }
}
#endif


}  // namespace

#ifdef CLOTHSIM_HANGING_EXE
// The report counts the pinned masses, so a user can see that a `<cloth>_pins` helper's pins
// landed (the hanging cloth: two corners, from its Cloth_pins helper).
TEST(Cli, ReportCountsThePinnedMasses) {
  const fs::path d = fresh_dir("report_pins");
  const Result r = run_program(CLOTHSIM_HANGING_EXE, "--headless --quiet --steps 2 --report " + q(d / "r.json"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = read_json(d / "r.json");
  EXPECT_EQ(j["scene"], "hanging");
  EXPECT_EQ(j["pinned_masses"], 2);
}

// Friction on a scene without colliders (the hanging cloth): refused, naming the option and
// the scene, exit 2, nothing written.
TEST(Cli, FrictionWithoutCollidersIsRefused) {
  const fs::path d = fresh_dir("friction_alone");
  const Result r =
      run_program(CLOTHSIM_HANGING_EXE, "--headless --quiet --steps 2 --friction 0.3 --report " + q(d / "r.json"));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--friction: scene 'hanging' has no colliders"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::is_empty(d));
}
#endif
