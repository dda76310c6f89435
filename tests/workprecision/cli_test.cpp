// clothsim_wp's command line: bad studies and output paths are refused before the study runs.
#include "program.hpp"

namespace {

using namespace clothsim::testing;

// clothsim_wp (the work-precision tool) writes <out>/<scene>.csv and .svg by the same rule:
// the paths are checked before the study (exit 2), a device is written through, never replaced.
// Values that would run a nonsense study (a NaN or overflowing stiffness, an integrator given
// twice, whose fitted order would be garbage), a scene the tool does not have
// (named with the ones it has), and study options with --model-cost: bad input, one line.
TEST(WorkPrecision, BadStudiesAreRefusedBeforeTheyRun) {
  const fs::path d = fresh_dir("wp_bad");
  const std::string out = " --fast --scene hanging --out " + q(d / "out");
  for (const std::string& args : {"--stiffness-scale nan" + out, "--stiffness-scale 1e306" + out,
                                  "--horizon 0" + out, "--integrators rk4,rk4" + out,
                                  std::string("--scene hanging --scene hanging --fast"), std::string("--scene dice"),
                                  "--model-cost --scene hanging --out " + q(d / "out")}) {
    const Result r = run_program(CLOTHSIM_WP_EXE, args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1) << args << ": " << r.output;
  }
  EXPECT_NE(run_program(CLOTHSIM_WP_EXE, "--scene dice").output.find("(hanging, skirt)"), std::string::npos);
  EXPECT_FALSE(fs::exists(d / "out"));
  EXPECT_EQ(run_program(CLOTHSIM_WP_EXE, "--version").code, 0);
}

TEST(WorkPrecision, OutputPathsAreCheckedBeforeTheStudy) {
  const fs::path d = fresh_dir("wp_paths");
  { std::ofstream(d / "afile") << "x\n"; }
  fs::create_directories(d / "out" / "hanging.csv");
  const std::string study = "--fast --scene hanging --integrators symplectic-euler --out ";
  const Result file = run_program(CLOTHSIM_WP_EXE, study + q(d / "afile"));
  EXPECT_EQ(file.code, 2) << file.output;
  EXPECT_NE(file.output.find("afile' is not a directory"), std::string::npos) << file.output;
  EXPECT_EQ(lines(file.output), 1) << file.output;
  const Result taken = run_program(CLOTHSIM_WP_EXE, study + q(d / "out"));
  EXPECT_EQ(taken.code, 2) << taken.output;
  EXPECT_NE(taken.output.find("hanging.csv' is a directory"), std::string::npos) << taken.output;
  EXPECT_EQ(lines(taken.output), 1) << taken.output;
  EXPECT_EQ(entries(d / "out"), 1);
  const Result bogus = run_program(CLOTHSIM_WP_EXE, "--bogus");
  EXPECT_EQ(bogus.code, 2) << bogus.output;
}

TEST(WorkPrecision, OutputsIntoDevicesAreWrittenThrough) {
  const fs::path d = fresh_dir("wp_devices");
  if (!make_char_device(d / "hanging.csv", 3) || !make_char_device(d / "hanging.svg", 7))
    GTEST_SKIP() << "mknod not permitted: " << std::strerror(errno);
  const Result r = run_program(CLOTHSIM_WP_EXE, "--fast --scene hanging --integrators symplectic-euler --out " + q(d));
  EXPECT_EQ(r.code, 1) << r.output;  // the .svg goes to a full device
  EXPECT_NE(r.output.find("hanging.svg': No space left"), std::string::npos) << r.output;
  EXPECT_TRUE(is_char_device(d / "hanging.csv")) << "the device was replaced";
  EXPECT_TRUE(is_char_device(d / "hanging.svg")) << "the device was replaced";
  EXPECT_EQ(entries(d), 2) << "a temporary file was left";
}

}  // namespace
