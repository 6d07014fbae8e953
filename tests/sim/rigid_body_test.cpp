// Rigid bodies from particles: mass properties against the analytic box, the integrator against exact
// motions (uniform acceleration, spin-up about a principal axis, torque-free rotation) and splitting.
#include "sim/rigid_body.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/error.h"

namespace thaw {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

struct Lattice {
  std::vector<Vec3> x;
  std::vector<double> m;
};

// nx × ny × nz particles at spacing dx, centres at origin + (i + 1/2) dx, each of mass rho dx³, then
// turned by `turn` about the origin.
Lattice box_lattice(Eigen::Array3i n, double dx, double rho = 917.0, const Vec3& origin = Vec3::Zero(),
                    const Mat3& turn = Mat3::Identity()) {
  Lattice l;
  for (int k = 0; k < n.z(); ++k)
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i) {
        l.x.push_back(turn * (origin + dx * Vec3(i + 0.5, j + 0.5, k + 0.5)));
        l.m.push_back(rho * dx * dx * dx);
      }
  return l;
}

// A tilted spin about body axis k of a 10 × 7 × 4 box, at 1 rev/s.
RigidBody spinning_box(int k, double tilt, MassProperties* out = nullptr) {
  const Lattice l = box_lattice({10, 7, 4}, 0.004);
  const MassProperties mp = mass_properties(l.x, l.m, 0.004);
  const Vec3 w =
      2 * std::numbers::pi *
      (std::cos(tilt) * Vec3::Unit(k) + std::sin(tilt) * (Vec3::Ones() - Vec3::Unit(k)) / std::sqrt(2.0));
  if (out) *out = mp;
  return rigid_body(mp, Vec3::Zero(), mp.axes * w);
}

double angle_between(const Vec3& u, const Vec3& v) { return std::atan2(u.cross(v).norm(), u.dot(v)); }

TEST(MassProperties, LatticeBoxHasTheBoxInertia) {
  // Each particle's own cube (m dx²/6) makes the lattice's inertia the box's exactly, not to O(dx²).
  const double dx = 0.002, rho = 917.0;
  const Vec3 origin(0.3, -0.1, 0.05);
  const Lattice l = box_lattice({20, 15, 8}, dx, rho, origin);
  const MassProperties mp = mass_properties(l.x, l.m, dx);
  const double a = 20 * dx, b = 15 * dx, c = 8 * dx, mass = rho * a * b * c;
  EXPECT_NEAR(mp.mass, mass, 1e-12 * mass);
  EXPECT_LT((mp.centre - (origin + 0.5 * Vec3(a, b, c))).norm(), 1e-14);
  // Ascending: the longest side (x) is the axis of least moment.
  const Vec3 expected = mass / 12 * Vec3(b * b + c * c, a * a + c * c, a * a + b * b);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(mp.moments[d], expected[d], 1e-12 * expected[d]) << d;
  EXPECT_LT((mp.axes - Mat3::Identity()).norm(), 1e-12);
  EXPECT_LT((mp.inertia - Mat3(expected.asDiagonal())).norm(), 1e-12 * expected.norm());
  // The offsets are the lattice about its centre.
  ASSERT_EQ(mp.offsets.size(), l.x.size());
  for (std::size_t i = 0; i < l.x.size(); i += 97)
    EXPECT_LT((mp.offsets[i] - (l.x[i] - mp.centre)).norm(), 1e-15);
}

TEST(MassProperties, RotatedBoxAxesRecoverTheRotation) {
  const Mat3 turn =
      (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()) * Eigen::AngleAxisd(-1.9, Vec3::UnitX()))
          .toRotationMatrix();
  const double dx = 0.003;
  const MassProperties flat =
      mass_properties(box_lattice({12, 9, 5}, dx).x, box_lattice({12, 9, 5}, dx).m, dx);
  const Lattice l = box_lattice({12, 9, 5}, dx, 917.0, Vec3(-0.01, 0.02, 0.2), turn);
  const MassProperties mp = mass_properties(l.x, l.m, dx);
  EXPECT_NEAR(mp.axes.determinant(), 1.0, 1e-12);
  EXPECT_LT((mp.axes.transpose() * mp.axes - Mat3::Identity()).norm(), 1e-12);
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(mp.moments[d], flat.moments[d], 1e-10 * flat.moments[d]);
    // The axis is the turned lattice axis, up to the sign convention.
    EXPECT_NEAR(std::abs(mp.axes.col(d).dot(turn.col(d))), 1.0, 1e-10) << d;
  }
  for (int d = 0; d < 2; ++d) {  // the sign convention: largest component positive
    Eigen::Index big;
    mp.axes.col(d).cwiseAbs().maxCoeff(&big);
    EXPECT_GT(mp.axes(big, d), 0.0);
  }
  // Each particle keeps its place: body offsets back to the world give the particle.
  for (std::size_t i = 0; i < l.x.size(); i += 31)
    EXPECT_LT((mp.centre + mp.axes * mp.offsets[i] - l.x[i]).norm(), 1e-14);
  // The offsets are the flat box's, up to the axes' signs.
  const Mat3 signs = (mp.axes.transpose() * turn).array().round().matrix();
  for (std::size_t i = 0; i < l.x.size(); i += 31)
    EXPECT_LT((mp.offsets[i] - signs * flat.offsets[i]).norm(), 1e-14);
}

TEST(MassProperties, DegenerateMomentsTakeTheWorldAxes) {
  const double dx = 0.01;
  const Lattice cube = box_lattice({6, 6, 6}, dx);
  EXPECT_LT((mass_properties(cube.x, cube.m, dx).axes - Mat3::Identity()).norm(), 1e-12);
  // A square section: x is the distinct (least) axis, y and z are taken as they are.
  const Lattice rod = box_lattice({12, 4, 4}, dx);
  const MassProperties mp = mass_properties(rod.x, rod.m, dx);
  EXPECT_LT((mp.axes - Mat3::Identity()).norm(), 1e-12);
  // One particle: a cube of side dx about its own centre.
  const std::vector<Vec3> one = {Vec3(1, 2, 3)};
  const std::vector<double> m1 = {2.0};
  const MassProperties single = mass_properties(one, m1, dx);
  EXPECT_NEAR(single.moments[0], 2.0 * dx * dx / 6, 1e-18);
  EXPECT_EQ(single.centre, Vec3(1, 2, 3));
}

TEST(MassProperties, RefusesWhatHasNoMass) {
  const std::vector<Vec3> x = {Vec3::Zero(), Vec3::Ones()};
  const std::vector<double> m = {1.0, 0.0}, m1 = {1.0};
  EXPECT_THROW(mass_properties({}, {}, 0.01), Error);
  EXPECT_THROW(mass_properties(x, m1, 0.01), Error);
  EXPECT_THROW(mass_properties(x, m, 0.01), Error);
  EXPECT_THROW(mass_properties(x, std::vector<double>{1.0, 1.0}, 0.0), Error);
}

TEST(RigidBody, ConstantForceMovesAsUniformAcceleration) {
  MassProperties mp;
  RigidBody body = spinning_box(0, 0.3, &mp);
  body.velocity = Vec3(0.4, -0.2, 1.5);
  const Vec3 x0 = body.position, v0 = body.velocity, force(0.0, 0.3, -9.81 * body.mass);
  const double dt = 1e-3;
  const int steps = 2000;
  for (int s = 0; s < steps; ++s) advance(body, force, Vec3::Zero(), dt);
  const double t = steps * dt;
  const Vec3 x = x0 + v0 * t + force * t * t / (2 * body.mass), v = v0 + force * t / body.mass;
  EXPECT_LT((body.position - x).norm(), 1e-13 * (1 + x.norm()));
  EXPECT_LT((body.velocity - v).norm(), 1e-13 * v.norm());
}

TEST(RigidBody, ConstantTorqueAboutAPrincipalAxisSpinsItUp) {
  for (int k = 0; k < 3; ++k) {
    MassProperties mp;
    RigidBody body = spinning_box(k, 0.0, &mp);
    body.angular_momentum.setZero();
    const Vec3 axis = body.rotation().col(k), start = body.rotation().col((k + 1) % 3);
    const double tau = 2e-5, dt = 1e-3;
    const int steps = 1500;
    for (int s = 0; s < steps; ++s) advance(body, Vec3::Zero(), tau * axis, dt);
    const double t = steps * dt;
    const Vec3 w = body.angular_velocity();
    EXPECT_NEAR(w.dot(axis), tau * t / mp.moments[k], 1e-12 * tau * t / mp.moments[k]) << k;
    EXPECT_LT((w - w.dot(axis) * axis).norm(), 1e-12 * w.norm()) << k;
    // Turned by ∫ω dt = τ t²/(2I) about the fixed axis (modulo 2π).
    const double angle = tau * t * t / (2 * mp.moments[k]);
    const Vec3 now = body.rotation().col((k + 1) % 3);
    const double turned = std::atan2(axis.dot(start.cross(now)), start.dot(now));
    EXPECT_NEAR(turned, std::remainder(angle, 2 * std::numbers::pi), 1e-9) << k;
  }
}

TEST(RigidBody, TorqueFreeRotationKeepsLAndBoundsTheEnergy) {
  // A generic tumble: L far from every axis.
  MassProperties mp;
  RigidBody body = spinning_box(0, 0.0, &mp);
  body.angular_momentum = mp.axes * mp.moments.cwiseProduct(2 * std::numbers::pi * Vec3(1.0, 0.7, -0.5));
  const Vec3 l0 = body.angular_momentum;
  const double e0 = body.kinetic_energy(), dt = 1e-3;
  double worst_first = 0, worst_last = 0;
  const int steps = 40000;  // ~40 turns
  for (int s = 0; s < steps; ++s) {
    advance(body, Vec3::Zero(), Vec3::Zero(), dt);
    double& worst = s < steps / 2 ? worst_first : worst_last;
    worst = std::max(worst, std::abs(body.kinetic_energy() - e0) / e0);
  }
  EXPECT_EQ(body.angular_momentum, l0);  // torque-free steps never touch the world L
  // L seen from the body, which turns: |Rᵀ L| stays |L| up to the quaternion's round-off.
  EXPECT_NEAR((body.orientation.conjugate() * body.angular_momentum).norm(), l0.norm(), 1e-13 * l0.norm());
  EXPECT_NEAR(body.orientation.norm(), 1.0, 1e-15);
  // Bounded, O((ω dt)²), and no drift: the second half of the run is no worse than the first.
  EXPECT_LT(worst_first, 3e-6);  // 1.0e-6 measured at ω dt = 8e-3
  EXPECT_LT(worst_last, 1.5 * worst_first);
}

TEST(RigidBody, StepsRunBackwardsToTheStart) {
  RigidBody body = spinning_box(1, 0.2);
  body.velocity = Vec3(0.1, 0.2, 0.3);
  const RigidBody start = body;
  const Vec3 f(0.01, 0.0, -0.02), tau(1e-6, -2e-6, 5e-7);
  for (int s = 0; s < 500; ++s) advance(body, f, tau, 2e-3);
  for (int s = 0; s < 500; ++s) advance(body, f, tau, -2e-3);
  EXPECT_LT((body.position - start.position).norm(), 1e-13);
  EXPECT_LT((body.velocity - start.velocity).norm(), 1e-13);
  EXPECT_LT(body.orientation.angularDistance(start.orientation), 1e-11);
  EXPECT_LT((body.angular_momentum - start.angular_momentum).norm(), 1e-13 * start.angular_momentum.norm());
}

TEST(RigidBody, IntermediateAxisFlipsWhileTheOthersStay) {
  const double tilt = 0.01, dt = 5e-4;
  for (int k = 0; k < 3; ++k) {
    RigidBody body = spinning_box(k, tilt);
    const Vec3 axis0 = body.rotation().col(k);
    double wander = 0;
    for (int s = 0; s < 20000; ++s) {  // 10 turns
      advance(body, Vec3::Zero(), Vec3::Zero(), dt);
      wander = std::max(wander, angle_between(body.rotation().col(k), axis0));
    }
    if (k == 1)
      EXPECT_GT(wander, 0.9 * std::numbers::pi) << "the intermediate axis turns over";
    else
      EXPECT_LT(wander, 6 * tilt) << "axis " << k << " is stable";
  }
}

TEST(RigidBody, FixedBodyStaysPut) {
  RigidBody body = spinning_box(2, 0.1);
  body.velocity = Vec3(1, 2, 3);
  body.fixed = true;
  const RigidBody start = body;
  for (int s = 0; s < 100; ++s) advance(body, Vec3(5, 5, 5), Vec3(1, 1, 1), 1e-3);
  EXPECT_EQ(body.position, start.position);
  EXPECT_EQ(body.orientation.coeffs(), start.orientation.coeffs());
  EXPECT_EQ(body.velocity_at(body.position + Vec3(0.01, 0.02, 0.0)), Vec3::Zero());
  EXPECT_EQ(body.kinetic_energy(), 0.0);
}

TEST(RigidBody, ChildrenCarryOnTheParentsMotionAndMergeBack) {
  const double dx = 0.004;
  const Lattice l = box_lattice({10, 7, 4}, dx, 917.0, Vec3(0.1, 0.0, 0.0));
  const MassProperties mp = mass_properties(l.x, l.m, dx);
  RigidBody parent = rigid_body(mp, Vec3(0.2, -0.1, 0.05), Vec3(1.0, -3.0, 2.0));
  for (int s = 0; s < 50; ++s)
    advance(parent, Vec3::Zero(), Vec3::Zero(), 1e-3);  // turned off the lattice axes
  // Melting cuts it across its body x axis: each half from its particles where they are now.
  Lattice half[2];
  for (std::size_t i = 0; i < l.x.size(); ++i) {
    const int side = mp.offsets[i].x() < 0 ? 0 : 1;
    half[side].x.push_back(parent.to_world(mp.offsets[i]));
    half[side].m.push_back(l.m[i]);
  }
  RigidBody child[2];
  Vec3 momentum = Vec3::Zero(), l_total = Vec3::Zero();
  double energy = 0;
  for (int c = 0; c < 2; ++c) {
    const MassProperties cm = mass_properties(half[c].x, half[c].m, dx);
    child[c] = child_of(parent, cm);
    for (std::size_t i = 0; i < half[c].x.size(); ++i) {
      const Vec3 x = child[c].to_world(cm.offsets[i]);
      EXPECT_LT((x - half[c].x[i]).norm(), 1e-15);
      EXPECT_LT((child[c].velocity_at(x) - parent.velocity_at(x)).norm(), 1e-13);
    }
    momentum += child[c].mass * child[c].velocity;
    l_total += child[c].angular_momentum +
               child[c].mass * (child[c].position - parent.position).cross(child[c].velocity);
    energy += child[c].kinetic_energy();
  }
  EXPECT_LT((momentum - parent.mass * parent.velocity).norm(), 1e-14);
  EXPECT_LT((l_total - parent.angular_momentum).norm(), 1e-12 * parent.angular_momentum.norm());
  EXPECT_NEAR(energy, parent.kinetic_energy(), 1e-12 * parent.kinetic_energy());
  // Joined again, they are the parent.
  std::vector<Vec3> all_x = half[0].x;
  std::vector<double> all_m = half[0].m;
  all_x.insert(all_x.end(), half[1].x.begin(), half[1].x.end());
  all_m.insert(all_m.end(), half[1].m.begin(), half[1].m.end());
  const RigidBody joined = merge(child[0], child[1], mass_properties(all_x, all_m, dx));
  EXPECT_LT((joined.position - parent.position).norm(), 1e-15);
  EXPECT_LT((joined.velocity - parent.velocity).norm(), 1e-14);
  EXPECT_LT((joined.angular_velocity() - parent.angular_velocity()).norm(),
            1e-12 * parent.angular_velocity().norm());
}

}  // namespace
}  // namespace thaw
