// The window's look-ahead (view/playback.hpp): the picture's clock, the frame policy run against
// a simulated window (steps and frames costing wall time by a profile, no real clock), and the
// ring of states with its take-back.
#include "hand_scene.hpp"

#include <clothsim/scene.hpp>
#include <clothsim/sim.hpp>
#include <clothsim/step.hpp>
#include <clothsim/view/playback.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

namespace cv = clothsim::view;

namespace {

struct WindowRun {
  double dropped = 0.0, preroll_wall = 0.0, wall = 0.0, min_ahead = 1e9;
  long frames = 0;
};

// A window on a virtual clock, deciding as the viewer does (Playback::next): steps of dt cost
// cost(t) x dt of wall time, a frame costs `frame` s, states are kept every `spacing` s.
WindowRun simulate(cv::Playback& pb, double seconds, double dt, double spacing, double frame,
             const std::function<double(double)>& cost) {
  WindowRun r;
  pb.restart(0.0, true);
  double wall = 0.0, last = 0.0, frame_start = -1.0, sim = 0.0, latest = 0.0;
  for (long guard = 0; guard < 10'000'000; ++guard) {
    pb.advance(wall - last, latest, sim < seconds);
    last = wall;
    if (!pb.prerolling() && sim < seconds - 0.5 * dt) r.min_ahead = std::min(r.min_ahead, latest - pb.shown());
    if (pb.shown() >= seconds - 1e-9) break;
    const bool room = sim - pb.shown() < pb.lookahead() + spacing;
    const auto act = pb.next(wall - frame_start, latest, sim, sim < seconds && room, frame);
    if (act.kind == cv::Playback::Action::Draw) {
      frame_start = wall;
      wall += frame;
      ++r.frames;
    } else if (act.kind == cv::Playback::Action::Step) {
      const double until = wall + std::min(act.seconds, 0.05);
      do {  // (at least one: the real clock moves on by itself, this one only by what is done)
        wall += cost(sim) * dt;
        sim += dt;
        latest = std::min(std::floor(sim / spacing + 1e-9) * spacing, seconds);
        if (sim >= seconds - 0.5 * dt) latest = sim;
      } while (wall < until && sim < seconds - 0.5 * dt && pb.wants_steps(sim));
    } else {
      wall += std::max(act.seconds, 1e-3);  // as the viewer waits for events
    }
  }
  r.dropped = pb.dropped();
  r.preroll_wall = pb.preroll_wall();
  r.wall = wall;
  return r;
}

// skirt_hires on this host (docs/performance.md): steps at 0.75 of real time in the free fall,
// 1.2 and 1.05 in the two seconds of sliding, 0.6-0.65 after; a software frame ~16 ms.
double skirt_hires_like(double t) { return t < 1.0 ? 0.75 : t < 2.0 ? 1.2 : t < 3.0 ? 1.05 : 0.62; }

}  // namespace

TEST(Playback, HeavySecondsBorrowFromTheCheapOnesAndNothingIsDropped) {
  cv::Playback pb(2.0, 1.0);
  const WindowRun r = simulate(pb, 20.0, 4e-4, 1.0 / 30, 0.016, skirt_hires_like);
  EXPECT_EQ(r.dropped, 0.0);
  EXPECT_GT(r.min_ahead, 0.1) << "the look-ahead ran low";
  EXPECT_NEAR(pb.lowest_ahead(), r.min_ahead, 1.0 / 30);  // what the closing line says
  // the price: the picture held still while the first second was computed ahead (0.75 s)
  EXPECT_NEAR(r.preroll_wall, 0.75, 0.1);
  EXPECT_NEAR(r.wall, 20.0 + r.preroll_wall, 0.1);
  EXPECT_GT(r.frames, 8 * 20);  // and it still draws (here ~12 per second on average)
}

TEST(Playback, WithoutThePrerollTheHeavySecondsFallBehind) {
  cv::Playback pb(2.0, 0.0);
  const WindowRun r = simulate(pb, 20.0, 4e-4, 1.0 / 30, 0.016, skirt_hires_like);
  EXPECT_GT(r.dropped, 0.1);
  EXPECT_EQ(r.preroll_wall, 0.0);
}

TEST(Playback, ASimulationSlowerThanRealTimeThroughoutDropsWhatItCannotCompute) {
  cv::Playback pb(2.0, 1.0);
  const WindowRun r = simulate(pb, 10.0, 1e-3, 1.0 / 30, 0.016, [](double) { return 1.3; });
  // 10 s at 1.3x plus frames cannot be shown in 10 s: at least (1 - 1/1.3) of what follows the
  // look-ahead is dropped, and said
  EXPECT_GT(r.dropped, (10.0 - 2.0) * (1.0 - 1.0 / 1.3));
  // the wall time: the pre-roll, the picture's 10 s and its waits for the simulation
  EXPECT_NEAR(r.wall, r.preroll_wall + 10.0 + r.dropped, 0.05);
}

TEST(Playback, AFastSimulationDrawsAtSixtyFramesPerSecond) {
  cv::Playback pb(2.0, 1.0);
  const WindowRun r = simulate(pb, 5.0, 2e-3, 1.0 / 60, 0.002, [](double) { return 0.02; });
  EXPECT_EQ(r.dropped, 0.0);
  EXPECT_LT(r.preroll_wall, 0.05);  // 1 s of simulation at 2 % of real time
  EXPECT_NEAR(static_cast<double>(r.frames) / 5.0, 60.0, 2.0);
}

TEST(Playback, TheClockWaitsForTheSimulationAndCountsItOnlyWhileItCouldGoOn) {
  cv::Playback pb(1.0, 0.5);
  pb.restart(2.0, true);
  EXPECT_TRUE(pb.prerolling());
  pb.advance(0.2, 2.3, true);  // 0.3 s ahead of 0.5: the picture holds
  EXPECT_EQ(pb.shown(), 2.0);
  EXPECT_TRUE(pb.prerolling());
  pb.advance(0.1, 2.5, true);  // 0.5 s ahead: it starts (from the next call)
  EXPECT_FALSE(pb.prerolling());
  EXPECT_NEAR(pb.preroll_wall(), 0.3, 1e-12);
  pb.advance(0.25, 2.5, true);
  EXPECT_DOUBLE_EQ(pb.shown(), 2.25);
  EXPECT_DOUBLE_EQ(pb.lowest_ahead(), 0.25);
  pb.advance(0.5, 2.5, true);  // past the newest state: waits there, 0.25 s dropped
  EXPECT_DOUBLE_EQ(pb.shown(), 2.5);
  EXPECT_NEAR(pb.dropped(), 0.25, 1e-12);
  pb.advance(1.0, 2.5, false);  // the run is over (or failed): waiting is not dropping
  EXPECT_NEAR(pb.dropped(), 0.25, 1e-12);
  pb.advance(-1.0, 2.5, true);  // a clock that went backwards, or NaN: no time
  pb.advance(std::numeric_limits<double>::quiet_NaN(), 2.5, true);
  EXPECT_DOUBLE_EQ(pb.shown(), 2.5);
  // A pre-roll the simulation cannot finish: at most kMaxPrerollWall of wall time, or at once
  // when it cannot go on.
  cv::Playback slow(2.0, 1.0);
  slow.restart(0.0, true);
  slow.advance(cv::Playback::kMaxPrerollWall, 0.1, true);
  EXPECT_FALSE(slow.prerolling());
  cv::Playback ended(2.0, 1.0);
  ended.restart(0.0, true);
  ended.advance(0.01, 0.3, false);
  EXPECT_FALSE(ended.prerolling());
  // A resume pre-rolls only kResumePreroll; lookahead and preroll are kept in range.
  ended.restart(0.3, false);
  EXPECT_TRUE(ended.prerolling());
  ended.advance(0.01, 0.3 + 0.5 * cv::Playback::kResumePreroll, true);
  EXPECT_TRUE(ended.prerolling());
  const double resumed = 0.3 + cv::Playback::kResumePreroll + 1e-9;
  ended.advance(0.01, resumed, true);
  EXPECT_FALSE(ended.prerolling());
  ended.advance(0.01, resumed, true);
  EXPECT_DOUBLE_EQ(ended.shown(), 0.31);
  EXPECT_EQ(ended.dropped(), 0.0);
  EXPECT_EQ(cv::Playback(-1.0, 1.0).lookahead(), 0.0);
  EXPECT_EQ(cv::Playback(1.0, 5.0).preroll(), 1.0);
  EXPECT_EQ(cv::Playback(std::numeric_limits<double>::quiet_NaN(), 1.0).lookahead(), 0.0);
}

TEST(Playback, FramesTakeALargerShareAsTheLookAheadFills) {
  cv::Playback pb(2.0, 0.0);
  pb.restart(0.0, false);
  const double f = 0.016;
  double previous = std::numeric_limits<double>::infinity();
  for (double ahead : {0.0, 0.2, 0.5, 1.0, 1.5, 1.79, 1.81, 1.9, 1.99}) {
    const double i = pb.frame_interval(ahead, f);
    EXPECT_LT(i, previous) << ahead;
    previous = i;
  }
  EXPECT_NEAR(pb.frame_interval(0.0, f), f / 0.1, 1e-12);  // 10 % of the time when empty
  EXPECT_NEAR(pb.frame_interval(1.8, f), f / 0.46, 1e-9);  // 46 % at 9/10
  EXPECT_NEAR(pb.frame_interval(2.0 - 1e-9, f), f / 0.95, 1e-6);  // 95 % nearly full
  // never fewer than 4 frames a second (a 45 ms software frame at 10 % would be 0.45 s apart)
  EXPECT_EQ(pb.frame_interval(0.0, 0.045), cv::Playback::kMaxFrameInterval);
  EXPECT_EQ(pb.frame_interval(2.0, f), cv::Playback::kMinFrameInterval);  // full: 60 per second
  EXPECT_EQ(pb.frame_interval(1.0, 0.0), cv::Playback::kMinFrameInterval);  // free frames: 60 too
  // next(): a frame when its interval has passed, else steps, or a wait when nothing can step
  EXPECT_EQ(pb.next(1.0, 1.0, 1.0, true, f).kind, cv::Playback::Action::Draw);
  const auto step = pb.next(0.0, 1.0, 1.0, true, f);
  EXPECT_EQ(step.kind, cv::Playback::Action::Step);
  EXPECT_NEAR(step.seconds, pb.frame_interval(1.0, f), 1e-12);
  const auto wait = pb.next(0.0, 1.0, 1.0, false, f);
  EXPECT_EQ(wait.kind, cv::Playback::Action::Wait);
  EXPECT_NEAR(wait.seconds, cv::Playback::kMinFrameInterval, 1e-12);
  EXPECT_EQ(pb.next(0.0, 2.0, 2.5, true, f).kind, cv::Playback::Action::Wait);  // 2.5 s ahead: enough
}

TEST(StateRing, PlansSixtyStatesPerSecondOrThirtyWhenSixtyDoNotFit) {
  clothsim::testing::HandScene h(12);
  clothsim::Model model = clothsim::build_model(h.scene, clothsim::scene_options(h.scene));
  model.options.dt = 1e-3;
  const std::size_t bytes = cv::StateRing::bytes_per_state(model);
  EXPECT_GE(bytes, 2 * 3 * sizeof(double) * 144);
  const auto roomy = cv::StateRing::plan(model, 2.0, std::size_t{1} << 30);
  EXPECT_EQ(roomy.every, 17u);  // 1/60 s in steps of 1 ms
  EXPECT_EQ(roomy.capacity, static_cast<std::size_t>(std::floor(2.0 / 0.017)) + 2);
  EXPECT_LE(roomy.lookahead, 2.0);  // never more than asked (the window said 3.02 s of 3)
  EXPECT_NEAR(roomy.lookahead, 2.0, 0.017);
  const auto tight = cv::StateRing::plan(model, 2.0, 100 * bytes);  // 120 would not fit, 62 do
  EXPECT_EQ(tight.every, 33u);
  EXPECT_EQ(tight.capacity, static_cast<std::size_t>(std::floor(2.0 / 0.033)) + 2);
  // with 4 substeps per step of dt (model steps of dt / 4 = 1 ms) the spacing is whole steps:
  // 17 -> 20 model steps
  for (const auto& [substeps, every] : {std::pair<int, std::uint64_t>{4, 20}, {17, 17}}) {
    clothsim::Model sub = model;
    sub.options.dt = substeps * 1e-3;
    EXPECT_EQ(cv::StateRing::plan(sub, 2.0, std::size_t{1} << 30, static_cast<std::uint64_t>(substeps)).every, every);
  }
  const auto tiny = cv::StateRing::plan(model, 2.0, 12 * bytes);  // the look-ahead shrinks to fit
  EXPECT_EQ(tiny.capacity, 12u);
  EXPECT_NEAR(tiny.lookahead, 10 * 0.033, 1e-12);
  EXPECT_EQ(cv::StateRing::plan(model, 0.0, std::size_t{1} << 30).lookahead, 0.0);
}

TEST(StateRing, ATakenBackStateStepsOnToTheSameBits) {
  clothsim::testing::HandScene h(12);
  const clothsim::Model model = clothsim::build_model(h.scene, clothsim::scene_options(h.scene));
  clothsim::Workspace ws = clothsim::make_workspace(model);
  // Straight: 60 steps.
  clothsim::State straight = clothsim::make_state(model);
  for (int i = 0; i < 60; ++i) ASSERT_TRUE(clothsim::step(model, straight, ws).finite);
  // Through the ring: states every 10 steps, the one at step 20 shown and taken back at step 50
  // (with the warm caches of the later steps), then 40 more.
  cv::StateRing ring(model, 8);
  clothsim::State s = clothsim::make_state(model);
  ring.push(s);
  for (int i = 1; i <= 50; ++i) {
    ASSERT_TRUE(clothsim::step(model, s, ws).finite);
    if (i % 10 == 0) ring.push(s);
  }
  EXPECT_EQ(ring.size(), 6u);
  EXPECT_TRUE(ring.show(20.5 * model.options.dt, 0.0));
  EXPECT_EQ(ring.front().steps, 20u);
  EXPECT_EQ(ring.back().steps, 50u);
  EXPECT_FALSE(ring.show(20.5 * model.options.dt, 0.0));  // already there
  s = ring.front();
  ring.clear();
  EXPECT_TRUE(ring.empty());
  for (int i = 0; i < 40; ++i) ASSERT_TRUE(clothsim::step(model, s, ws).finite);
  EXPECT_EQ(s.steps, straight.steps);
  EXPECT_EQ(s.t, straight.t);
  for (Eigen::Index k = 0; k < s.x.size(); ++k) {
    ASSERT_EQ(s.x.data()[k], straight.x.data()[k]) << k;
    ASSERT_EQ(s.v.data()[k], straight.v.data()[k]) << k;
  }
}

TEST(StateRing, KeepsItsCapacityAndReusesItsSlots) {
  clothsim::testing::HandScene h(6);
  const clothsim::Model model = clothsim::build_model(h.scene, clothsim::scene_options(h.scene));
  EXPECT_THROW(cv::StateRing(model, 1), std::invalid_argument);
  cv::StateRing ring(model, 3);
  clothsim::State s = clothsim::make_state(model);
  for (int i = 0; i < 3; ++i) {
    s.t = i;
    ring.push(s);
  }
  EXPECT_TRUE(ring.full());
  EXPECT_THROW(ring.push(s), std::logic_error);
  EXPECT_TRUE(ring.show(1.0, 0.0));  // drops t = 0
  s.t = 3;
  ring.push(s);  // into t = 0's slot
  EXPECT_EQ(ring.front().t, 1.0);
  EXPECT_EQ(ring.back().t, 3.0);
  EXPECT_TRUE(ring.show(10.0, 0.0));  // past the newest: the newest stays on screen
  EXPECT_EQ(ring.size(), 1u);
  EXPECT_EQ(ring.front().t, 3.0);
}

TEST(StateRing, KeepsEveryNthStateAndATimedRunsLast) {
  // every 10 steps
  EXPECT_TRUE(cv::keeps_state(10, 10, 0.0, 0.01, -1.0));
  EXPECT_FALSE(cv::keeps_state(11, 10, 0.0, 0.01, -1.0));
  // the last step of a run ending at 0.3 s (from t = 0.29, or a rounding below it), not on a
  // tenth step: kept, so the ring must have room for it (a full ring threw here)
  EXPECT_TRUE(cv::keeps_state(29, 10, 0.29, 0.01, 0.3));
  EXPECT_TRUE(cv::keeps_state(29, 10, 0.29 - 1e-15, 0.01, 0.3));
  EXPECT_FALSE(cv::keeps_state(27, 10, 0.27, 0.01, 0.3));
  EXPECT_FALSE(cv::keeps_state(7, 0, 0.0, 0.01, -1.0));  // (no spacing: only a last state)
}
