// The self-contact response (docs/collision.md, "Self-contact"): after each integrator step
// the close pairs are pushed apart to their target distance as position constraints, with
// Coulomb friction on their relative tangential move over the step (as on the colliders);
// then every mass is held within its bound of the last detection, which keeps any two
// elements from meeting; the velocities take the moves. Strain limiting's result is reached
// in a few moves, each within bounds found where it starts.
#include "parallel.hpp"
#include "self_contact.hpp"
#include "stages.hpp"

#include <algorithm>
#include <cmath>

namespace clothsim::detail {

namespace {

// Mass i's position `at` before the stage's first move of it in this step (xpre), kept once.
void keep_start(SelfScratch& sc, std::uint32_t i, const Eigen::Vector3d& at) {
  if (sc.kept[i] == sc.ends) return;
  sc.kept[i] = sc.ends, sc.xpre.col(i) = at;
  sc.moved_masses.push_back(i);
}

// How far each mass of a pair is from where it was at the detection.
void measure_away(SelfScratch& sc, const Eigen::Matrix3Xd& x) {
  for (const std::uint32_t i : sc.pair_masses) sc.away[i] = away_from(sc, x, i);
}

// Pushes one pair apart to its target, with friction on the relative tangential move since xs.
// A pair whose gap at the detection less its masses' moves since is at least its target is
// left alone without measuring it. A pair that has passed to the other side of where it was
// at the detection is pushed back to that side: the bounds put it back there anyway. Whether
// it was pushed.
bool separate(const Model& m, SelfScratch& sc, const SelfContact& contact, bool vertex_triangle, Eigen::Matrix3Xd& x) {
  const SelfPair& p = contact.pair;
  const std::uint32_t* q = p.mass;
  const double closed = vertex_triangle ? sc.away[q[0]] + std::max({sc.away[q[1]], sc.away[q[2]], sc.away[q[3]]})
                                        : std::max(sc.away[q[0]], sc.away[q[1]]) + std::max(sc.away[q[2]], sc.away[q[3]]);
  if (p.gap - closed >= p.target) return false;
  double c[4];
  const Eigen::Vector3d g = pair_gap(x, p.mass, vertex_triangle, c);
  const double along = g.dot(contact.side);
  const bool crossed = along <= 0.0 && contact.side.squaredNorm() > 0.0;
  const double gap = crossed ? along : g.norm();
  if (!(gap < p.target) || (gap == 0.0 && !crossed)) return false;  // (no gap and no side: no direction)
  double wsum = 0.0, w[4];
  for (int k = 0; k < 4; ++k) w[k] = m.inv_mass[p.mass[k]], wsum += c[k] * c[k] * w[k];
  if (wsum == 0.0) return false;
  const Eigen::Vector3d n = crossed ? contact.side : Eigen::Vector3d(g / gap);
  const double depth = p.target - gap;
  Eigen::Vector3d move = Eigen::Vector3d::Zero();  // the relative move over the step
  for (int k = 0; k < 4; ++k) move += c[k] * (x.col(p.mass[k]) - sc.xs.col(p.mass[k]));
  const Eigen::Vector3d tangent = move - n.dot(move) * n;
  const double slide = tangent.norm(), mu_s = m.contact.static_friction, mu_k = m.contact.friction;
  const double keep = slide <= mu_s * depth ? 1.0 : (slide > 0.0 ? std::min(1.0, mu_k * depth / slide) : 0.0);
  const Eigen::Vector3d dg = depth * n - keep * tangent;  // the change of the gap vector
  for (int k = 0; k < 4; ++k) {
    keep_start(sc, q[k], x.col(q[k]));
    x.col(q[k]) += (c[k] * w[k] / wsum) * dg;
    sc.away[q[k]] = away_from(sc, x, q[k]);
  }
  return true;
}

}  // namespace

void find_common_move(const State& state, SelfScratch& sc) {
  if (!sc.follow) return;
  Eigen::Vector3d move = Eigen::Vector3d::Zero(), velocity = Eigen::Vector3d::Zero();
  for (std::uint32_t i : sc.faced_masses) move += state.x.col(i) - sc.xd.col(i), velocity += state.v.col(i);
  const auto count = static_cast<double>(sc.faced_masses.size());
  sc.shift = move / count, sc.drift = velocity / count;
}

int self_contact_begin(const Model& model, const State& state, Workspace& ws, double h, bool may_split) {
  SelfScratch& sc = *ws.self;
  int parts = 1;
  if (sc.detect) {
    detect_self(model, state, h, sc, ws);
    // A pin that would move past a gap: parts in which each pin moves at most half its least
    // gap, and a detection for the first; none when more than kSelfMostParts would be needed
    // (pins that fast get the warning instead of a step many times as costly).
    if (may_split && sc.pin_room < 1.0 && sc.pin_room >= 2.0 / kSelfMostParts) {
      parts = static_cast<int>(std::ceil(2.0 / sc.pin_room));
      detect_self(model, state, h / parts, sc, ws);
      ++sc.split_steps;
    }
    if (sc.overrun_pairs > 0 && sc.pin_overruns == 0) sc.first_pin_overrun = state.t;
    sc.pin_overruns += sc.overrun_pairs;
  }
  for (const std::uint32_t i : sc.pair_masses) sc.xs.col(i) = state.x.col(i);  // (friction's start: pairs only)
  return parts;
}

namespace {

// Mass i back within its bound of where it was at the detection, when free and past it;
// whether it was. Its start is kept by the caller (held masses are few).
bool hold_one(const Model& model, SelfScratch& sc, Eigen::Matrix3Xd& x, std::uint32_t i, Eigen::Vector3d& start) {
  const double b = sc.bound[i];
  const Eigen::Vector3d d = x.col(i) - sc.xd.col(i) - sc.shift;
  if (d.squaredNorm() < kSurelyWithin * b * b) return false;
  const double len = d.norm();
  if (!(len > b && model.inv_mass[i] != 0.0)) return false;
  start = x.col(i);
  x.col(i) = sc.xd.col(i) + sc.shift + (b / len) * d;
  sc.held[i] = 1;
  return true;
}

// Every free mass back within its bound (threads split the masses and join their lists in
// order): the masses it held in sc.held_now. With `near`, also whether a mass it leaves alone
// that is in no pair nears its bound (nears_bound at v over h): no later pass moves it unless
// the springs relax.
void hold_all(const Model& model, SelfScratch& sc, Eigen::Matrix3Xd& x, const Workspace& ws,
              const Eigen::Matrix3Xd* v = nullptr, double h = 0.0, bool* near = nullptr) {
  const auto n = static_cast<std::uint32_t>(model.mass_count());
  const int nt = team(ws, n);
  const auto parts_n = static_cast<std::size_t>(std::max(nt, 1));
  sc.held_parts.resize(parts_n);
  sc.near_parts.assign(parts_n, 0);
  parallel_region(nt, [&](int t, int parts) {
    auto& out = sc.held_parts[static_cast<std::size_t>(t)];
    out.clear();
    bool seen = near == nullptr;
    Eigen::Vector3d start;
    const auto i0 = static_cast<std::uint32_t>(std::uint64_t{n} * static_cast<std::uint64_t>(t) / static_cast<std::uint64_t>(parts));
    const auto i1 = static_cast<std::uint32_t>(std::uint64_t{n} * static_cast<std::uint64_t>(t + 1) / static_cast<std::uint64_t>(parts));
    for (std::uint32_t i = i0; i < i1; ++i) {
      if (hold_one(model, sc, x, i, start)) out.emplace_back(i, start);
      else if (!seen && sc.listed[i] != sc.stamp && !std::isinf(sc.bound[i])) seen = nears_bound(sc, x, *v, i, h);
    }
    sc.near_parts[static_cast<std::size_t>(t)] = near != nullptr && seen;
  });
  if (near) *near = std::any_of(sc.near_parts.begin(), sc.near_parts.end(), [](std::uint8_t b) { return b != 0; });
  sc.held_now.clear();
  for (std::size_t t = 0; t < parts_n; ++t)
    for (const auto& held : sc.held_parts[t]) sc.held_now.push_back(held), keep_start(sc, held.first, held.second);
}

// hold_all() after a push: only the pairs' masses and those the last hold held can be past
// their bounds (no other mass has moved since it looked).
void hold_pushed(const Model& model, SelfScratch& sc, Eigen::Matrix3Xd& x) {
  sc.held_last.swap(sc.held_now);
  sc.held_now.clear();
  Eigen::Vector3d start;
  const auto one = [&](std::uint32_t i) {
    if (hold_one(model, sc, x, i, start)) sc.held_now.emplace_back(i, start), keep_start(sc, i, start);
  };
  for (const std::uint32_t i : sc.pair_masses) one(i);
  for (const auto& h : sc.held_last)
    if (sc.listed[h.first] != sc.stamp) one(h.first);  // (not a pair's: listed marks those)
}

// The springs take their length again with the masses just held locked (weight 0). Every mass
// may move: the starts of all not yet moved are kept first.
void relax_around_held(const Model& model, SelfScratch& sc, Eigen::Matrix3Xd& x, Workspace& ws, double h) {
  for (std::uint32_t i = 0; i < model.mass_count(); ++i)
    if (sc.kept[i] != sc.ends) sc.kept[i] = sc.ends, sc.xpre.col(i) = x.col(i);
  sc.all_moved = true;
  std::copy(model.inv_mass.data(), model.inv_mass.data() + model.inv_mass.size(), sc.weight.begin());
  for (const auto& held : sc.held_now) sc.weight[held.first] = 0.0;
  relax_structural(model, x, sc.weight.data(), ws, h);
  hold_all(model, sc, x, ws);
}

// Every close pair pushed apart once, in order. Whether any was.
bool push_pairs(const Model& model, SelfScratch& sc, Eigen::Matrix3Xd& x) {
  if (sc.vt.empty() && sc.ee.empty()) return false;
  measure_away(sc, x);
  bool pushed = false;
  for (const SelfContact& p : sc.vt) pushed = separate(model, sc, p, true, x) || pushed;
  for (const SelfContact& p : sc.ee) pushed = separate(model, sc, p, false, x) || pushed;
  return pushed;
}

}  // namespace

void limit_strain_within_bounds(const Model& model, State& state, Workspace& ws, double h) {
  SelfScratch& sc = *ws.self;
  limit_strain(model, state, ws);
  sc.xlim = state.x;
  find_common_move(state, sc);
  // The first move within the step's bounds; each next one within bounds found where the
  // last left the masses.
  for (int move = 0; (hold_all(model, sc, state.x, ws), !sc.held_now.empty()) && move < kSelfLimiterMoves; ++move) {
    detect_self(model, state, h, sc, ws);
    state.x = sc.xlim;
  }
  // Detect again when a mass may reach its bound in the next step.
  for (Eigen::Index i = 0; i < state.x.cols() && !sc.detect; ++i) sc.detect = nears_bound(sc, state.x, state.v, i, h);
}

namespace {

// Mass i's velocity takes the stage's moves: a mass held at its bound keeps its velocity but
// the part that leaves the bound (an inelastic stop: holding never adds energy; the passes
// move only positions); any other takes its move over h.
void take_moves(SelfScratch& sc, State& state, std::uint32_t i, double h) {
  if (std::isinf(sc.bound[i])) return;
  const Eigen::Vector3d out = state.x.col(i) - sc.xd.col(i) - sc.shift;
  if (sc.held[i] && out.norm() > 0.0) {
    const Eigen::Vector3d u = out.normalized();
    state.v.col(i) -= std::max(0.0, state.v.col(i).dot(u)) * u;
  } else {
    state.v.col(i) += (state.x.col(i) - sc.xpre.col(i)) / h;
  }
}

}  // namespace

void self_contact_end(const Model& model, State& state, Workspace& ws, double h) {
  SelfScratch& sc = *ws.self;
  ++sc.ends, sc.moved_masses.clear(), sc.all_moved = false;
  find_common_move(state, sc);
  std::fill(sc.held.begin(), sc.held.end(), std::uint8_t{0});
  // Pushes and bounds in turn: a push the bounds cut short gets another try within them. With
  // XPBD the springs then take their length again with the held masses locked, so that a held
  // mass does not leave its neighbours pulling at it (which would feed the springs energy).
  // A pass that neither pushes nor holds leaves nothing for the next.
  const bool springs = model.options.integrator == Integrator::XPBD;
  bool near_left = false;  // (a mass the passes leave alone nears its bound)
  for (int pass = 0; pass < kSelfPasses; ++pass) {
    const bool pushed = push_pairs(model, sc, state.x);
    if (pass == 0) hold_all(model, sc, state.x, ws, &state.v, h, &near_left);
    else hold_pushed(model, sc, state.x);
    const bool held = !sc.held_now.empty();
    if (held && springs) relax_around_held(model, sc, state.x, ws, h);
    if (!pushed && !held) break;
  }
  // The velocities take the moves (a mass the stage did not move has none to take).
  const auto n = static_cast<std::int64_t>(model.mass_count());
  if (sc.all_moved)
    parallel_for(team(ws, model.mass_count()), n, [&](std::int64_t i) { take_moves(sc, state, static_cast<std::uint32_t>(i), h); });
  else
    for (const std::uint32_t i : sc.moved_masses) take_moves(sc, state, i, h);
  // Detect again when a mass may reach its bound in the next step. A collider that stops
  // part of a cloth ends its common move: detect, and hold the bounds still.
  const auto nears = [&](std::int64_t i) {
    return !std::isinf(sc.bound[static_cast<std::size_t>(i)]) && nears_bound(sc, state.x, state.v, i, h);
  };
  const auto any_of = [&](const std::vector<std::uint32_t>& masses) {
    return std::any_of(masses.begin(), masses.end(), [&](std::uint32_t i) { return nears(i); });
  };
  sc.detect = sc.pins_move || (sc.follow && ws.last_contacts > 0) ||
              (sc.all_moved ? parallel_find(team(ws, model.mass_count()), n, nears)
                            : near_left || any_of(sc.pair_masses) || any_of(sc.moved_masses));
}

}  // namespace clothsim::detail
