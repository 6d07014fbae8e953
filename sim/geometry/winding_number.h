#pragma once
// The generalized winding number of a triangle soup (Jacobson, Kavan & Sorkine-Hornung 2013, "Robust
// inside-outside segmentation using generalized winding numbers"): the signed solid angles of its
// triangles seen from a point, summed and divided by 4 pi. It is 1 inside a closed mesh whose triangles
// face out and 0 outside; a small hole or a crack only blurs it near the gap, so w > 1/2 still tells
// inside from outside for meshes that are not quite watertight.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "sim/geometry/mesh.h"

namespace thaw {

// Signed solid angle of triangle t seen from q, in [-2 pi, 2 pi] (Van Oosterom & Strackee 1983):
// positive when q is behind t, i.e. on the side its normal (b - a) x (c - a) points away from.
double solid_angle(const Triangle& t, const Eigen::Vector3d& q);

// Exact: every triangle's solid angle, O(triangles) per point.
double winding_number(const TriangleSoup& mesh, const Eigen::Vector3d& q);

// The same, fast: triangles are grouped in a bounding-volume hierarchy, and a group seen from farther than
// kFarField times its radius counts by its expansion about its centre (Barill, Dickson, Schmidt, Levin &
// Jacobson 2018, "Fast winding numbers for soups and clouds"): the dipole term plus its first-order
// correction. Near groups are summed exactly, so points near the surface get the exact value.
class WindingNumber {
 public:
  static constexpr double kFarField = 2.0;  // Barill et al.'s beta

  explicit WindingNumber(TriangleSoup mesh);

  double operator()(const Eigen::Vector3d& q) const;
  bool inside(const Eigen::Vector3d& q) const { return (*this)(q) > 0.5; }
  // inside() of every point, in parallel (OpenMP); the result does not depend on the thread count.
  std::vector<std::uint8_t> inside(const std::vector<Eigen::Vector3d>& points) const;

  const TriangleSoup& mesh() const { return mesh_; }  // in the hierarchy's order
  const Eigen::AlignedBox3d& bounds() const { return bounds_; }

 private:
  struct Node {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();       // area-weighted centroid of its triangles
    double radius = 0.0;                                    // farthest corner from the centre
    Eigen::Vector3d area_normal = Eigen::Vector3d::Zero();  // sum of area * unit normal
    Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();       // sum of (area * normal) (centroid - centre)^T
    int first = 0, count = 0;                               // its triangles: mesh_[first, first + count)
    int left = -1, right = -1;                              // children; -1 in a leaf
  };

  int build(int first, int count);

  TriangleSoup mesh_;
  Eigen::AlignedBox3d bounds_;
  std::vector<Node> nodes_;  // nodes_[0] is the root
};

}  // namespace thaw
