// From a cloth material in SI units to what the Model stores per mass and per spring, so that
// the same material behaves alike at any mesh resolution (docs/physics.md, "Materials"):
//   mass       m_i = density * (sum of the areas of the triangles at i) / 3
//   stretch    k_e = stretch * A_e / L_e^2          (A_e: the areas of the edge's triangles)
//   bend       k_b = 183 * bend * |e|^2 / (A_e L_b^2)  (the hinge |e| of the bend spring L_b:
//              the discrete-shells hinge energy 3 bend |e|^2 / A_e theta^2 / 2 at a 60 degree fold)
//   damping    drag per kilogram
//   air        the faces' drag, 1/2 air_density C_D u^2 per area at normal speed u, C_D = 1.17
//              (a flat plate across the flow; Hoerner, Fluid-Dynamic Drag, 1965, ch. 3)
//   contact    the cloth keeps max(thickness, 5 % of its mean edge) from colliders; the force-based
//              integrators' penalty stops the fastest fall of the scene with a margin of 2
#pragma once

#include <clothsim/sim.hpp>

#include <span>

namespace clothsim {

/// The masses of a material's cloth: density times a third of each point's triangles' area
/// (masses: (n), indexed by global mass; triangles: 3 global indices each). A point in no
/// triangle (or only degenerate ones) gets the mean mass of the others.
void lump_masses(const Eigen::Matrix3Xd& x0, std::span<const std::uint32_t> triangles, double density,
                 Eigen::VectorXd& masses);

/// Every spring's scale for a material (Model::spring_scale): stretch A_e / L_e^2, bend
/// 183 |e|^2 / (A_e L_b^2). A spring on no triangle's edge (or across none) keeps 1 / L^2 times
/// the mean area of the cloth's triangles, times the same factors.
void material_spring_scales(Model& model, std::span<const std::uint32_t> triangles);

/// The drag coefficient of a flat plate across the flow.
inline constexpr double kPlateDrag = 1.17;

/// Model::air for a material: air_density kPlateDrag / (2 density), 1/m.
inline double air_drag_rate(const Options& o) { return o.air_density * kPlateDrag / (2.0 * o.density); }

/// The contact of a material's cloth: its distance, band and penalty (ContactParams).
ContactParams material_contact(const Model& model, const Options& options);

/// The long-range attachments of the pinned masses (Model::attach_pin, attach_rest): the
/// kAttachments nearest pins of every free mass along the structural springs (Dijkstra from
/// all pins at once, each mass settled once per pin).
void long_range_attachments(Model& model);

/// The mean rest length of the structural springs (0 without any).
double mean_structural_length(const Model& model);

}  // namespace clothsim
