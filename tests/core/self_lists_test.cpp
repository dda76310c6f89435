// The self-contact candidate lists against brute force: after every update they hold each
// pair of elements nearer than `far` (a vertex and a triangle it is not a corner of, two
// edges without a common mass), and the detection measures each one that is; a cloth that
// moves as one keeps its lists; when they are built changes no bit of a run. White-box: the
// stage's private header.
#include "self_contact.hpp"

#include <clothsim/model_builder.hpp>
#include <clothsim/self_crossings.hpp>
#include <clothsim/step.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <tuple>
#include <vector>

namespace clothsim {
namespace {

using Key = std::array<std::uint32_t, 4>;

constexpr int kSide = 13;

// Sheets of side x side masses: sheet k's positions are place(u, v, k), u, v in [0, 1].
template <class Place>
Model sheets_model(int sheets, Place place, int side = kSide, const Options& o = {}) {
  ModelBuilder b(o, "sheets");
  auto id = [side](int i, int j) { return static_cast<std::uint32_t>(j * side + i); };
  for (int k = 0; k < sheets; ++k) {
    Eigen::Matrix3Xd x(3, side * side);
    std::vector<std::uint32_t> tri;
    std::vector<SpringSpec> springs;
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) x.col(id(i, j)) = place(double(i) / (side - 1), double(j) / (side - 1), k);
    for (int j = 0; j + 1 < side; ++j)
      for (int i = 0; i + 1 < side; ++i) {
        tri.insert(tri.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        springs.push_back({id(i, j), id(i + 1, j), 0});
        springs.push_back({id(i, j), id(i, j + 1), 0});
      }
    b.add_cloth(x, springs, {}, tri);
  }
  return b.build();
}

// Positions place(u, v, k) of every mass of sheets_model's sheets.
template <class Place>
void place_sheets(Eigen::Matrix3Xd& x, int sheets, Place place, int side = kSide) {
  for (int k = 0; k < sheets; ++k)
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i)
        x.col((k * side + j) * side + i) = place(double(i) / (side - 1), double(j) / (side - 1), k);
}

// A pair's key: VT as (v, triangle's corners sorted); EE as the two edges sorted, each sorted.
Key key(const std::uint32_t m[4], bool vt) {
  Key k{m[0], m[1], m[2], m[3]};
  if (vt) {
    std::sort(k.begin() + 1, k.end());
  } else {
    std::sort(k.begin(), k.begin() + 2), std::sort(k.begin() + 2, k.end());
    if (std::pair(k[2], k[3]) < std::pair(k[0], k[1])) std::swap(k[0], k[2]), std::swap(k[1], k[3]);
  }
  return k;
}

// Every pair nearer than `far` at x, by brute force, is a candidate and is measured.
void expect_lists_hold(const Model& m, const Eigen::Matrix3Xd& x, const detail::SelfScratch& sc, int round) {
  std::set<Key> listed, measured;
  for (std::uint32_t j = 0; j < sc.cand_vt.size() + sc.cand_ee.size(); ++j)
    listed.insert(key(detail::candidate(sc, j).mass, j < sc.cand_vt.size()));
  for (std::uint32_t j : sc.active) measured.insert(key(detail::candidate(sc, j).mass, j < sc.cand_vt.size()));
  double coef[4];
  int missing = 0, unmeasured = 0;
  auto check = [&](const std::uint32_t q[4], bool vt) {
    if (detail::pair_gap(x, q, vt, coef).norm() >= sc.far) return;
    missing += !listed.count(key(q, vt));
    unmeasured += !measured.count(key(q, vt));
  };
  for (std::uint32_t v = 0; v < m.mass_count(); ++v)
    for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
      const std::uint32_t q[4] = {v, m.triangles[t], m.triangles[t + 1], m.triangles[t + 2]};
      if (q[1] != v && q[2] != v && q[3] != v) check(q, true);
    }
  for (std::size_t e = 0; e < sc.edges.size(); e += 2)
    for (std::size_t f = e + 2; f < sc.edges.size(); f += 2) {
      const std::uint32_t q[4] = {sc.edges[e], sc.edges[e + 1], sc.edges[f], sc.edges[f + 1]};
      if (q[2] != q[0] && q[2] != q[1] && q[3] != q[0] && q[3] != q[1]) check(q, false);
    }
  EXPECT_EQ(missing, 0) << "pairs within far not listed, round " << round;
  EXPECT_EQ(unmeasured, 0) << "pairs within far not measured, round " << round;
}

// What a run of run_two_sheets saw: the lists' builds, the most candidates measured at once,
// the most pairs listed late at once.
struct ListsRun {
  std::uint64_t builds = 0;
  std::size_t most_active = 0, most_late = 0;
};

// Two sheets at place(u, v, k, t) for t from 0 to 1 in `rounds` steps: the lists brought up to
// date at each, and checked against brute force at every `every`-th and the last.
template <class Place>
ListsRun run_two_sheets(Place place, int rounds, int every = 1) {
  const Model m = sheets_model(2, [&](double a, double b, int k) { return place(a, b, k, 0.0); });
  auto sc = detail::make_self_scratch(m);
  EXPECT_TRUE(sc);
  if (!sc) return {};
  const Workspace ws = make_workspace(m);
  Eigen::Matrix3Xd x = m.x0;
  ListsRun run;
  for (int r = 0; r <= rounds; ++r) {
    place_sheets(x, 2, [&](double a, double b, int k) { return place(a, b, k, double(r) / rounds); });
    detail::find_candidates(m, x, *sc, ws);
    if (r % every == 0 || r == rounds) expect_lists_hold(m, x, *sc, r);
    run.most_active = std::max(run.most_active, sc->active.size());
    run.most_late = std::max(run.most_late, sc->cand_vt.size() + sc->cand_ee.size() - sc->built_vt - sc->built_ee);
  }
  run.builds = sc->builds;
  return run;
}

// A rippled sheet slides across another and settles onto it: pairs come near and go by
// (brute force every fifth round and the last).
TEST(SelfLists, HoldEveryNearPairAsOneClothSlidesOverAnother) {
  constexpr int kRounds = 200;
  const ListsRun run = run_two_sheets(
      [](double a, double b, int k, double t) -> Eigen::Vector3d {
        if (k == 0) return {a, 0.0, b};
        const double ripple = 0.006 * std::sin(9.0 * a + 20.0 * t);
        return {a + 0.4 * t, 0.05 * (1.0 - t) + 0.008 + ripple, b + 0.1 * t};
      },
      kRounds, 5);
  EXPECT_GT(run.most_active, 1000u) << "many pairs come within far";
  EXPECT_LT(run.builds, kRounds / 4u) << "the lists hold over several rounds";
  EXPECT_GT(run.builds, 2u) << "the slide brings new pairs near";
}

// A sheet that stretches and turns in its plane, above another that lies still: the pairs
// whose masses move apart by more than the lists allow are listed late (those of one layer
// never come near; those between the layers may), and the lists hold over several rounds.
TEST(SelfLists, ASheetThatStretchesAndTurnsListsPairsLate) {
  constexpr int kRounds = 100;
  const ListsRun run = run_two_sheets(
      [](double a, double b, int k, double t) -> Eigen::Vector3d {
        if (k == 0) return {a, 0.0, b};
        const double turn = 0.6 * t, grow = 1.0 + 0.3 * t, c = std::cos(turn), s = std::sin(turn);
        const double u = grow * (a - 0.5), w = grow * (b - 0.5);
        return {0.5 + c * u - s * w, 0.02, 0.5 + s * u + c * w};
      },
      kRounds, 5);
  EXPECT_GT(run.most_late, 0u) << "pairs are found late";
  EXPECT_LT(run.builds, kRounds / 4u) << "the lists hold over several rounds";
}

// The lists' check runs in tasks on the threads: on two threads it finds the same pairs late,
// in the same order, leaves the same slack and builds the lists as often as on one.
TEST(SelfLists, TwoThreadsListTheSamePairsAsOne) {
  constexpr int kRounds = 160, kLarge = 33;  // (2 x 33^2 masses: enough for the check to split)
  const auto place = [](double a, double b, int k, double t) -> Eigen::Vector3d {
    if (k == 0) return {a, 0.0, b};
    const double turn = 0.6 * t, grow = 1.0 + 0.3 * t, c = std::cos(turn), s = std::sin(turn);
    const double u = grow * (a - 0.5), w = grow * (b - 0.5);
    return {0.5 + c * u - s * w, 0.01, 0.5 + s * u + c * w};
  };
  const Model m = sheets_model(2, [&](double a, double b, int k) { return place(a, b, k, 0.0); }, kLarge);
  auto one = detail::make_self_scratch(m), two = detail::make_self_scratch(m);
  ASSERT_TRUE(one && two);
  const Workspace w1 = make_workspace(m);
  Workspace w2 = make_workspace(m);
  w2.threads = 2;
  const auto same = [](const std::vector<detail::SelfPair>& p, const std::vector<detail::SelfPair>& q) {
    return std::equal(p.begin(), p.end(), q.begin(), q.end(), [](const auto& a, const auto& b) {
      return std::equal(a.mass, a.mass + 4, b.mass) && a.built == b.built;
    });
  };
  Eigen::Matrix3Xd x = m.x0;
  std::size_t most_late = 0;
  for (int r = 0; r <= kRounds; ++r) {
    place_sheets(x, 2, [&](double a, double b, int k) { return place(a, b, k, double(r) / kRounds); }, kLarge);
    detail::find_candidates(m, x, *one, w1);
    detail::find_candidates(m, x, *two, w2);
    ASSERT_EQ(one->builds, two->builds) << "round " << r;
    ASSERT_TRUE(same(one->cand_vt, two->cand_vt) && same(one->cand_ee, two->cand_ee)) << "round " << r;
    ASSERT_EQ(one->active, two->active) << "round " << r;
    ASSERT_EQ(one->slack, two->slack) << "round " << r;
    most_late = std::max(most_late, one->cand_vt.size() + one->cand_ee.size() - one->built_vt - one->built_ee);
  }
  EXPECT_GT(most_late, 0u) << "the checks find pairs late";
  EXPECT_LT(one->builds, kRounds / 2u) << "the lists hold over several rounds";
}

// A sheet slides in from beside another, just above its level: the pairs between them come
// near between the lists' builds, listed late as they come.
TEST(SelfLists, PairsComingNearAreListedLate) {
  const ListsRun run = run_two_sheets(
      [](double a, double b, int k, double t) -> Eigen::Vector3d {
        return k == 0 ? Eigen::Vector3d(a, 0.0, b) : Eigen::Vector3d(a + 1.3 - 0.8 * t, 0.01, b);
      },
      100, 5);
  EXPECT_GT(run.most_late, 100u) << "pairs are found late";
  EXPECT_LT(run.builds, 20u) << "the lists are built again at most every fifth round";
}

// When the lists are built changes no bit of a run without turning pins: two sheets thrown
// into each other, stepped with the lists kept as usual and with them built at every
// detection, end at the same positions and velocities.
TEST(SelfLists, WhenTheListsAreBuiltChangesNoBit) {
  Options o;
  o.gravity_y = 0.0;
  const double c = std::cos(0.6), s = std::sin(0.6);
  const Model m = sheets_model(
      2,
      [&](double a, double b, int k) -> Eigen::Vector3d {
        if (k == 0) return {a, 0.0, b};
        return {0.5 + c * (a - 0.5) - s * (b - 0.5), 0.03, 0.5 + s * (a - 0.5) + c * (b - 0.5)};
      },
      kSide, o);
  const auto run = [&](bool build_always) {
    State st = make_state(m);
    const Eigen::Index half = kSide * kSide;
    st.v.row(1).head(half).setConstant(1.0);
    st.v.row(1).tail(half).setConstant(-1.0);
    st.v.row(0).tail(half).setConstant(0.5);
    Workspace ws = make_workspace(m);
    ws.substeps = 20;
    for (int k = 0; k < 600; ++k) {
      if (build_always) ws.self->xl.resize(3, 0);  // (the next detection builds the lists)
      step(m, st, ws);
    }
    return std::tuple(st, self_contact_counts(ws).value_or(SelfContactCounts{}));
  };
  const auto [usual, usual_counts] = run(false);
  const auto [always, always_counts] = run(true);
  EXPECT_GT(usual_counts.detections, 20u) << "the sheets meet and press";
  EXPECT_GT(always_counts.list_builds, 2 * usual_counts.list_builds);
  EXPECT_TRUE((usual.x.array() == always.x.array()).all()) << "positions differ";
  EXPECT_TRUE((usual.v.array() == always.v.array()).all()) << "velocities differ";
  EXPECT_EQ(count_self_crossings(m, usual.x).crossings, 0u);
  const Eigen::Index half = kSide * kSide;
  EXPECT_GT(usual.x.row(1).tail(half).mean(), usual.x.row(1).head(half).mean()) << "the upper sheet stays above";
}

// A cloth that moves as one, however far, keeps the lists it started with.
TEST(SelfLists, ACommonMoveKeepsTheLists) {
  const Model m = sheets_model(1, [](double a, double b, int) { return Eigen::Vector3d(a, 0.1 * std::sin(5.0 * a), b); });
  auto sc = detail::make_self_scratch(m);
  const Workspace ws = make_workspace(m);
  Eigen::Matrix3Xd x = m.x0;
  for (int r = 0; r < 50; ++r) {
    x.colwise() += Eigen::Vector3d(0.03, -0.2, 0.01);
    detail::find_candidates(m, x, *sc, ws);
    expect_lists_hold(m, x, *sc, r);
  }
  EXPECT_EQ(sc->builds, 1u);
}

}  // namespace
}  // namespace clothsim
