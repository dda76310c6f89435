// The step: one integrator over the force stage, pinned masses kept exact, time kept.
// Nothing here allocates after make_workspace(), but once per thread count (the threads'
// shares of springs and collision runs) and once for the scratch of an integrator other than
// symplectic Euler.
#include "parallel.hpp"
#include "self_contact.hpp"
#include "spring_split.hpp"
#include "stages.hpp"

#include <clothsim/integrators.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace clothsim {

State make_state(const Model& model) {
  State s;
  s.x = model.x0;
  s.v = Eigen::Matrix3Xd::Zero(3, model.x0.cols());
  return s;
}

Workspace make_workspace(const Model& model) {
  Workspace ws;
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  ws.f = Eigen::Matrix3Xd::Zero(3, n);
  ws.adjacency = std::make_shared<const SpringAdjacency>(SpringAdjacency::build(model));
  ws.spring_split = std::make_shared<detail::SpringSplit>();
  ws.spring_f.assign(4 * model.spring_count() + 4, 0.0);
  for (std::size_t i = 0; i < model.pinned.size(); ++i)
    if (model.pinned[i]) ws.pinned_index.push_back(static_cast<std::uint32_t>(i));
  ws.pinned_x = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(ws.pinned_index.size()));
  ws.collision = detail::make_collision_scratch(model);
  ws.self = detail::make_self_scratch(model);
  if (model.air > 0.0) detail::make_air_scratch(model, ws);
  const bool friction = model.contact.friction > 0.0 || model.contact.static_friction > 0.0;
  if (friction && model.colliders && model.options.integrator != Integrator::XPBD)
    ws.contact_f = Eigen::Matrix3Xd::Zero(3, n);
  if (model.strain_limit > 0.0) {
    ws.stretched.reserve(model.spring_count());
    ws.moved.assign(model.mass_count(), 0);
    ws.moved_list.reserve(model.mass_count());
    ws.listed.assign(model.spring_count(), 0);
    if (model.colliders) {
      ws.held.assign(model.mass_count(), 0);
      ws.anchor.assign(model.mass_count(), ~std::uint32_t{0});  // (none until the first step's end)
      ws.reach.assign(model.mass_count(), 0.0);
      ws.frontier.reserve(2 * model.spring_count() + model.mass_count());
    }
  }
  return ws;
}

void save_pins(const State& s, Workspace& ws) {
  for (std::size_t p = 0; p < ws.pinned_index.size(); ++p)
    ws.pinned_x.col(static_cast<Eigen::Index>(p)) = s.x.col(ws.pinned_index[p]);
}

void restore_pins(State& s, const Workspace& ws) {
  // Pinned masses keep their exact bits (x + h*0 would turn -0.0 into +0.0).
  for (std::size_t p = 0; p < ws.pinned_index.size(); ++p) {
    s.x.col(ws.pinned_index[p]) = ws.pinned_x.col(static_cast<Eigen::Index>(p));
    s.v.col(ws.pinned_index[p]).setZero();
  }
}

namespace {

// Pins that turn (Model::pin_axis): each pinned mass at its rest position turned by pin_spin t
// about its group's axis (Rodrigues), kept in ws.pinned_x; the integrator sees it there at
// rest (velocity 0, so that no integrator moves it further).
void turn_pins(const Model& m, State& s, Workspace& ws, double t) {
  const double angle = m.options.pin_spin * t, c = std::cos(angle), sn = std::sin(angle);
  for (std::size_t p = 0; p < ws.pinned_index.size(); ++p) {
    const auto q = static_cast<Eigen::Index>(p);
    const auto i = static_cast<Eigen::Index>(ws.pinned_index[p]);
    const Eigen::Vector3d u = m.pin_axis.col(q), r = m.x0.col(i) - m.pin_origin.col(q);
    if (u.isZero())
      ws.pinned_x.col(q) = m.x0.col(i);
    else
      ws.pinned_x.col(q) = m.pin_origin.col(q) + c * r + sn * u.cross(r) + (1.0 - c) * u.dot(r) * u;
    s.x.col(i) = ws.pinned_x.col(q);
    s.v.col(i).setZero();
  }
}

// After the step the turning pins move at omega u x (x - origin).
void spin_pin_velocities(const Model& m, State& s, const Workspace& ws) {
  for (std::size_t p = 0; p < ws.pinned_index.size(); ++p) {
    const auto q = static_cast<Eigen::Index>(p);
    const auto i = static_cast<Eigen::Index>(ws.pinned_index[p]);
    s.v.col(i) = m.options.pin_spin * m.pin_axis.col(q).cross(s.x.col(i) - m.pin_origin.col(q));
  }
}

// One integrator step of h, with the colliders' friction where the integrator has none of its own.
void integrate(const Model& model, State& state, Workspace& ws, double h, bool& checked, bool& finite) {
  using namespace detail;
  switch (model.options.integrator) {
    case Integrator::SymplecticEuler: symplectic_euler(model, state, ws, h, checked, finite); break;
    case Integrator::ExplicitEuler: explicit_euler(model, state, ws, h); break;
    case Integrator::Verlet: verlet(model, state, ws, h); break;
    case Integrator::Midpoint: midpoint(model, state, ws, h); break;
    case Integrator::RK4: rk4(model, state, ws, h); break;
    case Integrator::ImplicitEuler: implicit_euler(model, state, ws, h); break;
    case Integrator::FastMassSpring: fast_mass_spring(model, state, ws, h); break;
    case Integrator::XPBD: xpbd(model, state, ws, h); break;
    case Integrator::Auto: break;  // (resolved when the Model is built)
  }
  if (model.options.integrator != Integrator::XPBD) apply_friction(model, state, ws, h);  // (XPBD's is in its contact)
}

}  // namespace

StepStatus step(const Model& model, State& state, Workspace& ws) {
  using namespace detail;
  const double h = model.options.dt / ws.substeps;
  ws.drag = state.drag;
  const Integrator method = model.options.integrator;
  // the scratch of the other integrators, made on their first step (once per Workspace)
  if (method != Integrator::SymplecticEuler && !ws.integrator_scratch)
    ws.integrator_scratch = make_integrator_scratch(model);
  bool checked = false, finite = true;
  // (before the pins turn: they move within the step)
  const int parts = ws.self ? self_contact_begin(model, state, ws, h, true) : 1;
  const double hp = h / parts;
  // pins that turn are put where they are at the step's end; others keep their bits
  const auto turning = static_cast<std::size_t>(model.pin_axis.cols());
  const bool spin = turning > 0 && turning == ws.pinned_index.size();
  // The slow stages run once per dt: the air's drag over half of dt before its first substep
  // and half after its last (exact for any step; the halves keep the split second order),
  // strain limiting after its last.
  const auto per = static_cast<std::uint64_t>(std::max(ws.substeps, 1));
  const bool first = state.steps % per == 0, last = (state.steps + 1) % per == 0;
  const bool air = model.air > 0.0;
  for (int k = 0; k < parts; ++k) {  // (parts: pins that turn past their gaps, self_contact_begin)
    if (k > 0) self_contact_begin(model, state, ws, hp, false);
    if (spin)
      turn_pins(model, state, ws, state.t + (k + 1) * hp);
    else
      save_pins(state, ws);
    if (air && first && k == 0) air_drag(model, state, ws, 0.5 * model.options.dt);
    bool part_checked = false, part_finite = true;
    integrate(model, state, ws, hp, part_checked, part_finite);
    checked = k == 0 ? part_checked : checked && part_checked, finite = finite && part_finite;
    if (ws.self) self_contact_end(model, state, ws, hp);
    if (k + 1 < parts) {
      restore_pins(state, ws);
      if (spin) spin_pin_velocities(model, state, ws);
    }
  }
  if (air && last) air_drag(model, state, ws, 0.5 * model.options.dt);
  if (last && ws.self && model.strain_limit > 0.0) limit_strain_within_bounds(model, state, ws, h);
  else if (last) limit_strain(model, state, ws);
  restore_pins(state, ws);
  if (spin) spin_pin_velocities(model, state, ws);
  state.t += h;
  ++state.steps;
  state.max_penetration = std::max(state.max_penetration, ws.last_penetration);
  return StepStatus{checked ? finite : all_finite(state, ws)};
}

}  // namespace clothsim
