#include "sim/geometry/shape.h"

#include <algorithm>
#include <cmath>

#include "sim/geometry/winding_number.h"

namespace thaw {

namespace {

using Vec3 = Eigen::Vector3d;

// Half-extents along x, y, z of a disc of `radius` whose normal is the unit vector u.
Vec3 disc_half_extent(const Vec3& u, double radius) {
  return (Vec3::Ones() - u.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt() * radius;
}

// Position along the axis (0 at `from`, `length` at `to`) and squared distance from the axis.
struct AxisCoordinates {
  double along, off2, length;
};

AxisCoordinates axis_coordinates(const Vec3& from, const Vec3& to, const Vec3& p) {
  const Vec3 axis = to - from;
  const double length = axis.norm();
  const Vec3 d = p - from;
  if (length == 0.0) return {0.0, d.squaredNorm(), 0.0};
  const double along = d.dot(axis) / length;
  return {along, std::max(0.0, d.squaredNorm() - along * along), length};
}

}  // namespace

Shape Shape::box(const Vec3& min, const Vec3& max, const Eigen::Matrix3d& rotation) {
  Shape s;
  s.kind_ = Kind::Box;
  s.a_ = min;
  s.b_ = max;
  s.rotation_ = rotation;
  s.rotated_ = !rotation.isIdentity(0.0);
  const Vec3 centre = 0.5 * (min + max), half = 0.5 * (max - min);
  // The rotated box's extent along each axis: |R| times the half-extents.
  const Vec3 reach = rotation.cwiseAbs() * half;
  s.bounds_ =
      s.rotated_ ? Eigen::AlignedBox3d(centre - reach, centre + reach) : Eigen::AlignedBox3d(min, max);
  return s;
}

Shape Shape::sphere(const Vec3& centre, double radius) {
  Shape s;
  s.kind_ = Kind::Sphere;
  s.a_ = centre;
  s.radius_ = radius;
  s.bounds_ = Eigen::AlignedBox3d(centre - Vec3::Constant(radius), centre + Vec3::Constant(radius));
  return s;
}

Shape Shape::cylinder(const Vec3& from, const Vec3& to, double radius) {
  Shape s;
  s.kind_ = Kind::Cylinder;
  s.a_ = from;
  s.b_ = to;
  s.radius_ = radius;
  const Vec3 reach = disc_half_extent((to - from).normalized(), radius);
  s.bounds_ = Eigen::AlignedBox3d(from.cwiseMin(to) - reach, from.cwiseMax(to) + reach);
  return s;
}

Shape Shape::cone(const Vec3& from, const Vec3& to, double radius) {
  Shape s = cylinder(from, to, radius);
  s.kind_ = Kind::Cone;
  const Vec3 reach = disc_half_extent((to - from).normalized(), radius);
  s.bounds_ = Eigen::AlignedBox3d(from - reach, from + reach).extend(to);
  return s;
}

Shape Shape::capsule(const Vec3& from, const Vec3& to, double radius) {
  Shape s = cylinder(from, to, radius);
  s.kind_ = Kind::Capsule;
  s.bounds_ = Eigen::AlignedBox3d(from.cwiseMin(to) - Vec3::Constant(radius),
                                  from.cwiseMax(to) + Vec3::Constant(radius));
  return s;
}

Shape Shape::mesh(TriangleSoup triangles) {
  // Triangles facing inwards enclose a negative volume and wind -1 around the inside.
  if (signed_volume(triangles) < 0.0)
    for (Triangle& t : triangles) std::swap(t.b, t.c);
  Shape s;
  s.kind_ = Kind::Mesh;
  s.mesh_ = std::make_shared<const WindingNumber>(std::move(triangles));
  s.bounds_ = s.mesh_->bounds();
  return s;
}

bool Shape::contains(const Vec3& p) const {
  if (!bounds_.contains(p)) return false;
  switch (kind_) {
    case Kind::Box: {
      if (!rotated_) return true;
      const Vec3 centre = 0.5 * (a_ + b_);
      const Vec3 local = centre + rotation_.transpose() * (p - centre);
      return (local.array() >= a_.array()).all() && (local.array() <= b_.array()).all();
    }
    case Kind::Sphere:
      return (p - a_).squaredNorm() <= radius_ * radius_;
    case Kind::Cylinder: {
      const AxisCoordinates c = axis_coordinates(a_, b_, p);
      return c.along >= 0.0 && c.along <= c.length && c.off2 <= radius_ * radius_;
    }
    case Kind::Cone: {
      const AxisCoordinates c = axis_coordinates(a_, b_, p);
      if (c.along < 0.0 || c.along > c.length) return false;
      const double r = radius_ * (1.0 - c.along / c.length);
      return c.off2 <= r * r;
    }
    case Kind::Capsule: {
      const AxisCoordinates c = axis_coordinates(a_, b_, p);
      const double beyond = c.along < 0.0 ? -c.along : c.along > c.length ? c.along - c.length : 0.0;
      return c.off2 + beyond * beyond <= radius_ * radius_;
    }
    case Kind::Mesh:
      return mesh_->inside(p);
  }
  return false;
}

std::vector<std::uint8_t> Shape::contains(const std::vector<Vec3>& points) const {
  std::vector<std::uint8_t> out(points.size(), 0);
  if (kind_ != Kind::Mesh) {
    for (std::size_t i = 0; i < points.size(); ++i) out[i] = contains(points[i]);
    return out;
  }
  // Only the points in the bounding box need the winding number.
  std::vector<std::size_t> candidates;
  std::vector<Vec3> near;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (bounds_.contains(points[i])) {
      candidates.push_back(i);
      near.push_back(points[i]);
    }
  }
  const std::vector<std::uint8_t> in = mesh_->inside(near);
  for (std::size_t k = 0; k < candidates.size(); ++k) out[candidates[k]] = in[k];
  return out;
}

double Shape::volume() const {
  const double length = (b_ - a_).norm();
  const double disc = M_PI * radius_ * radius_;
  switch (kind_) {
    case Kind::Box:
      return (b_ - a_).prod();
    case Kind::Sphere:
      return 4.0 / 3.0 * M_PI * radius_ * radius_ * radius_;
    case Kind::Cylinder:
      return disc * length;
    case Kind::Cone:
      return disc * length / 3.0;
    case Kind::Capsule:
      return disc * length + 4.0 / 3.0 * M_PI * radius_ * radius_ * radius_;
    case Kind::Mesh:
      return signed_volume(mesh_->mesh());
  }
  return 0.0;
}

}  // namespace thaw
