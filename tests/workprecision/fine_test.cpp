// clothsim_wp --fine --fast: the fine, stiff case (skirt_hires in cotton) writes one row per
// run for every integrator, with finite numbers where the run stayed finite, and the default
// method at its planned step keeps the strain at or below 10 %.
#include "program.hpp"

#include <cmath>
#include <map>
#include <sstream>
#include <vector>

namespace {

using namespace clothsim::testing;

struct Row {
  std::string method;
  bool planned = false, finite = false;
  double h = 0.0, error = 0.0, cpu_per_second = 0.0, max_strain = 0.0;
};

std::vector<Row> read_rows(const fs::path& csv) {
  std::istringstream in(slurp(csv));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "method,substeps,h,planned,finite,error,cpu_per_second,max_strain,steps");
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) f.push_back(cell);
    EXPECT_EQ(f.size(), 9u) << line;
    if (f.size() != 9u) continue;
    rows.push_back({f[0], f[3] == "1", f[4] == "1", std::stod(f[2]), std::stod(f[5]), std::stod(f[6]),
                    std::stod(f[7])});
  }
  return rows;
}

TEST(WorkPrecisionFine, FastRunWritesEveryMethodAndXpbdKeepsItsStrain) {
  const fs::path d = fresh_dir("wp_fine");
  const Result r = run_program(CLOTHSIM_WP_EXE, "--fine --fast --out " + q(d));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("target: xpbd to 1 %"), std::string::npos) << r.output;
  const std::vector<Row> rows = read_rows(d / "skirt_hires.csv");
  std::map<std::string, int> per_method;
  for (const Row& row : rows) {
    ++per_method[row.method];
    EXPECT_TRUE(std::isfinite(row.h) && row.h > 0.0) << row.method;
    EXPECT_TRUE(std::isfinite(row.cpu_per_second) && row.cpu_per_second > 0.0) << row.method;
    if (row.finite) {
      EXPECT_TRUE(std::isfinite(row.error) && std::isfinite(row.max_strain)) << row.method;
    }
  }
  for (const char* m : {"symplectic-euler", "explicit-euler", "verlet", "midpoint", "rk4", "implicit-euler",
                        "fast-mass-spring", "xpbd"})
    EXPECT_GE(per_method[m], 1) << m;
  int planned = 0;
  for (const Row& row : rows)
    if (row.planned && (row.method == "xpbd" || row.method == "symplectic-euler")) {
      ++planned;
      EXPECT_TRUE(row.finite) << row.method;
      EXPECT_LE(row.max_strain, 0.10) << row.method;
      EXPECT_LT(row.error, 0.01) << row.method;
    }
  EXPECT_EQ(planned, 2);
  // the planned step of xpbd is the guard's: far above symplectic Euler's
  double h_xpbd = 0.0, h_se = 0.0;
  for (const Row& row : rows)
    if (row.planned) (row.method == "xpbd" ? h_xpbd : h_se) = row.h;
  EXPECT_GT(h_xpbd, 10.0 * h_se);
}

// --fine runs its own study: the options of the sweep over the baked scenes are refused.
TEST(WorkPrecisionFine, SweepOptionsAreRefused) {
  for (const std::string args : {"--fine --scene hanging", "--fine --horizon 1", "--fine --model-cost"}) {
    const Result r = run_program(CLOTHSIM_WP_EXE, args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1) << args << ": " << r.output;
  }
}

}  // namespace
