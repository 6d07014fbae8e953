#pragma once
// The volumes that ice and solids fill: a box (optionally rotated about its centre), a sphere, a
// cylinder, a cone, a capsule, or a triangle mesh. Each answers one question, whether a point is inside,
// and knows its bounding box; the lattice over that box, filtered by the question, samples it
// (voxelize.h).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <vector>

#include "sim/geometry/mesh.h"

namespace thaw {

class WindingNumber;

class Shape {
 public:
  enum class Kind { Box, Sphere, Cylinder, Cone, Capsule, Mesh };

  Shape() = default;  // an empty box at the origin

  // [min, max] turned by `rotation` about its centre.
  static Shape box(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                   const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity());
  static Shape sphere(const Eigen::Vector3d& centre, double radius);
  // Flat ends at `from` and `to`.
  static Shape cylinder(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double radius);
  // Base circle of `radius` at `from`, apex at `to`.
  static Shape cone(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double radius);
  // The points within `radius` of the segment from `from` to `to`.
  static Shape capsule(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double radius);
  // Inside where the generalized winding number exceeds 1/2 (winding_number.h). The triangles are in world
  // coordinates (place_mesh); a mesh whose triangles face inwards is turned inside out first.
  static Shape mesh(TriangleSoup triangles);

  Kind kind() const { return kind_; }
  const Eigen::AlignedBox3d& bounds() const { return bounds_; }
  // An unrotated box, sampled by whole cells like the blocks of scenes before shapes (voxelize.h).
  bool axis_aligned_box() const { return kind_ == Kind::Box && !rotated_; }

  bool contains(const Eigen::Vector3d& p) const;  // the surface counts as inside
  // contains() of every point; meshes evaluate in parallel.
  std::vector<std::uint8_t> contains(const std::vector<Eigen::Vector3d>& points) const;

  // Exact for the primitives; for a mesh, the divergence-theorem volume (exact when it is closed).
  double volume() const;

 private:
  Kind kind_ = Kind::Box;
  Eigen::Vector3d a_ = Eigen::Vector3d::Zero();  // box: min; sphere: centre; cylinder, cone, capsule: from
  Eigen::Vector3d b_ = Eigen::Vector3d::Zero();  // box: max; cylinder, cone, capsule: to
  double radius_ = 0.0;
  Eigen::Matrix3d rotation_ = Eigen::Matrix3d::Identity();  // box
  bool rotated_ = false;
  Eigen::AlignedBox3d bounds_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::shared_ptr<const WindingNumber> mesh_;  // shared by copies of a scene; never changed
};

}  // namespace thaw
