// The self-contact response (docs/collision.md, "Self-contact"): after each integrator step
// the close pairs are pushed apart to their target distance as position constraints, with
// Coulomb friction on their relative tangential move over the step (as on the colliders);
// then every mass is held within its bound of the last detection, which keeps any two
// elements from meeting; the velocities take the moves.
#include "parallel.hpp"
#include "self_contact.hpp"

#include <algorithm>
#include <cmath>

namespace clothsim::detail {

void detect_self(const Model& m, const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws);

namespace {

// Pushes one pair apart to its target, with friction on the relative tangential move since xs.
void separate(const Model& m, const SelfScratch& sc, const SelfPair& p, bool vertex_triangle, Eigen::Matrix3Xd& x) {
  double c[4];
  const Eigen::Vector3d g = pair_gap(x, p.mass, vertex_triangle, c);
  const double gap = g.norm();
  if (!(gap < p.target) || gap == 0.0) return;  // (no gap: no direction)
  double wsum = 0.0, w[4];
  for (int k = 0; k < 4; ++k) w[k] = m.inv_mass[p.mass[k]], wsum += c[k] * c[k] * w[k];
  if (wsum == 0.0) return;
  const Eigen::Vector3d n = g / gap;
  const double depth = p.target - gap;
  Eigen::Vector3d move = Eigen::Vector3d::Zero();  // the relative move over the step
  for (int k = 0; k < 4; ++k) move += c[k] * (x.col(p.mass[k]) - sc.xs.col(p.mass[k]));
  const Eigen::Vector3d tangent = move - n.dot(move) * n;
  const double slide = tangent.norm(), mu_s = m.contact.static_friction, mu_k = m.contact.friction;
  const double keep = slide <= mu_s * depth ? 1.0 : (slide > 0.0 ? std::min(1.0, mu_k * depth / slide) : 0.0);
  const Eigen::Vector3d dg = depth * n - keep * tangent;  // the change of the gap vector
  for (int k = 0; k < 4; ++k) x.col(p.mass[k]) += (c[k] * w[k] / wsum) * dg;
}

}  // namespace

void self_contact_begin(const Model& model, const State& state, Workspace& ws) {
  SelfScratch& sc = *ws.self;
  if (sc.detect) detect_self(model, state.x, sc, ws);
  sc.xs = state.x;
}

void self_contact_end(const Model& model, State& state, Workspace& ws, double h) {
  SelfScratch& sc = *ws.self;
  sc.xpre = state.x;
  for (const SelfPair& p : sc.vt) separate(model, sc, p, true, state.x);
  for (const SelfPair& p : sc.ee) separate(model, sc, p, false, state.x);
  // Each free mass within its bound of the cloth's common move since the detection (a gap
  // does not change when everything moves alike); detect again when a mass may reach its
  // bound in the next step.
  Eigen::Vector3d shift = Eigen::Vector3d::Zero(), drift = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < model.mass_count(); ++i)
    if (sc.in_face[i]) shift += state.x.col(static_cast<Eigen::Index>(i)) - sc.xd.col(static_cast<Eigen::Index>(i)),
                       drift += state.v.col(static_cast<Eigen::Index>(i));
  shift /= static_cast<double>(sc.faced), drift /= static_cast<double>(sc.faced);
  bool near_bound = false;
  const auto n = static_cast<std::int64_t>(model.mass_count());
  [[maybe_unused]] const int nt = team(ws, model.mass_count());
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1) reduction(|| : near_bound)
  for (std::int64_t i = 0; i < n; ++i) {
    const double b = sc.bound[static_cast<std::size_t>(i)];
    if (std::isinf(b)) continue;
    const Eigen::Vector3d d = state.x.col(i) - sc.xd.col(i) - shift;
    const double len = d.norm();
    if (len > b && model.inv_mass[i] != 0.0) state.x.col(i) = sc.xd.col(i) + shift + (b / len) * d;
    state.v.col(i) += (state.x.col(i) - sc.xpre.col(i)) / h;
    const double ahead = kSelfLookAhead * h * (state.v.col(i) - drift).norm();
    near_bound = near_bound || (state.x.col(i) - sc.xd.col(i) - shift).norm() + ahead > b;
  }
  sc.detect = near_bound;
}

}  // namespace clothsim::detail
