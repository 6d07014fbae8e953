// Torque-free spin of an ice box (the tennis-racket, or Dzhanibekov, experiment): the rigid-body dynamics
// of sim/rigid_body.h alone, no fluid. An a × b × c ice block is sampled into particles as any scene's
// ice is (res = particles along the longest side), its mass properties come from those particles, and it
// is spun about one principal axis, tilted by a small angle, for a number of revolutions.
// References, all from the parameters:
//  - the box's principal moments M (b² + c²)/12, ... (the lattice of particle cubes tiles the box, so the
//    particles' inertia is the box's up to round-off);
//  - |L| and the kinetic energy are constant; both are measured from the particles' rigid velocity field
//    (so the body frame, the offsets and the moments must agree), as drift per revolution and as the
//    largest excursion;
//  - the polhode period 4 K(k) / ω_p of Euler's equations (Landau & Lifshitz, Mechanics §37), measured as
//    the time between sign changes of L along the intermediate body axis;
//  - about the min or max axis the spin is stable: the axis stays within θ_max + θ_0 of where it started,
//    θ_0 the initial angle between L and the axis, θ_max the largest one that conservation of E and |L|
//    allows; about the intermediate axis it is unstable and the axis turns over (beyond 90°, towards 180°).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include "sim/error.h"
#include "sim/rigid_body.h"
#include "sim/solver.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

using Vec3 = Eigen::Vector3d;

Field params() {
  return object(
      "",
      {
          number("a", "Box side along x").in("m").def(0.04).above(0),
          number("b", "Box side along y").in("m").def(0.03).above(0),
          number("c", "Box side along z (the three sides must differ)").in("m").def(0.02).above(0),
          number("density", "Ice density").in("kg/m^3").def(917.0).above(0),
          choice("axis", {"min", "intermediate", "max"}, "Principal axis (by moment of inertia) spun about")
              .def("min"),
          number("spin", "Spin rate about the axis").in("rev/s").def(1.0).above(0),
          number("perturbation",
                 "Tilt of the initial angular velocity from the axis, towards the bisector of "
                 "the other two")
              .in("rad")
              .def(0.01)
              .above(0)
              .below(0.5),
          number("revolutions", "Run length in revolutions at the spin rate").def(20.0).above(0),
          number("dt", "Time step; the default gives ω dt = 2π × 2.5e-4 = 1.6e-3 rad at 1 rev/s")
              .in("s")
              .def(2.5e-4)
              .above(0),
          number("conservation_gate",
                 "Gate on the relative drift of |L| and energy per revolution, and on their "
                 "largest relative excursion")
              .def(1e-6)
              .above(0),
          number("inertia_gate", "Gate on the principal moments' relative error against the box's")
              .def(1e-6)
              .above(0),
          number("period_gate", "Gate on the polhode period's relative error").def(1e-4).above(0),
          number("wander_gate",
                 "min and max axes: gate on the axis' largest angle from its start over the bound "
                 "that conservation of energy and |L| allows")
              .def(1.01)
              .above(0),
      });
}

int axis_index(const std::string& axis) { return axis == "min" ? 0 : axis == "intermediate" ? 1 : 2; }

// An ice block filling [0, box] sampled as a scene samples it: particle masses and positions as the
// engine holds them.
HostParticles ice_box_particles(const Vec3& box, double dx, double density) {
  const Json corner = {box.x(), box.y(), box.z()};
  const Json doc = {
      {"name", "validation/rigid-spin"},
      {"domain", {{"min", {-dx, -dx, -dx}}, {"max", {box.x() + dx, box.y() + dx, box.z() + dx}}}},
      {"gravity", {0, 0, 0}},
      {"spacing", dx},
      {"materials",
       {{"water",
         {{"kind", "fluid"}, {"density", density}, {"conductivity", 0.56}, {"specific_heat", 4217.0}}},
        {"ice",
         {{"kind", "ice"},
          {"density", density},
          {"conductivity", 2.22},
          {"specific_heat", 2050.0},
          {"melts_into", "water"}}}}},
      {"ice",
       {{{"material", "ice"}, {"box", {{"min", {0.0, 0.0, 0.0}}, {"max", corner}}}, {"temperature", -5.0}}}},
  };
  return sample_scene(scene_from_json(doc));
}

// Period of the torque-free motion with principal moments I (ascending), angular momentum M² and energy
// 2E (Landau & Lifshitz §37): with A = (I2 - I1)(2E I3 - M²) and B = (I3 - I2)(M² - 2E I1),
// ω_p² = max(A, B) / (I1 I2 I3), k² = min(A, B) / max(A, B), period 4 K(k) / ω_p. The body components
// of L along the intermediate axis go as sn(ω_p t, k), changing sign every 2 K / ω_p.
double polhode_period(const Vec3& inertia, const Vec3& body_l) {
  const double m2 = body_l.squaredNorm(), two_e = body_l.cwiseAbs2().cwiseQuotient(inertia).sum();
  const double i1 = inertia[0], i2 = inertia[1], i3 = inertia[2];
  const double a = (i2 - i1) * (two_e * i3 - m2), b = (i3 - i2) * (m2 - two_e * i1);
  const double hi = std::max(a, b), lo = std::min(a, b);
  const double k = std::sqrt(lo / hi);
  if (!(k < 1.0 - 1e-12))
    throw SceneError("perturbation", "puts the spin on the separatrix, where the polhode period is infinite");
  return 4.0 * std::comp_ellint_1(k) / std::sqrt(hi / (i1 * i2 * i3));
}

// About a stable axis k: the largest angle between L and the axis that the conserved
// 2E - M²/I_k = Σ_{m≠k} L_m² (1/I_m - 1/I_k) allows, plus the initial one; every term of the sum has
// the same sign, so the largest L_⊥² is the sum over the smaller coefficient.
double wander_bound(const Vec3& inertia, const Vec3& body_l, int k) {
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  const double di = std::abs(1 / inertia[i] - 1 / inertia[k]), dj = std::abs(1 / inertia[j] - 1 / inertia[k]);
  const double c = body_l[i] * body_l[i] * di + body_l[j] * body_l[j] * dj;
  const double perp_max = std::sqrt(c / std::min(di, dj)), m = body_l.norm();
  const double theta_max = std::asin(std::min(1.0, perp_max / m));
  const double theta_0 = std::atan2(std::hypot(body_l[i], body_l[j]), std::abs(body_l[k]));
  return theta_max + theta_0;
}

double angle_between(const Vec3& u, const Vec3& v) { return std::atan2(u.cross(v).norm(), u.dot(v)); }

CaseResult run(ClRuntime&, const Json& prm, int res) {
  const auto t0 = std::chrono::steady_clock::now();
  const Vec3 sides(prm["a"], prm["b"], prm["c"]);
  const double rho = prm["density"], eps = prm["perturbation"], dt = prm["dt"];
  const double spin = prm["spin"], revolutions = prm["revolutions"];
  const int k = axis_index(prm["axis"]);
  for (int d = 1; d < 3; ++d)
    for (int e = 0; e < d; ++e)
      if (sides[d] == sides[e])
        throw SceneError(std::string(1, "abc"[d]), "equals side " + std::string(1, "abc"[e]) +
                                                       ": equal moments have no distinct principal axes");

  // A whole number of spacings along each side, as in the hydrostatic case, so the particle cubes tile
  // the box that the reference describes.
  const double dx = sides.maxCoeff() / res;
  Eigen::Array3i n;
  for (int d = 0; d < 3; ++d) n[d] = std::max(1, static_cast<int>(std::lround(sides[d] / dx)));
  if (n[0] == n[1] || n[1] == n[2] || n[0] == n[2])
    throw Error("rigid-spin: at --res " + std::to_string(res) + " the sides round to " +
                std::to_string(n[0]) + " x " + std::to_string(n[1]) + " x " + std::to_string(n[2]) +
                " particles, which ties two moments: raise --res");
  const Vec3 box = n.cast<double>().matrix() * dx;
  const HostParticles p = ice_box_particles(box, dx, rho);
  std::vector<Vec3> x(p.size());
  std::vector<double> m(p.size());
  for (std::size_t q = 0; q < p.size(); ++q) {
    x[q] = Vec3(p.position[q][0], p.position[q][1], p.position[q][2]);
    m[q] = p.position[q][3];
  }
  const MassProperties mp = mass_properties(x, m, dx);

  // The reference moments of the box, ascending like the body frame.
  const double mass_ref = rho * box.prod();
  Vec3 moments_ref =
      (mass_ref / 12.0) * Vec3(box[1] * box[1] + box[2] * box[2], box[0] * box[0] + box[2] * box[2],
                               box[0] * box[0] + box[1] * box[1]);
  std::sort(moments_ref.data(), moments_ref.data() + 3);
  MetricResult moments{0, 0, -1, prm["inertia_gate"]};
  for (int d = 0; d < 3; ++d) {
    const double err = std::abs(mp.moments[d] - moments_ref[d]) / moments_ref[d];
    if (err > moments.error) moments = {mp.moments[d], moments_ref[d], err, moments.gate};
  }

  // Spin about body axis k, tilted by eps towards the bisector of the other two.
  const double omega = 2 * std::numbers::pi * spin;
  const Vec3 tilt = (Vec3::Ones() - Vec3::Unit(k)) / std::sqrt(2.0);
  const Vec3 omega_body = omega * (std::cos(eps) * Vec3::Unit(k) + std::sin(eps) * tilt);
  RigidBody body = rigid_body(mp, Vec3::Zero(), mp.axes * omega_body);
  const Vec3 l_body_ref = moments_ref.cwiseProduct(omega_body);
  const double period_ref = polhode_period(moments_ref, l_body_ref);

  // |L| and the kinetic energy of the particles moving with the body: Σ m r × (ω × r) and ½ Σ m |ω × r|²,
  // plus each particle cube's own spin.
  double own = 0;
  for (double mq : m) own += mq * dx * dx / 6.0;
  auto particle_momenta = [&](double& l_norm, double& energy) {
    const Eigen::Matrix3d r = body.rotation();
    const Vec3 w = body.angular_velocity();
    Vec3 l = own * w;
    double two_e = own * w.squaredNorm();
    for (std::size_t q = 0; q < x.size(); ++q) {
      const Vec3 rq = r * mp.offsets[q], v = w.cross(rq);
      l += m[q] * rq.cross(v);
      two_e += m[q] * v.squaredNorm();
    }
    l_norm = l.norm();
    energy = 0.5 * two_e;
  };
  double l0 = 0, e0 = 0;
  particle_momenta(l0, e0);
  const Vec3 axis0 = body.rotation().col(k);
  const auto steps = static_cast<std::uint64_t>(std::max(1.0, std::ceil(revolutions / spin / dt - 1e-9)));
  double l_worst = l0, e_worst = e0, l_end = l0, e_end = e0, wander = 0;
  // Sign changes of L along the intermediate body axis: the first and last times, and how many.
  double prev_l1 = (body.orientation.conjugate() * body.angular_momentum)[1], first_cross = 0, last_cross = 0;
  long crossings = 0;
  for (std::uint64_t s = 1; s <= steps; ++s) {
    advance(body, Vec3::Zero(), Vec3::Zero(), dt);
    particle_momenta(l_end, e_end);
    if (std::abs(l_end - l0) > std::abs(l_worst - l0)) l_worst = l_end;
    if (std::abs(e_end - e0) > std::abs(e_worst - e0)) e_worst = e_end;
    wander = std::max(wander, angle_between(body.rotation().col(k), axis0));
    const double l1 = (body.orientation.conjugate() * body.angular_momentum)[1];
    if ((l1 < 0) != (prev_l1 < 0)) {
      const double t = (double(s) - 1 + prev_l1 / (prev_l1 - l1)) * dt;
      if (crossings++ == 0) first_cross = t;
      last_cross = t;
    }
    prev_l1 = l1;
  }
  const double revs_run = double(steps) * dt * spin;
  const double cons_gate = prm["conservation_gate"];
  // Two sign changes are half a period apart; fewer than two in the run measure nothing and fail.
  const double period = crossings >= 2 ? 2.0 * (last_cross - first_cross) / double(crossings - 1) : 0.0;

  CaseResult r;
  r.particles = p.size();
  r.steps = steps;
  r.metrics = {
      {"principal_moments", moments},
      {"angular_momentum_drift", {l_end, l0, std::abs(l_end - l0) / l0 / revs_run, cons_gate}},
      {"angular_momentum_oscillation", {l_worst, l0, std::abs(l_worst - l0) / l0, cons_gate}},
      {"energy_drift", {e_end, e0, std::abs(e_end - e0) / e0 / revs_run, cons_gate}},
      {"energy_oscillation", {e_worst, e0, std::abs(e_worst - e0) / e0, cons_gate}},
      {"polhode_period",
       {period, period_ref, std::abs(period - period_ref) / period_ref, prm["period_gate"]}},
  };
  if (k == 1) {
    // The intermediate axis turns over: the metric passes once it has gone more than 90° from its start.
    const double pi = std::numbers::pi;
    r.metrics.push_back({"axis_flip", {wander, pi, pi - wander, pi / 2}});
  } else {
    const double bound = wander_bound(moments_ref, l_body_ref, k);
    r.metrics.push_back({"axis_wander", {wander, bound, wander / bound, prm["wander_gate"]}});
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace

ValidationCase rigid_spin_case() {
  return {"rigid-spin",
          "torque-free spin of an ice box about a principal axis: |L| and energy kept to 1e-6 per "
          "revolution, the "
          "min and max axes stable, the intermediate one flips; res = particles along the longest side",
          16, params, run};
}

}  // namespace thaw
