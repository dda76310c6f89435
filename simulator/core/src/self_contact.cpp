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
  sc.xs = state.x;
  return parts;
}

namespace {

// Each free mass back within its bound of where it was at the detection; a mass held back is
// locked (weight 0) for the springs' pass that follows. Whether any was.
bool hold(const Model& model, SelfScratch& sc, Eigen::Matrix3Xd& x, const Workspace& ws) {
  const auto n = static_cast<std::int64_t>(model.mass_count());
  return parallel_any(team(ws, model.mass_count()), n, [&](std::int64_t i) {
    const double b = sc.bound[static_cast<std::size_t>(i)];
    const Eigen::Vector3d d = x.col(i) - sc.xd.col(i) - sc.shift;
    if (d.squaredNorm() < kSurelyWithin * b * b) return false;
    const double len = d.norm();
    if (!(len > b && model.inv_mass[i] != 0.0)) return false;
    x.col(i) = sc.xd.col(i) + sc.shift + (b / len) * d;
    sc.weight[static_cast<std::size_t>(i)] = 0.0;
    sc.held[static_cast<std::size_t>(i)] = 1;
    return true;
  });
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
  for (int move = 0; hold(model, sc, state.x, ws) && move < kSelfLimiterMoves; ++move) {
    detect_self(model, state, h, sc, ws);
    state.x = sc.xlim;
  }
  // Detect again when a mass may reach its bound in the next step.
  for (Eigen::Index i = 0; i < state.x.cols() && !sc.detect; ++i) sc.detect = nears_bound(sc, state.x, state.v, i, h);
}

void self_contact_end(const Model& model, State& state, Workspace& ws, double h) {
  SelfScratch& sc = *ws.self;
  sc.xpre = state.x;
  find_common_move(state, sc);
  std::fill(sc.held.begin(), sc.held.end(), std::uint8_t{0});
  // Pushes and bounds in turn: a push the bounds cut short gets another try within them. With
  // XPBD the springs then take their length again with the held masses locked, so that a held
  // mass does not leave its neighbours pulling at it (which would feed the springs energy).
  // A pass that neither pushes nor holds leaves nothing for the next.
  const bool springs = model.options.integrator == Integrator::XPBD;
  for (int pass = 0; pass < kSelfPasses; ++pass) {
    const bool pushed = push_pairs(model, sc, state.x);
    std::copy(model.inv_mass.data(), model.inv_mass.data() + model.inv_mass.size(), sc.weight.begin());
    const bool held = hold(model, sc, state.x, ws);
    if (held && springs) {
      relax_structural(model, state.x, sc.weight.data(), ws, h);
      hold(model, sc, state.x, ws);
    }
    if (!pushed && !held) break;
  }
  // The velocities take the pushes; a mass held at its bound keeps its velocity but the part
  // that leaves the bound (an inelastic stop: holding never adds energy; the passes above
  // move only positions). Detect again when a mass may reach its bound in the next step.
  const auto n = static_cast<std::int64_t>(model.mass_count());
  const bool near_bound = parallel_any(team(ws, model.mass_count()), n, [&](std::int64_t i) {
    const double b = sc.bound[static_cast<std::size_t>(i)];
    if (std::isinf(b)) return false;
    const Eigen::Vector3d out = state.x.col(i) - sc.xd.col(i) - sc.shift;
    if (sc.held[static_cast<std::size_t>(i)] && out.norm() > 0.0) {
      const Eigen::Vector3d u = out.normalized();
      state.v.col(i) -= std::max(0.0, state.v.col(i).dot(u)) * u;
    } else {
      state.v.col(i) += (state.x.col(i) - sc.xpre.col(i)) / h;
    }
    return nears_bound(sc, state.x, state.v, i, h);
  });
  // A collider that stops part of a cloth ends its common move: detect, and hold the bounds still.
  sc.detect = near_bound || sc.pins_move || (sc.follow && ws.last_contacts > 0);
}

}  // namespace clothsim::detail
