// The contact stage: the penalty forces of every collider (report eq. 12) for the force-based
// integrators, or the pushes that put points at the contact distance for the position-based
// one; on one thread or several; and the Coulomb friction of the force-based integrators.
// Without the collision module it adds nothing.
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

// One call of the query over the whole cloth: call(begin, end, stats) for runs of kRun masses,
// a contiguous share of them per thread (handing them out as threads get free is 30 % slower:
// the cache entries then move between the cores), the shares balanced by the time each took
// in the last call. All share one cache: a point's answer does not depend on the others or on
// who computes it; the statistics combine in run order. So the results do not depend on the
// split, only the speed does.
template <class Call>
PenaltyStats over_runs(std::size_t n, CollisionScratch& cs, int nt, Call call) {
  const std::size_t count = (n + CollisionScratch::kRun - 1) / CollisionScratch::kRun;
  const auto parts = static_cast<std::size_t>(nt);
  if (cs.runs.size() != count || cs.bound.size() != parts + 1) {  // allocates once per thread count
    cs.runs.assign(count, {});
    cs.bound.resize(parts + 1);
    for (std::size_t t = 0; t <= parts; ++t) cs.bound[t] = count * t / parts;
    cs.seconds.assign(parts, 0.0);
  }
  bool timed = true;
  parallel_region(nt, [&](int thread, int team_count) {
    const auto t = static_cast<std::size_t>(thread), got = static_cast<std::size_t>(team_count);
    const double t0 = wtime();
    const std::size_t r0 = got == parts ? cs.bound[t] : count * t / got;
    const std::size_t r1 = got == parts ? cs.bound[t + 1] : count * (t + 1) / got;
    for (std::size_t r = r0; r < r1; ++r) {
      const std::size_t b = r * CollisionScratch::kRun;
      call(b, std::min(n, b + CollisionScratch::kRun), cs.runs[r]);
    }
    if (got == parts) cs.seconds[t] = wtime() - t0;
#pragma omp single nowait
    if (got != parts) timed = false;
  });
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

void record(Workspace& ws, const PenaltyStats& stats) {
  ws.last_penetration = stats.max_penetration;
  ws.last_contacts = static_cast<std::uint32_t>(stats.contacts);
}

// The penalty forces into `out` (added).
void penalty_into(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& out, Workspace& ws) {
  const ColliderSet& set = *model.colliders;
  const ContactParams& c = model.contact;
  PenaltyStats stats;
  const int nt = team(ws, collision_work(model.mass_count(), set.object_count()));
  if (!ws.collision) {  // a Workspace not made by make_workspace: the hints, if sized
    accumulate_penalty(set, x, c.distance, c.k_rep, out, stats, std::span<std::int32_t>(ws.contact_hint));
  } else if (nt <= 1) {
    accumulate_penalty(set, x, c.distance, c.k_rep, out, stats, ws.collision->whole);
  } else {
    ws.collision->whole.tick();  // one call of the shared cache, in runs
    ws.collision->whole.use_band(c.distance);
    stats = over_runs(model.mass_count(), *ws.collision, nt, [&](std::size_t b, std::size_t e, PenaltyStats& s) {
      accumulate_penalty(set, x, b, e, c.distance, c.k_rep, out, s, ws.collision->whole);
    });
  }
  record(ws, stats);
}

}  // namespace

void add_contact_push(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& push, Workspace& ws) {
  ws.last_penetration = 0.0;
  ws.last_contacts = 0;
  if (!model.colliders || !ws.collision) return;
  const ColliderSet& set = *model.colliders;
  const ContactParams& c = model.contact;
  ContactCache& cache = ws.collision->whole;
  cache.tick();
  cache.use_band(c.band);
  const int nt = team(ws, collision_work(model.mass_count(), set.object_count()));
  const auto call = [&](std::size_t b, std::size_t e, PenaltyStats& s) {
    accumulate_push(set, x, b, e, c.distance, c.band, push, s, cache);
  };
  if (nt <= 1) {
    PenaltyStats stats;
    call(0, model.mass_count(), stats);
    record(ws, stats);
  } else {
    record(ws, over_runs(model.mass_count(), *ws.collision, nt, call));
  }
}

}  // namespace detail

void add_contact_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f, Workspace& ws) {
  ws.last_penetration = 0.0;
  ws.last_contacts = 0;
  if (!model.colliders) return;
  if (ws.contact_f.cols() != x.cols()) return detail::penalty_into(model, x, f, ws);
  // with friction: the contact forces apart, for apply_friction() after the step
  ws.contact_f.setZero();
  detail::penalty_into(model, x, ws.contact_f, ws);
  f += ws.contact_f;
}

void apply_friction(const Model& model, State& state, const Workspace& ws, double h) {
  if (ws.contact_f.cols() != state.v.cols()) return;
  const double mu_s = model.contact.static_friction, mu_k = model.contact.friction;
  const auto n = static_cast<std::int64_t>(model.mass_count());
  detail::parallel_for(detail::team(ws, model.mass_count()), n, [&](std::int64_t i) {
    const Eigen::Vector3d cf = ws.contact_f.col(i);
    const double fn = cf.norm();
    if (!(fn > 0.0) || model.pinned[static_cast<std::size_t>(i)]) return;
    // the normal impulse of this step, as a velocity, and the tangential velocity it can stop
    const Eigen::Vector3d nrm = cf / fn;
    const double dvn = h * fn * model.inv_mass[i];
    const Eigen::Vector3d vt = state.v.col(i) - nrm.dot(state.v.col(i)) * nrm;
    const double st = vt.norm();
    if (st <= mu_s * dvn) state.v.col(i) -= vt;                  // static: it sticks
    else state.v.col(i) -= std::min(1.0, mu_k * dvn / st) * vt;  // kinetic: slowed by mu_k dvn
  });
}

#else

namespace detail {
struct CollisionScratch {};
std::shared_ptr<CollisionScratch> make_collision_scratch(const Model&) { return nullptr; }
void add_contact_push(const Model&, const Eigen::Matrix3Xd&, Eigen::Matrix3Xd&, Workspace& ws) {
  ws.last_penetration = 0.0;
  ws.last_contacts = 0;
}
}  // namespace detail

void add_contact_forces(const Model&, const Eigen::Matrix3Xd&, Eigen::Matrix3Xd&, Workspace& ws) {
  ws.last_penetration = 0.0;
  ws.last_contacts = 0;
}

void apply_friction(const Model&, State&, const Workspace&, double) {}

#endif

}  // namespace clothsim
