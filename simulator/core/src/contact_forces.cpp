// The contact stage: the penalty forces of every collider (report eq. 12), on one thread or
// several. Without the collision module it adds nothing.
#include "parallel.hpp"
#include "stages.hpp"

#include <algorithm>

#ifdef CLOTHSIM_HAVE_COLLISION
#include <clothsim/collision.hpp>
#endif

namespace clothsim {

#ifdef CLOTHSIM_HAVE_COLLISION
namespace detail {

struct CollisionScratch {
  ContactCache whole;  ///< every (mass, collider) pair's certificate
  /// More threads: the statistics of each run of kRun masses (combined in run order).
  static constexpr std::size_t kRun = 128;
  std::vector<PenaltyStats> runs;
  /// (threads + 1) the first run of each thread; each call moves a boundary by one run towards
  /// the thread that took longer (contacts are not spread evenly over the cloth).
  std::vector<std::size_t> bound;
  std::vector<double> seconds;  ///< (threads) each thread's time in the last call
};

std::shared_ptr<CollisionScratch> make_collision_scratch(const Model& model) {
  if (!model.colliders) return nullptr;
  auto cs = std::make_shared<CollisionScratch>();
  cs->whole.resize(model.mass_count(), model.colliders->object_count());
  return cs;
}

namespace {

// Runs of kRun masses, a contiguous share of them per thread (handing them out as threads get
// free is 30 % slower: the cache entries then move between the cores), the shares balanced by
// the time each took in the last call. All share one cache: a point's answer and force do not
// depend on the others or on who computes them; the statistics combine in run order. So the
// results do not depend on the split, only the speed does.
PenaltyStats threaded_penalty(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f, CollisionScratch& cs,
                              int nt) {
  const ColliderSet& set = *model.colliders;
  const Options& o = model.options;
  const std::size_t n = model.mass_count();
  const std::size_t count = (n + CollisionScratch::kRun - 1) / CollisionScratch::kRun;
  const auto parts = static_cast<std::size_t>(nt);
  if (cs.runs.size() != count || cs.bound.size() != parts + 1) {  // allocates once per thread count
    cs.runs.assign(count, {});
    cs.bound.resize(parts + 1);
    for (std::size_t t = 0; t <= parts; ++t) cs.bound[t] = count * t / parts;
    cs.seconds.assign(parts, 0.0);
  }
  bool timed = true;
  cs.whole.tick();  // one call of the shared cache, in runs
  cs.whole.use_band(o.epsilon);
#pragma omp parallel num_threads(nt)
  {
    const std::size_t t = thread_num(), got = team_size();
    const double t0 = wtime();
    const std::size_t r0 = got == parts ? cs.bound[t] : count * t / got;
    const std::size_t r1 = got == parts ? cs.bound[t + 1] : count * (t + 1) / got;
    for (std::size_t r = r0; r < r1; ++r) {
      const std::size_t b = r * CollisionScratch::kRun;
      accumulate_penalty(set, x, b, std::min(n, b + CollisionScratch::kRun), o.epsilon, o.k_rep, f, cs.runs[r],
                         cs.whole);
    }
    if (got == parts) cs.seconds[t] = wtime() - t0;
#pragma omp single nowait
    if (got != parts) timed = false;
  }
  for (std::size_t t = 1; timed && t < parts; ++t) {
    if (cs.seconds[t - 1] > 1.1 * cs.seconds[t] && cs.bound[t] > cs.bound[t - 1]) --cs.bound[t];
    else if (cs.seconds[t] > 1.1 * cs.seconds[t - 1] && cs.bound[t] < cs.bound[t + 1]) ++cs.bound[t];
  }
  PenaltyStats stats;
  for (const auto& run : cs.runs) {
    stats.max_penetration = std::max(stats.max_penetration, run.max_penetration);
    stats.contacts += run.contacts;
  }
  return stats;
}

}  // namespace
}  // namespace detail

void add_contact_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f, Workspace& ws) {
  ws.last_penetration = 0.0;
  ws.last_contacts = 0;
  if (!model.colliders) return;
  const ColliderSet& set = *model.colliders;
  const Options& o = model.options;
  PenaltyStats stats;
  const int nt = detail::team(ws, detail::collision_work(model.mass_count(), set.object_count()));
  if (!ws.collision) {  // a Workspace not made by make_workspace: the hints, if sized
    accumulate_penalty(set, x, o.epsilon, o.k_rep, f, stats, std::span<std::int32_t>(ws.contact_hint));
  } else if (nt <= 1) {
    accumulate_penalty(set, x, o.epsilon, o.k_rep, f, stats, ws.collision->whole);
  } else {
    stats = detail::threaded_penalty(model, x, f, *ws.collision, nt);
  }
  ws.last_penetration = stats.max_penetration;
  ws.last_contacts = static_cast<std::uint32_t>(stats.contacts);
}

#else

namespace detail {
struct CollisionScratch {};
std::shared_ptr<CollisionScratch> make_collision_scratch(const Model&) { return nullptr; }
}  // namespace detail

void add_contact_forces(const Model&, const Eigen::Matrix3Xd&, Eigen::Matrix3Xd&, Workspace& ws) {
  ws.last_penetration = 0.0;
  ws.last_contacts = 0;
}

#endif

}  // namespace clothsim
