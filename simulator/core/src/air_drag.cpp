// The air's drag on the cloth's faces (quadratic in the normal speed, as on a flat plate):
// what makes a sheet fall at a metre or two per second rather than a stone's speed. Per step,
// a face's normal velocity u decays exactly as du/dt = -air |u| u, u -> u / (1 + h air |u|),
// so the stage is stable for any step; the face's change of momentum goes to its three masses
// (each carries a third of the face's area), gathered per mass in one order for any thread
// count.
#include "parallel.hpp"
#include "stages.hpp"

#include <Eigen/Geometry>

#include <cstdint>

namespace clothsim::detail {

void make_air_scratch(const Model& m, Workspace& ws) {
  const std::size_t faces = m.triangles.size() / 3;
  ws.face_dv = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(faces));
  ws.face_start.assign(m.mass_count() + 1, 0);
  for (std::uint32_t i : m.triangles) ++ws.face_start[i + 1];
  for (std::size_t i = 0; i < m.mass_count(); ++i) ws.face_start[i + 1] += ws.face_start[i];
  ws.face_list.resize(m.triangles.size());
  std::vector<std::uint32_t> fill(ws.face_start.begin(), ws.face_start.end() - 1);
  for (std::size_t k = 0; k < m.triangles.size(); ++k) ws.face_list[fill[m.triangles[k]]++] = static_cast<std::uint32_t>(k / 3);
}

void air_drag(const Model& m, State& s, Workspace& ws, double h) {
  const auto faces = static_cast<std::int64_t>(m.triangles.size() / 3);
  const std::uint32_t* t = m.triangles.data();
  // Each face's momentum change per unit of area, over 3: a third goes to each of its masses.
  const double share = m.options.density / 3.0, rate = h * m.air;
  parallel_for(team(ws, m.triangles.size() / 3), faces, [&](std::int64_t f) {
    const std::uint32_t a = t[3 * f], b = t[3 * f + 1], c = t[3 * f + 2];
    const Eigen::Vector3d n2 = (s.x.col(b) - s.x.col(a)).cross(s.x.col(c) - s.x.col(a));  // |n2| = 2 area
    const double len = n2.norm();
    if (!(len > 0.0)) {
      ws.face_dv.col(f).setZero();
      return;
    }
    const Eigen::Vector3d normal = n2 / len;
    const double u = normal.dot(s.v.col(a) + s.v.col(b) + s.v.col(c)) / 3.0;
    const double du = -u * rate * std::abs(u) / (1.0 + rate * std::abs(u));
    ws.face_dv.col(f) = (share * 0.5 * len * du) * normal;  // momentum to each mass
  });
  const auto n = static_cast<std::int64_t>(m.mass_count());
  parallel_for(team(ws, m.mass_count()), n, [&](std::int64_t i) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (std::uint32_t k = ws.face_start[static_cast<std::size_t>(i)]; k < ws.face_start[static_cast<std::size_t>(i) + 1]; ++k)
      p += ws.face_dv.col(ws.face_list[k]);
    s.v.col(i) += m.inv_mass[i] * p;
  });
}

}  // namespace clothsim::detail
