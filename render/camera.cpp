#include "render/camera.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace thaw {
namespace {
constexpr double kDeg = M_PI / 180.0;
}

Eigen::Vector3d OrbitCamera::eye() const {
  const double a = azimuth * kDeg, e = elevation * kDeg;
  return target +
         distance * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

Eigen::Matrix4f OrbitCamera::view() const {
  const Eigen::Vector3d f = (target - eye()).normalized();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d s = f.cross(up);
  if (s.norm() < 1e-9) s = Eigen::Vector3d::UnitX();
  s.normalize();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye());
  m(1, 3) = -u.dot(eye());
  m(2, 3) = f.dot(eye());
  return m.cast<float>();
}

Eigen::Matrix4f OrbitCamera::projection(float near, float far) const {
  const double t = 1.0 / std::tan(0.5 * fov * kDeg);
  const double aspect = double(width) / double(height);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = t / aspect;
  p(1, 1) = t;
  p(2, 2) = (far + near) / (near - far);
  p(2, 3) = 2.0 * far * near / (near - far);
  p(3, 2) = -1.0;
  return p.cast<float>();
}

void OrbitCamera::ray(double x, double y, Eigen::Vector3d& origin, Eigen::Vector3d& direction) const {
  const Eigen::Vector3d e = eye();
  const Eigen::Vector3d f = (target - e).normalized();
  Eigen::Vector3d s = f.cross(Eigen::Vector3d::UnitZ());
  if (s.norm() < 1e-9) s = Eigen::Vector3d::UnitX();
  s.normalize();
  const Eigen::Vector3d u = s.cross(f);
  const double t = std::tan(0.5 * fov * kDeg);
  const double aspect = double(width) / double(height);
  // Pixel centres: x + 0.5, y + 0.5; normalised device coordinates in [-1, 1], y up.
  const double nx = (2.0 * (x + 0.5) / width - 1.0) * t * aspect;
  const double ny = (1.0 - 2.0 * (y + 0.5) / height) * t;
  origin = e;
  direction = (f + nx * s + ny * u).normalized();
}

OrbitCamera OrbitCamera::framing(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double azimuth,
                                 double elevation, int width, int height) {
  OrbitCamera c;
  c.azimuth = azimuth;
  c.elevation = elevation;
  c.width = width;
  c.height = height;
  c.target = 0.5 * (lo + hi);
  const double radius = 0.5 * (hi - lo).norm();
  const double half = 0.5 * c.fov * kDeg;
  c.distance = radius / std::sin(std::min(half, half * double(width) / double(height))) * 1.05;
  return c;
}

}  // namespace thaw
