#pragma once
// The orbit camera of every view: it looks at `target` from `distance`, turned `azimuth` degrees about
// the vertical (z) axis from +x and raised `elevation` degrees above the horizontal.
#include <Eigen/Core>

namespace thaw {

struct OrbitCamera {
  double azimuth = 30.0;    // [deg]
  double elevation = 25.0;  // [deg], in (-90, 90)
  double distance = 0.5;    // [m]
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double fov = 40.0;              // vertical field of view [deg]
  int width = 640, height = 480;  // [pixels]

  Eigen::Vector3d eye() const;
  Eigen::Matrix4f view() const;  // world -> camera (OpenGL convention: camera looks down -z)
  Eigen::Matrix4f projection(float near, float far) const;
  // The ray through the centre of pixel (x, y), y counted down from the top row: origin at the eye,
  // unit direction.
  void ray(double x, double y, Eigen::Vector3d& origin, Eigen::Vector3d& direction) const;
  // A camera that frames the box [lo, hi] from the given angles.
  static OrbitCamera framing(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double azimuth = 30.0,
                             double elevation = 25.0, int width = 640, int height = 480);
};

}  // namespace thaw
