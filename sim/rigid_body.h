#pragma once
// Ice objects as rigid bodies (Iwasaki et al. 2010, §5): a body moves as a whole under the sum of the
// forces on its particles and the sum of their torques about its centre of mass, carrying its angular
// momentum L and turning with ω = I⁻¹ L. Host-side, double precision: a scene holds a handful of bodies.
//
// The body frame is the principal frame, so the inertia tensor is three numbers and the particles keep
// fixed offsets in it. Bodies are built from their particles (mass_properties), advanced by a symplectic
// splitting (advance), and split or merged when melting cuts an object in two or freezing joins two.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>
#include <vector>

namespace thaw {

// What a set of particles weighs and how it resists turning. Each particle is a uniform cube of side dx,
// so besides the point-mass term it adds its own m dx²/6 to each diagonal entry: a lattice of such cubes
// that tiles a box has exactly the box's inertia.
struct MassProperties {
  double mass = 0.0;                                  // [kg]
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();   // centre of mass, world [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the centre, world axes [kg m²]
  // Principal moments [kg m²], ascending (body axis 0 turns most easily; moments within 1e-6 of the
  // largest count as equal and may come in either order), and the principal axes as the
  // columns of a rotation (det +1): body → world. Each of axes 0 and 1 points so that its component of
  // largest magnitude is positive; axis 2 = axis 0 × axis 1. Within a degenerate pair (a square section)
  // or triple (a cube) of moments, the axes are the ones closest to the world axes.
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Vector3d> offsets;  // each particle's x - centre, in the body frame [m]
};

// Throws Error when there are no particles, the sizes differ, a mass is not positive or dx is not.
MassProperties mass_properties(std::span<const Eigen::Vector3d> positions, std::span<const double> masses,
                               double dx);

// A rigid body: its state is the centre of mass, the linear velocity, the orientation and the angular
// momentum. L rather than ω is the state because L is what torques change and what torque-free motion
// keeps; ω follows from it.
struct RigidBody {
  double mass = 0.0;                                                // [kg]
  Eigen::Vector3d moments = Eigen::Vector3d::Ones();                // principal moments, body frame [kg m²]
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               // centre of mass, world [m]
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();               // of the centre of mass, world [m/s]
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // unit, body → world
  Eigen::Vector3d angular_momentum = Eigen::Vector3d::Zero();       // about the centre, world [kg m²/s]
  // Held in place (an ice object frozen to a wall): advance() and drift() neither move nor turn it, and
  // kick() zeroes its momenta, so the velocity field it shows the fluid is zero.
  bool fixed = false;

  Eigen::Matrix3d rotation() const { return orientation.toRotationMatrix(); }
  // R I⁻¹ Rᵀ and R I Rᵀ: the inertia tensor and its inverse in world axes.
  Eigen::Matrix3d inverse_inertia_world() const;
  Eigen::Matrix3d inertia_world() const;
  Eigen::Vector3d angular_velocity() const;  // ω = R I⁻¹ Rᵀ L [rad/s]
  double kinetic_energy() const;             // ½ M |V|² + ½ L · ω [J]
  // Where a body-frame offset sits in the world, and the rigid velocity V + ω × (x - c) at a world point.
  Eigen::Vector3d to_world(const Eigen::Vector3d& body_offset) const;
  Eigen::Vector3d velocity_at(const Eigen::Vector3d& world_point) const;
};

// A body in the pose of its particles (orientation = principal axes), moving with `velocity` and
// turning with `angular_velocity` (world), so L = I ω.
RigidBody rigid_body(const MassProperties& mp, const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero(),
                     const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero());

// One step of dt under a force on the centre of mass and a torque about it (world), both held over the
// step: a half kick of P and L, a torque-free drift (translation and free rotation), a half kick. Under a
// constant force the centre moves exactly as x0 + V t + F t²/(2M), and the step is symplectic and
// time-reversible (advance by dt, then by -dt, returns to the start up to round-off).
//
// Why not the paper's update (L += T dt, ω = I⁻¹ L, turn by ω dt): turning by ω dt while ω stays fixed is
// explicit Euler on the free-rotation flow, in which ω and the body axes drift apart; a torque-free body
// then gains or loses energy every step and an ice block spun about a stable axis slowly tumbles (a
// tumbling 4 × 2.8 × 1.6 cm block at ω dt = 8e-3: 29 % of its energy in 40 turns). The splitting below
// keeps |L| exactly and the energy within an O(dt²) band with no drift (1e-6 for that block).
void advance(RigidBody& body, const Eigen::Vector3d& force, const Eigen::Vector3d& torque, double dt);

// The parts of advance(), for a caller whose forces depend on the particles' positions (velocity
// Verlet): kick(F(x_n), dt/2), drift(dt), compute F(x_n+1), kick(F(x_n+1), dt/2).
void kick(RigidBody& body, const Eigen::Vector3d& force, const Eigen::Vector3d& torque, double h);
void drift(RigidBody& body, double h);

// Torque-free rotation over h by the splitting of Dullweber, Leimkuhler & McLachlan (1997, J. Chem. Phys.
// 107, 5840): the kinetic energy Σ L_k²/(2 I_k) is split into its three principal terms, whose flows are
// exact rotations about one body axis at the rate L_k / I_k, composed symmetrically as 1:h/2, 2:h/2,
// 3:h, 2:h/2, 1:h/2 (axis 2, the largest moment, in the middle). World L is not touched, so |L| is kept
// exactly; the composition is symplectic and symmetric, so the energy error stays bounded.
void free_rotation(RigidBody& body, double h);

// When melting cuts a body in two: a piece with its own mass properties (computed from its particles at
// their current positions) that carries on the parent's rigid motion. Its centre moves with the parent's
// velocity field, V + ω × (c_child - c_parent); it turns with the parent's ω, so L_child = I_child ω.
// Both pieces together keep the parent's momentum and angular momentum (and energy) exactly.
RigidBody child_of(const RigidBody& parent, const MassProperties& child);

// When two bodies join: one body with the union's mass properties that keeps the total momentum and the
// total angular momentum about the union's centre of mass (an inelastic joining: energy is not kept
// unless the two moved as one rigid body).
RigidBody merge(const RigidBody& a, const RigidBody& b, const MassProperties& joined);

}  // namespace thaw
