// The gathered, threaded force loops give exactly the scatter loop's results.
#include "perf_scenes.hpp"

#include <clothsim/integrators.hpp>
#include <clothsim/model_builder.hpp>
#include <clothsim/thread_choice.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

namespace clothsim {
namespace {

// A triangulated n x n cloth with its positions jittered (so no spring is at rest).
Model jittered_grid(int n, std::shared_ptr<const ColliderSet> colliders = nullptr) {
  Model m = perf::grid_model(n, std::move(colliders));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (Eigen::Index i = 0; i < m.x0.size(); ++i) m.x0.data()[i] += u(rng);
  return m;
}

std::uint64_t run(const Model& m, int steps, int threads, bool gathered = true) {
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  ws.threads = threads;
  if (!gathered) ws.adjacency.reset();  // the scatter loop
  for (int i = 0; i < steps; ++i) EXPECT_TRUE(step(m, s, ws).finite);
  return state_hash(s);
}

TEST(Gather, EqualsTheScatterLoopBitForBit) {
  const Model m = jittered_grid(40);
  const State s = make_state(m);
  Workspace ws = make_workspace(m);
  Eigen::Matrix3Xd ref = Eigen::Matrix3Xd::Random(3, s.x.cols()), got = ref;
  add_spring_forces(m, s.x, ref);
  add_spring_forces(m, s.x, got, ws);
  const double rel = (got - ref).norm() / ref.norm();
  EXPECT_LE(rel, 1e-12);
  EXPECT_EQ(0, std::memcmp(got.data(), ref.data(), sizeof(double) * static_cast<std::size_t>(ref.size())))
      << "relative difference " << rel;
}

TEST(Gather, CoincidentEndsGiveNoForceAsInTheScatter) {
  Model m = jittered_grid(16);
  m.x0.col(5) = m.x0.col(6);  // spring 5-6 has length 0
  const State s = make_state(m);
  Workspace ws = make_workspace(m);
  Eigen::Matrix3Xd ref = Eigen::Matrix3Xd::Constant(3, s.x.cols(), 1.0), got = ref;
  add_spring_forces(m, s.x, ref);
  add_spring_forces(m, s.x, got, ws);
  ASSERT_TRUE(got.allFinite());
  EXPECT_EQ(got, ref);
}

// ModelBuilder's spring order lets the gather read each mass's a ends as a range (run);
// springs in any other order take the entries' general path, with the same bits.
TEST(Gather, RunsOfAEndsAndSpringsInAnyOrder) {
  const Model ordered = jittered_grid(30);
  const SpringAdjacency adj = SpringAdjacency::build(ordered);
  ASSERT_EQ(adj.run.size(), ordered.mass_count());
  std::size_t ends = 0;
  for (std::uint32_t r : adj.run) ends += r;
  EXPECT_EQ(ends, ordered.spring_count());  // every spring's a end, once

  Model shuffled = ordered;  // the same springs, reordered, half of them turned around
  std::vector<std::size_t> order(ordered.spring_count());
  for (std::size_t s = 0; s < order.size(); ++s) order[s] = s;
  std::shuffle(order.begin(), order.end(), std::mt19937_64(11));
  for (std::size_t s = 0; s < order.size(); ++s) {
    const std::size_t o = order[s];
    shuffled.spring_a[s] = s % 2 ? ordered.spring_b[o] : ordered.spring_a[o];
    shuffled.spring_b[s] = s % 2 ? ordered.spring_a[o] : ordered.spring_b[o];
    shuffled.rest_length0[static_cast<Eigen::Index>(s)] = ordered.rest_length0[static_cast<Eigen::Index>(o)];
    shuffled.spring_kind[s] = ordered.spring_kind[o];
  }
  EXPECT_TRUE(SpringAdjacency::build(shuffled).run.empty());
  // An odd number of masses: the AVX2 gather takes them two at a time, and the last alone.
  const Model odd = jittered_grid(31);
  ASSERT_FALSE(SpringAdjacency::build(odd).run.empty());
  for (const Model* m : std::initializer_list<const Model*>{&ordered, &shuffled, &odd}) {
    const State s = make_state(*m);
    Workspace ws = make_workspace(*m);
    Eigen::Matrix3Xd ref = Eigen::Matrix3Xd::Random(3, s.x.cols()), got = ref;
    add_spring_forces(*m, s.x, ref);
    add_spring_forces(*m, s.x, got, ws);
    EXPECT_EQ(0, std::memcmp(got.data(), ref.data(), sizeof(double) * static_cast<std::size_t>(ref.size())));
  }
}

// A chain whose every mass is joined to its next k (jittered positions): away from the ends
// each mass has k a ends and k b ends (the paired gather's loops with equal counts; near the
// ends unequal ones); every k gives the scatter's bits.
TEST(Gather, ChainsWithOneToNineEndsOfEachKind) {
  for (std::uint32_t k = 1; k <= 9; ++k) {
    const std::uint32_t n = 203;  // an odd count: the last mass alone
    Eigen::Matrix3Xd x(3, n);
    std::mt19937_64 rng(k);
    std::uniform_real_distribution<double> u(-0.01, 0.01);
    for (std::uint32_t i = 0; i < n; ++i) x.col(i) = Eigen::Vector3d(0.05 * i + u(rng), u(rng), u(rng));
    std::vector<SpringSpec> springs;
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t j = i + 1; j <= i + k && j < n; ++j)
        springs.push_back(SpringSpec{i, j, static_cast<std::uint8_t>(j - i > 1), 0.05 * (j - i)});
    ModelBuilder b(seed_options(), "chain");
    b.add_cloth(x, springs, {});
    const Model m = b.build();
    const SpringAdjacency adj = SpringAdjacency::build(m);
    ASSERT_EQ(adj.run.size(), m.mass_count());
    std::size_t uniform = 0;  // masses with k a ends and k b ends
    for (std::size_t i = 0; i < m.mass_count(); ++i)
      uniform += adj.run[i] == k && adj.start[i + 1] - adj.start[i] == 2 * k;
    EXPECT_GE(uniform, n - 2 * k - 2) << "k = " << k;
    const State s = make_state(m);
    Workspace ws = make_workspace(m);
    Eigen::Matrix3Xd ref = Eigen::Matrix3Xd::Random(3, s.x.cols()), got = ref;
    add_spring_forces(m, s.x, ref);
    add_spring_forces(m, s.x, got, ws);
    EXPECT_EQ(0, std::memcmp(got.data(), ref.data(), sizeof(double) * static_cast<std::size_t>(ref.size())))
        << "k = " << k;
  }
}

TEST(Gather, WorkspaceWithoutAdjacencyFallsBackToTheScatter) {
  const Model m = jittered_grid(24);
  EXPECT_EQ(run(m, 30, 1, true), run(m, 30, 1, false));
}

TEST(Threads, ZeroMeansEveryCore) {
  EXPECT_EQ(resolve_threads(3), step_splits(jittered_grid(72)) ? 3 : 3);
  EXPECT_GE(resolve_threads(0), 1);
  EXPECT_EQ(resolve_threads(0), resolve_threads(-1));
}

// Large enough (> 4096 masses) that the loops really split between threads.
TEST(Threads, TwoAndThreeThreadsAreBitIdenticalToOne) {
  const Model m = jittered_grid(72);
  const std::uint64_t one = run(m, 40, 1);
  EXPECT_EQ(run(m, 40, 2), one);
  EXPECT_EQ(run(m, 40, 3), one);
  EXPECT_EQ(run(m, 40, 1, false), one);  // and to the scatter loop
}

TEST(Threads, BitIdenticalOverACollider) {
  const Model m = jittered_grid(72, perf::sphere_collider(3));
  const std::uint64_t one = run(m, 30, 1);
  EXPECT_EQ(run(m, 30, 2), one);
  EXPECT_EQ(run(m, 30, 1, false), one);
}

// --threads auto switches the count while a run steps: the contact caches, the spring split
// and the collision runs' balance carry over, and the bits stay those of one thread.
TEST(Threads, SwitchingTheCountWhileSteppingIsBitIdentical) {
  const Model m = jittered_grid(72, perf::sphere_collider(3));
  ASSERT_TRUE(step_splits(m));
  const std::uint64_t one = run(m, 60, 1);
  {
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    int in_contact = 0;  // steps with contact forces: the collision's split is switched too
    for (int i = 0; i < 60; ++i) {
      ws.threads = i / 7 % 2 == 0 ? 2 : 1;  // 1..7 on two threads, 8..14 on one, ...
      ASSERT_TRUE(step(m, s, ws).finite);
      if (ws.last_contacts > 0) ++in_contact;
    }
    EXPECT_GT(in_contact, 30);
    EXPECT_EQ(state_hash(s), one);
  }
  {  // the chooser itself, fed a fixed 2 ms per step (no clock: the same switches on any
     // machine): 34 steps of trial on two threads, then the rest on one (its trial)
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    ThreadChooser chooser(2);
    int switches = 0;
    for (int i = 0; i < 60; ++i) {
      if (ws.threads != chooser.threads()) ws.threads = chooser.threads(), ++switches;
      ASSERT_TRUE(step(m, s, ws).finite);
      chooser.step_took(2e-3);
    }
    EXPECT_EQ(chooser.steps_many(), static_cast<std::uint64_t>(ThreadChooser::kWarm + ThreadChooser::kTrialSteps));
    EXPECT_EQ(chooser.steps_one(), 60 - chooser.steps_many());
    EXPECT_GE(switches, 1);
    EXPECT_EQ(state_hash(s), one);
  }
  {  // chosen_step() (its clock): the first steps of the first trial are on all cores
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    ThreadChooser chooser(2);
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(chosen_step(chooser, m, s, ws).finite);
    EXPECT_EQ(ws.threads, 2);
    EXPECT_EQ(chooser.steps_many(), 10u);
    ws.threads = 1;
    for (int i = 10; i < 60; ++i) ASSERT_TRUE(step(m, s, ws).finite);
    EXPECT_EQ(state_hash(s), one);
  }
}

TEST(Threads, SmallModelsDoNotSplit) {
  EXPECT_FALSE(step_splits(jittered_grid(40)));  // 1 600 masses
  EXPECT_TRUE(step_splits(jittered_grid(72)));   // 5 184
}

TEST(Threads, BitIdenticalWithAnotherIntegrator) {
  Model m = jittered_grid(72);
  m.options.integrator = Integrator::RK4;
  EXPECT_EQ(run(m, 10, 2), run(m, 10, 1));
}

}  // namespace
}  // namespace clothsim
