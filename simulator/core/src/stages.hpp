// The core's stages, in the order a step runs them: step() calls one integrator; every
// integrator calls the force stage (compute_forces), which calls the internal forces and the
// contact stage (add_contact_forces, step.hpp). Private to the core.
#pragma once

#include <clothsim/step.hpp>

#include <memory>
#include <vector>

namespace clothsim::detail {

// --- integrators: advance x, v by h (pins, time and the finiteness check are step()'s) ------

/// Report eqs. 1-7 (the seed's method, threaded and in AVX2); tells whether the new state is
/// finite when it checked that on the way (checked = true).
void symplectic_euler(const Model& model, State& state, Workspace& ws, double h, bool& checked, bool& finite);
void explicit_euler(const Model& model, State& state, Workspace& ws, double h);
void verlet(const Model& model, State& state, Workspace& ws, double h);
void midpoint(const Model& model, State& state, Workspace& ws, double h);
void rk4(const Model& model, State& state, Workspace& ws, double h);
void implicit_euler(const Model& model, State& state, Workspace& ws, double h);
void fast_mass_spring(const Model& model, State& state, Workspace& ws, double h);
void xpbd(const Model& model, State& state, Workspace& ws, double h);
/// One of XPBD's passes over the structural springs at x with the inverse masses w (after an
/// xpbd() step of h): the self-contact stage's, with the masses it holds at their bounds locked.
void relax_structural(const Model& model, Eigen::Matrix3Xd& x, const double* w, Workspace& ws, double h);

/// The air's drag on the cloth's faces over h, before the integrator (air_drag.cpp): each face's
/// normal velocity u becomes u / (1 + h air |u|), the exact decay of du/dt = -air |u| u, its
/// change shared by the face's masses by their share of its mass.
void air_drag(const Model& model, State& state, Workspace& ws, double h);
/// The air drag's face lists (Workspace::face_start, face_list, face_dv).
void make_air_scratch(const Model& model, Workspace& ws);

/// Strain limiting after the integrator's update: no structural spring past model.strain_limit
/// (a few passes), positions and velocities together (strain_limit.cpp).
void limit_strain(const Model& model, State& state, Workspace& ws);
/// Within a step: each mass back within reach of the mass the colliders held that it hangs
/// from (the last limit_strain's attachments), positions only (strain_limit.cpp).
void keep_in_reach(const Model& model, Eigen::Matrix3Xd& x, const Workspace& ws);

/// a = f / m, row-wise (pinned masses have inv_mass 0).
inline auto accel(const Model& model, const Eigen::Matrix3Xd& f) {
  return (f.array().rowwise() * model.inv_mass.transpose().array()).matrix();
}

// --- forces --------------------------------------------------------------------------------

/// f = m g - gamma v + springs (report eqs. 2-6), through the gathered passes when ws has them.
void internal_forces(const Model& model, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& f,
                     Workspace& ws);

/// The position-based contact: adds to `push` the move that puts every point near a collider
/// at the contact distance (model.contact), on ws.threads threads for large models.
void add_contact_push(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& push, Workspace& ws);

/// The contact stage's memory between steps (made by make_workspace for a model with colliders).
std::shared_ptr<struct CollisionScratch> make_collision_scratch(const Model& model);

}  // namespace clothsim::detail
