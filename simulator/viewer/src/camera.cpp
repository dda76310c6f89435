#include <clothsim/view/camera.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace clothsim::view {

namespace {
constexpr double kMaxPitch = 1.55;  // just short of straight down/up, so the view never flips
}

bool point_at_depth(const Ray& ray, const Eigen::Vector3d& eye, const Eigen::Vector3d& forward,
                    double depth, Eigen::Vector3d& point) {
  const double along = ray.dir.dot(forward);
  if (along <= 1e-9) return false;
  // origin + t dir lies on the plane (p - eye) . forward = depth.
  const double t = (depth - (ray.origin - eye).dot(forward)) / along;
  point = ray.origin + t * ray.dir;
  return true;
}

void OrbitCamera::frame(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double aspect) {
  target = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);
  const double tan_v = std::tan(0.5 * fovy), tan_h = tan_v * std::max(aspect, 1e-3);
  const Eigen::Vector3d f = forward();
  const Eigen::Vector3d s = f.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d u = s.cross(f);
  // The nearest distance at which every corner of the box projects inside the picture
  // (tighter than fitting the bounding sphere), plus a small margin.
  distance = 1e-3;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d r = Eigen::Vector3d((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                                              (corner & 4) ? hi.z() : lo.z()) - target;
    const double depth = r.dot(f);  // > 0: beyond the target
    distance = std::max(distance, -depth + std::abs(r.dot(s)) / tan_h);
    distance = std::max(distance, -depth + std::abs(r.dot(u)) / tan_v);
  }
  distance *= 1.08;
  near_plane = std::max(distance - 4.0 * radius, distance * 1e-3);
  far_plane = distance + 20.0 * radius;
}

void OrbitCamera::orbit(double dx, double dy) {
  yaw -= dx * 0.008;
  pitch = std::clamp(pitch + dy * 0.008, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(double dx, double dy, int viewport_h) {
  // One pixel moves the target by the size of a pixel at the target's depth.
  const double per_pixel = 2.0 * distance * std::tan(0.5 * fovy) / std::max(viewport_h, 1);
  const Eigen::Vector3d f = forward();
  const Eigen::Vector3d right = f.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d up = right.cross(f);
  target += (-dx * right + dy * up) * per_pixel;
}

void OrbitCamera::zoom(double wheel_steps) {
  const double scale = std::pow(0.88, wheel_steps);
  // The far plane keeps its depth beyond the target (else, zoomed far out, the scene falls
  // behind it and the picture is blank).
  far_plane += distance * (scale - 1.0);
  distance *= scale;
  near_plane *= scale;
}

Eigen::Vector3d OrbitCamera::forward() const {
  return Eigen::Vector3d(-std::cos(pitch) * std::sin(yaw), -std::sin(pitch),
                         -std::cos(pitch) * std::cos(yaw));
}

Eigen::Vector3d OrbitCamera::eye() const { return target - distance * forward(); }

Eigen::Matrix4f OrbitCamera::view() const {
  const Eigen::Vector3d f = forward();
  const Eigen::Vector3d s = f.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d u = s.cross(f);
  const Eigen::Vector3d e = eye();
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(e);
  m(1, 3) = -u.dot(e);
  m(2, 3) = f.dot(e);
  return m.cast<float>();
}

Eigen::Matrix4f OrbitCamera::projection(double aspect) const {
  const double f = 1.0 / std::tan(0.5 * fovy);
  const double n = near_plane, fa = far_plane;
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = f / std::max(aspect, 1e-6);
  p(1, 1) = f;
  p(2, 2) = (fa + n) / (n - fa);
  p(2, 3) = 2.0 * fa * n / (n - fa);
  p(3, 2) = -1.0;
  return p.cast<float>();
}

Ray OrbitCamera::ray(double x, double y, double width, double height) const {
  const double ndc_x = 2.0 * x / std::max(width, 1.0) - 1.0;
  const double ndc_y = 1.0 - 2.0 * y / std::max(height, 1.0);
  const double tan_half = std::tan(0.5 * fovy);
  const double aspect = width / std::max(height, 1.0);
  const Eigen::Vector3d f = forward();
  const Eigen::Vector3d s = f.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d u = s.cross(f);
  const Eigen::Vector3d dir = (f + ndc_x * tan_half * aspect * s + ndc_y * tan_half * u).normalized();
  return {eye(), dir};
}

}  // namespace clothsim::view
