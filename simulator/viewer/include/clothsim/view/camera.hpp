// Orbit camera of the viewer: yaw/pitch/distance around a target point (world Y up).
#pragma once

#include <Eigen/Core>

namespace clothsim::view {

struct Ray {
  Eigen::Vector3d origin, dir;  ///< dir has unit length
};

/// The point of `ray` at `depth` along the camera's forward axis from `eye` (the drag keeps
/// the grabbed point on this plane facing the camera); false if the ray runs parallel to it.
bool point_at_depth(const Ray& ray, const Eigen::Vector3d& eye, const Eigen::Vector3d& forward,
                    double depth, Eigen::Vector3d& point);

class OrbitCamera {
 public:
  /// Places the target at the box's centre and backs off until the whole box is in view.
  void frame(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double aspect);

  void orbit(double dx_pixels, double dy_pixels);                 ///< mouse motion
  void pan(double dx_pixels, double dy_pixels, int viewport_h);   ///< moves the target in the view plane
  void zoom(double wheel_steps);                                   ///< > 0 moves closer

  Eigen::Vector3d eye() const;
  Eigen::Matrix4f view() const;
  Eigen::Matrix4f projection(double aspect) const;
  /// The ray through a window point (x right, y down, in the same units as width/height).
  Ray ray(double x, double y, double width, double height) const;
  /// Unit vector the camera looks along.
  Eigen::Vector3d forward() const;

  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double distance = 5.0;
  double yaw = 0.5;      ///< rad, around +Y
  double pitch = 0.3;    ///< rad, > 0 looks down on the target
  double fovy = 0.7854;  ///< rad, vertical field of view
  double near_plane = 0.01, far_plane = 100.0;
};

}  // namespace clothsim::view
