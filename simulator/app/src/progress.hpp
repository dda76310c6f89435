// The progress of a headless run on stderr.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>

namespace clothsim::app {

// Progress of a headless run. On a terminal: a bar with simulated time, wall time so far, and
// the time left at the pace of the last few percent (a step costs more once the cloth is in
// contact). Otherwise (a log, CI): one line every 30 s of wall time, so a long run is not silent.
class Progress {
 public:
  Progress(std::uint64_t total, bool on, bool terminal)
      : total_(total), on_(on && total >= 200), terminal_(terminal) {}
  void update(std::uint64_t done, double t) {
    if (!on_) return;
    const int pct = static_cast<int>(100 * done / total_);
    if (pct == last_) return;
    last_ = pct;
    const double now = std::chrono::duration<double>(Clock::now() - start_).count();
    at_[pct % kRecent] = now;
    const int back = std::min(pct, kRecent - 1);  // percent points with a time
    const double left = back > 0 ? (now - at_[(pct - back) % kRecent]) / back * (100 - pct) : 0.0;
    if (!terminal_) {
      if (now < next_line_ || pct >= 100) return;
      next_line_ = now + kLineEvery;
      std::fprintf(stderr, "clothsim: %d %% (t = %.2f s), wall %.0f s, left ~%.0f s\n", pct, t, now, left);
      return;
    }
    const int bar = pct * 30 / 100;
    std::fprintf(stderr, "\r[%.*s%*s] %3d%%  t = %.2f s  wall %.0f s", bar, "##############################",
                 30 - bar, "", pct, t, now);
    if (pct > 0 && pct < 100) std::fprintf(stderr, "  left ~%.0f s ", left);
    else std::fprintf(stderr, "%14s", "");
    std::fflush(stderr);
  }
  void finish() {
    if (on_ && terminal_ && last_ >= 0) std::fprintf(stderr, "\n");
  }

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr int kRecent = 6;            // the pace of the last 5 percent points
  static constexpr double kLineEvery = 30.0;   // s of wall time between lines without a terminal
  std::uint64_t total_;
  bool on_, terminal_;
  int last_ = -1;
  Clock::time_point start_ = Clock::now();
  double at_[kRecent] = {};
  double next_line_ = kLineEvery;
};

}  // namespace clothsim::app
