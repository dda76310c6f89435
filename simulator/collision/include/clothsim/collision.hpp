// clothsim collision: cloth points against static triangle meshes (the 2016 report, sec. 4).
//
// Depends on Eigen only. Usable without the rest of the simulator:
//   ColliderSet set;
//   set.add_object("floor", V, indices);   // V: 3 x V positions, indices: 3 per triangle
//   set.build();                           // once: drops degenerate triangles, builds a BVH
//   accumulate_penalty(set, x, eps, k_rep, f, stats);   // every step, never allocates
//
// Conventions (see docs/collision.md):
//   * A triangle's unit normal follows its counter-clockwise winding, n = (B-A)x(C-A)/|..|,
//     as Blender writes outward-facing faces. Front side = the side n points to.
//   * The distance of a point P to a triangle is the TRUE Euclidean distance to the closest
//     point of the triangle (face, edge or vertex: Ericson's closest point), signed by the
//     side of the triangle's plane: positive in front, negative behind, +0 on the plane.
//   * Per collider object only the closest triangle counts (ties: lowest triangle index);
//     forces of different objects add up.
//
// The parts, by topic (this header includes them all):
//   clothsim/collision/point_triangle.hpp  point_triangle(), triangle_is_degenerate()
//   clothsim/collision/collider_set.hpp    ColliderSet: triangles, BVH, queries
//   clothsim/collision/contact_cache.hpp   ContactCache: certificates between calls
//   clothsim/collision/penalty.hpp         accumulate_penalty(), PenaltyStats
#pragma once

// The standard and Eigen headers its users may rely on through it.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "clothsim/collision/collider_set.hpp"
#include "clothsim/collision/contact_cache.hpp"
#include "clothsim/collision/penalty.hpp"
#include "clothsim/collision/point_triangle.hpp"
