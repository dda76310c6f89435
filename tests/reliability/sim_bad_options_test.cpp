// The simulator from the outside: bad option values are refused with one clear line naming the
// option (exit 2, nothing written), and a run that blows up stops with a report (exit 1,
// "finite": false) instead of crashing or writing NaNs silently.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "process.hpp"

namespace fs = std::filesystem;
using reliability::Result;
using reliability::TempDir;

namespace {

const std::string kExe = CLOTHSIM_EXE;

TEST(SimBadOptions, RefusedWithExitTwoAndOneLine) {
  struct Bad {
    std::vector<std::string> args;
    std::string names;  // what the message must mention
  };
  const std::vector<Bad> bad = {
      {{"--dt", "0"}, "dt"},          {{"--dt", "-0.01"}, "dt"},      {{"--dt", "nan"}, "dt"},
      {{"--dt", "inf"}, "dt"},        {{"--dt", "abc"}, "dt"},        {{"--dt", "1e999"}, "dt"},
      {{"--mass", "0"}, "mass"},      {{"--mass", "-1"}, "mass"},     {{"--mass", "nan"}, "mass"},
      {{"--k-struct", "-400"}, "k"},  {{"--k-struct", "inf"}, "k"},   {{"--k-bend", "nan"}, "k"},
      {{"--damping", "-0.1"}, "damping"}, {{"--damping", "nan"}, "damping"},
      {{"--gravity", "nan"}, "gravity"},  {{"--epsilon", "-0.1"}, "epsilon"},
      {{"--epsilon", "nan"}, "epsilon"},  {{"--k-rep", "-1"}, "k"},
      {{"--seconds", "nan"}, "seconds"},
      {{"--seconds", "-1"}, "seconds"},   {{"--steps", "0"}, "steps"},
      {{"--steps", "-3"}, "steps"},       {{"--export-every", "0"}, "export-every"},
      {{"--no-such-option"}, "no-such-option"},
      {{"--density", "0"}, "density"},    {{"--density", "-0.2"}, "density"},
      {{"--stretch", "0"}, "stretch"},    {{"--stretch", "-5"}, "stretch"},
      {{"--bend", "-1"}, "bend"},         {{"--material", "wool"}, "cotton, silk, denim, leather, rubber"},
      {{"--friction", "-0.1"}, "friction"}, {{"--static-friction", "-1"}, "static-friction"},
      {{"--friction", "0.5", "--static-friction", "0.2"}, "static_friction"},
      {{"--mass", "0.01", "--density", "0.1"}, "--density"},
      {{"--steps", "10", "--seconds", "1"}, "seconds"},
      {{"--pin-spin", "nan"}, "pin-spin"}, {{"--pin-spin", "inf"}, "pin-spin"},
  };
  for (const Bad& b : bad) {
    TempDir work("simbad");
    std::vector<std::string> argv = {kExe, "--headless", "--quiet"};
    argv.insert(argv.end(), b.args.begin(), b.args.end());
    const fs::path report = work.path / "report.json";
    argv.insert(argv.end(), {"--report", report.string()});
    std::string joined;
    for (const auto& a : b.args) joined += a + " ";
    SCOPED_TRACE(joined);
    const Result r = reliability::run(argv, {}, 20.0);
    EXPECT_FALSE(r.timed_out) << "still running after 20 s";
    EXPECT_EQ(r.signal, 0);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(reliability::count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(b.names), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(report)) << "a refused run wrote a report";
  }
}

TEST(SimBadOptions, ReportIntoAMissingFolderIsRefused) {
  TempDir work("simrep");
  const Result r = reliability::run(
      {kExe, "--headless", "--quiet", "--steps", "2", "--report", (work.path / "no" / "such" / "r.json").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(reliability::count_lines(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(work.path / "no"));
}

// Far beyond the stable step (symplectic Euler blows up past h*omega = 2): the state
// overflows to inf/NaN within a few steps. The run must stop there with a report.
TEST(SimExplosion, StopsWithAReportNotACrash) {
  TempDir work("boom");
  const fs::path report = work.path / "report.json";
  // --substeps 1: take the step as asked (the default, auto, would substep under the limit)
  const Result r = reliability::run({kExe, "--headless", "--quiet", "--dt", "0.5", "--k-struct", "1e6",
                                     "--substeps", "1", "--steps", "2000", "--report", report.string()});
  EXPECT_EQ(r.signal, 0) << r.err;
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("non-finite"), std::string::npos) << r.err;
  ASSERT_TRUE(fs::exists(report));
  const auto j = nlohmann::json::parse(reliability::read_file(report));  // throws on NaN text
  ASSERT_TRUE(j.contains("finite"));
  EXPECT_FALSE(j["finite"].get<bool>());
  ASSERT_TRUE(j.contains("failed_step"));
  EXPECT_GT(j["failed_step"].get<long long>(), 0);
  EXPECT_LT(j["failed_step"].get<long long>(), 2000);
}

// The same settings at a stable step size run through: the check above is about the blow-up.
TEST(SimExplosion, StableStepRunsThrough) {
  TempDir work("calm");
  const fs::path report = work.path / "report.json";
  const Result r = reliability::run({kExe, "--headless", "--quiet", "--steps", "20", "--report", report.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(reliability::read_file(report));
  EXPECT_TRUE(j["finite"].get<bool>());
}

}  // namespace
