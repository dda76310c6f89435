// The force stage every integrator calls (report eqs. 2-6 and 12, and the user's drag).
#include "stages.hpp"

namespace clothsim {

void compute_forces(const Model& model, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                    Eigen::Matrix3Xd& f, Workspace& ws) {
  detail::internal_forces(model, x, v, f, ws);
  add_contact_forces(model, x, f, ws);
  const Drag& d = ws.drag;
  if (d.mass >= 0 && static_cast<std::size_t>(d.mass) < model.mass_count() && d.k > 0.0) {
    const Eigen::Vector3d pull = d.target - x.col(d.mass);
    const double len = pull.norm();
    f.col(d.mass) += d.k * (len > d.reach ? (d.reach / len) * pull : pull);
  }
}

}  // namespace clothsim
