#include "sim/rigid_body.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "sim/error.h"

namespace thaw {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Moments closer than this (relative to the largest) count as equal, and their axes are then chosen
// instead of taken from the eigensolver, whose basis of a degenerate subspace is arbitrary. Particle
// positions are single precision on the device, so a lattice cube's moments already differ by ~1e-7.
constexpr double kDegenerate = 1e-6;

// Flips u so that its component of largest magnitude is positive (the first one on a tie).
Vec3 canonical_sign(const Vec3& u) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(u[i]) > std::abs(u[k])) k = i;
  return u[k] < 0 ? Vec3(-u) : u;
}

// The unit vector orthogonal to u closest to a world axis: that axis (the one u leans on least) with its
// u component removed.
Vec3 in_plane_axis(const Vec3& u) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(u[i]) < std::abs(u[k])) k = i;
  const Vec3 e = Vec3::Unit(k);
  return (e - u[k] * u).normalized();
}

// Principal axes of a symmetric inertia tensor as the columns of a rotation, in ascending order of moment.
Mat3 principal_axes(const Mat3& inertia) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(inertia);
  const Vec3 lambda = eig.eigenvalues();
  const Mat3 v = eig.eigenvectors();
  const double tol = kDegenerate * std::abs(lambda[2]);
  const bool low_pair = lambda[1] - lambda[0] <= tol, high_pair = lambda[2] - lambda[1] <= tol;
  Mat3 a;
  if (low_pair && high_pair) {
    a.setIdentity();
  } else if (low_pair) {
    const Vec3 u = canonical_sign(v.col(2));
    a.col(0) = in_plane_axis(u);
    a.col(1) = u.cross(a.col(0));
    a.col(2) = u;
  } else if (high_pair) {
    const Vec3 u = canonical_sign(v.col(0));
    a.col(0) = u;
    a.col(1) = in_plane_axis(u);
    a.col(2) = u.cross(a.col(1));
  } else {
    a.col(0) = canonical_sign(v.col(0));
    a.col(1) = canonical_sign(v.col(1));
    a.col(2) = a.col(0).cross(a.col(1));
  }
  return a;
}

// A rotation by `angle` about a body axis, applied on the body side of a body → world quaternion.
Eigen::Quaterniond body_axis_turn(int axis, double angle) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Vec3::Unit(axis)));
}

}  // namespace

MassProperties mass_properties(std::span<const Eigen::Vector3d> positions, std::span<const double> masses,
                               double dx) {
  if (positions.empty()) throw Error("mass_properties: no particles");
  if (positions.size() != masses.size())
    throw Error("mass_properties: " + std::to_string(positions.size()) + " positions but " +
                std::to_string(masses.size()) + " masses");
  if (!(dx > 0)) throw Error("mass_properties: particle spacing must be positive");
  MassProperties mp;
  // Centre first, then the inertia about it: summing m x xᵀ about the origin and shifting afterwards
  // would cancel digits when the body sits far from the origin.
  Vec3 first_moment = Vec3::Zero();
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!(masses[i] > 0))
      throw Error("mass_properties: particle " + std::to_string(i) + " has mass " +
                  std::to_string(masses[i]));
    mp.mass += masses[i];
    first_moment += masses[i] * positions[i];
  }
  mp.centre = first_moment / mp.mass;
  // I = Σ m (|r|² 1 - r rᵀ) + Σ m dx²/6 1: point masses plus each particle's own cube.
  Mat3 second = Mat3::Zero();  // Σ m r rᵀ
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Vec3 r = positions[i] - mp.centre;
    second.noalias() += masses[i] * r * r.transpose();
  }
  mp.inertia = (second.trace() + mp.mass * dx * dx / 6.0) * Mat3::Identity() - second;
  mp.axes = principal_axes(mp.inertia);
  mp.moments = (mp.axes.transpose() * mp.inertia * mp.axes).diagonal();
  mp.offsets.resize(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i)
    mp.offsets[i] = mp.axes.transpose() * (positions[i] - mp.centre);
  return mp;
}

Eigen::Matrix3d RigidBody::inverse_inertia_world() const {
  const Mat3 r = rotation();
  return r * moments.cwiseInverse().asDiagonal() * r.transpose();
}

Eigen::Matrix3d RigidBody::inertia_world() const {
  const Mat3 r = rotation();
  return r * moments.asDiagonal() * r.transpose();
}

Eigen::Vector3d RigidBody::angular_velocity() const {
  // ω = R I⁻¹ Rᵀ L, through the body frame where I is diagonal.
  const Vec3 body_l = orientation.conjugate() * angular_momentum;
  return orientation * body_l.cwiseQuotient(moments);
}

double RigidBody::kinetic_energy() const {
  return 0.5 * mass * velocity.squaredNorm() + 0.5 * angular_momentum.dot(angular_velocity());
}

Eigen::Vector3d RigidBody::to_world(const Eigen::Vector3d& body_offset) const {
  return position + orientation * body_offset;
}

Eigen::Vector3d RigidBody::velocity_at(const Eigen::Vector3d& world_point) const {
  return velocity + angular_velocity().cross(world_point - position);
}

RigidBody rigid_body(const MassProperties& mp, const Eigen::Vector3d& velocity,
                     const Eigen::Vector3d& angular_velocity) {
  RigidBody b;
  b.mass = mp.mass;
  b.moments = mp.moments;
  b.position = mp.centre;
  b.velocity = velocity;
  b.orientation = Eigen::Quaterniond(mp.axes).normalized();
  b.angular_momentum = mp.inertia * angular_velocity;
  return b;
}

void kick(RigidBody& body, const Eigen::Vector3d& force, const Eigen::Vector3d& torque, double h) {
  if (body.fixed) {
    body.velocity.setZero();
    body.angular_momentum.setZero();
    return;
  }
  body.velocity += (h / body.mass) * force;
  body.angular_momentum += h * torque;
}

void free_rotation(RigidBody& body, double h) {
  // Each sub-flow turns the body about its axis k at the rate L_k / I_k, where L_k = (Rᵀ L)_k is constant
  // along that flow (it is the component along the turning axis), so each sub-step is exact.
  auto turn = [&body](int k, double step) {
    const Vec3 body_l = body.orientation.conjugate() * body.angular_momentum;
    body.orientation = body.orientation * body_axis_turn(k, step * body_l[k] / body.moments[k]);
  };
  turn(0, 0.5 * h);
  turn(1, 0.5 * h);
  turn(2, h);
  turn(1, 0.5 * h);
  turn(0, 0.5 * h);
  body.orientation.normalize();
}

void drift(RigidBody& body, double h) {
  if (body.fixed) return;
  body.position += h * body.velocity;
  free_rotation(body, h);
}

void advance(RigidBody& body, const Eigen::Vector3d& force, const Eigen::Vector3d& torque, double dt) {
  kick(body, force, torque, 0.5 * dt);
  drift(body, dt);
  kick(body, force, torque, 0.5 * dt);
}

RigidBody child_of(const RigidBody& parent, const MassProperties& child) {
  const Vec3 omega = parent.angular_velocity();
  RigidBody c = rigid_body(child, parent.velocity_at(child.centre), omega);
  c.fixed = parent.fixed;
  if (c.fixed) c.velocity.setZero(), c.angular_momentum.setZero();
  return c;
}

RigidBody merge(const RigidBody& a, const RigidBody& b, const MassProperties& joined) {
  RigidBody m = rigid_body(joined);
  m.fixed = a.fixed || b.fixed;
  if (m.fixed) return m;
  const Vec3 momentum = a.mass * a.velocity + b.mass * b.velocity;
  m.velocity = momentum / joined.mass;
  // L about the joined centre: each body's spin plus the orbital part of its centre's motion.
  m.angular_momentum = a.angular_momentum + b.angular_momentum +
                       a.mass * (a.position - joined.centre).cross(a.velocity) +
                       b.mass * (b.position - joined.centre).cross(b.velocity);
  return m;
}

}  // namespace thaw
