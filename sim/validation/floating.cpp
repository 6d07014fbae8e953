// Floating ice (docs/VALIDATION-RESULTS.md): a square ice prism, breadth b, height H, free in a tank of
// water, starts tilted by `tilt` degrees about y, its centre at the height of Archimedes' draft.
// References, from the parameters:
// - upright, the draft over the height is f = rho_ice / rho_water (Archimedes);
// - the angle it comes to rest at. Turning about y leaves every section across y the same b x H
//   rectangle, so the buoyancy follows exactly from that rectangle cut by the waterline at the depth
//   that immerses the fraction f of it: the righting arm GZ(theta) is the horizontal offset of the cut
//   area's centroid from the rectangle's centre (heel_equilibrium below). The prism turns the way GZ
//   pushes it from `tilt` and stops at the first stable zero of GZ: 0 when upright is stable, which is
//   b / H > sqrt(6 f (1 - f)) (the metacentric height b^2 / (12 f H) - H (1 - f) / 2 is positive), and
//   a heeled or capsized angle otherwise.
// The prism is held at its starting pose while the water settles (damped) around it, then let go.
// Measured over the last `average_time` seconds: the angle between the prism's height axis and z, and,
// for an upright prism, its draft below two water levels taken near the walls:
// - the surface one sees: the median over columns of the top particle plus half a spacing;
// - the level the water's mass makes: the water's mass in that ring over rho_water and the ring's area.
// The first sits up to half a spacing below the second: free-surface particles, which have no
// pressure below rest density, crowd down onto the layer beneath. The pressure under the prism
// follows the mass (p = g * mass above per area), so the second is Archimedes' level.
//
// Kernel: the case runs Wendland C2 over 3 spacings. With the default cubic spline over 2 spacings the
// water around the prism locks it like a jelly: at res 8 the wide prism stops at 7 degrees instead of
// righting itself, and the narrow one stops at 16 degrees (19 at res 12, after 2 s) instead of capsizing.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "sim/error.h"
#include "sim/rigid_ice.h"
#include "sim/solver.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

Field params() {
  return object(
      "",
      {
          number("height", "Prism height H").in("m").def(0.03).above(0),
          number("breadth_ratio", "Breadth over height b / H (the prism's base is b x b)").def(1.0).above(0),
          number("ice_density", "Ice density").in("kg/m^3").def(917.0).above(0),
          number("water_density", "Water rest density").in("kg/m^3").def(1000.0).above(0),
          number("tilt", "Initial tilt about the y axis").in("degrees").def(10.0).at_least(0).at_most(60),
          number("margin",
                 "Water beyond the prism's longer side (so a capsized prism keeps it) on each side, in prism "
                 "heights")
              .def(0.6)
              .above(0),
          number("depth", "Water depth, in prism heights").def(1.5).above(0),
          number("settle_time", "Damped settling of the water (the prism held in place meanwhile)")
              .in("s")
              .def(0.1)
              .at_least(0),
          number("damping", "Velocity relaxation rate of the water while settling")
              .in("1/s")
              .def(10.0)
              .at_least(0),
          number("run_time", "Undamped run after settling (a narrow prism takes about 3 s to capsize)")
              .in("s")
              .def(4.0)
              .above(0),
          number("average_time", "The heel and draft are averaged over the run's last ... seconds")
              .in("s")
              .def(0.2)
              .above(0),
          number("draft_gate",
                 "Gate on |draft - f H| as a fraction of H (or half a spacing, whichever is larger)")
              .def(0.01)
              .above(0),
          number("heel_gate", "Gate on |heel - heel at rest| (the angle the righting arm comes to zero at)")
              .in("degrees")
              .def(6.0)
              .above(0),
          solver_schema_with(
              {{"artificial_viscosity", 0.05}, {"kernel", "wendland_c2"}, {"support_ratio", 3.0}}),
      });
}

// The angle between the prism's height axis (`height_axis`, in the body frame) and the world's z.
double tilt_degrees(const RigidBody& b, const Eigen::Vector3d& height_axis) {
  const double c = std::clamp((b.rotation() * height_axis).z(), -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

// The horizontal offset of the centroid of a b x h rectangle, turned by theta about y, below the
// waterline that leaves the fraction f of its area immersed, from the rectangle's centre: the righting
// arm. Positive: the buoyancy turns the prism back towards upright.
double righting_arm(double b, double h, double f, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  std::vector<Eigen::Vector2d> corners;
  for (const auto& [x, z] :
       {std::pair{-0.5 * b, -0.5 * h}, {0.5 * b, -0.5 * h}, {0.5 * b, 0.5 * h}, {-0.5 * b, 0.5 * h}})
    corners.emplace_back(x * c + z * s, -x * s + z * c);
  // The part of the polygon below z = w (Sutherland-Hodgman against one half-plane): its area and centroid.
  auto below = [&](double w, double& cx) {
    std::vector<Eigen::Vector2d> cut;
    for (std::size_t k = 0; k < corners.size(); ++k) {
      const Eigen::Vector2d& p = corners[k];
      const Eigen::Vector2d& q = corners[(k + 1) % corners.size()];
      const bool pin = p.y() <= w, qin = q.y() <= w;
      if (pin) cut.push_back(p);
      if (pin != qin) cut.push_back(p + (q - p) * ((w - p.y()) / (q.y() - p.y())));
    }
    double area = 0, sx = 0;
    for (std::size_t k = 0; k < cut.size(); ++k) {
      const Eigen::Vector2d& p = cut[k];
      const Eigen::Vector2d& q = cut[(k + 1) % cut.size()];
      const double cross = p.x() * q.y() - q.x() * p.y();
      area += 0.5 * cross;
      sx += (p.x() + q.x()) * cross / 6.0;
    }
    cx = std::abs(area) > 0 ? sx / area : 0.0;
    return std::abs(area);
  };
  double lo = -(b + h), hi = b + h, cx = 0;
  for (int k = 0; k < 200; ++k) {
    const double w = 0.5 * (lo + hi);
    (below(w, cx) < f * b * h ? lo : hi) = w;
  }
  below(0.5 * (lo + hi), cx);
  // The buoyancy (up, at x = cx) about the centre: torque about y = -cx F, against a positive theta
  // when cx > 0.
  return cx;
}

// Where a prism let go at `start` radians comes to rest: it turns the way the righting arm pushes it
// and stops at the first angle where the arm changes sign against the motion.
double heel_equilibrium(double b, double h, double f, double start) {
  const double step = 1e-3;
  const double arm = righting_arm(b, h, f, start);
  if (std::abs(arm) < 1e-12 * (b + h)) return start;
  const double dir = arm > 0 ? -1.0 : 1.0;
  double theta = start;
  for (int k = 0; k < 4000; ++k) {
    const double next = theta + dir * step;
    if (next <= 0.0) return 0.0;
    if (next >= 0.5 * M_PI) return 0.5 * M_PI;
    if ((righting_arm(b, h, f, next) > 0) != (arm > 0)) {
      double lo = theta, hi = next;  // bisect the sign change
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        ((righting_arm(b, h, f, mid) > 0) == (arm > 0) ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi);
    }
    theta = next;
  }
  return theta;
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double H = prm["height"], ratio = prm["breadth_ratio"];
  const double rho_i = prm["ice_density"], rho_w = prm["water_density"];
  const double f = rho_i / rho_w;
  if (f >= 1.0) throw SceneError("ice_density", "must be below water_density for the ice to float");
  const double dx = H / res;
  // Whole spacings, so the lattice fills the prism and the water exactly.
  auto snap = [&](double x) { return std::max(1.0, std::round(x / dx)) * dx; };
  const double h = snap(H), b = snap(ratio * H);
  const double margin = snap(double(prm["margin"]) * H), depth = snap(double(prm["depth"]) * H);
  const double W = std::max(b, h) + 2 * margin;
  const double x0 = 0.5 * (W - b);  // the prism's base, centred
  const double level = depth;       // the water's top before the ice goes in
  // Centre at the reference draft: bottom f h below the level.
  const double bottom = level - f * h;
  const Eigen::Vector3d lo(x0, x0, bottom), hi(x0 + b, x0 + b, bottom + h);
  Json doc = {
      {"name", "validation/floating"},
      {"domain",
       {{"min", {0, 0, 0}},
        {"max", {W, W, depth + 1.2 * h}},
        {"walls", {"-x", "+x", "-y", "+y", "-z"}},
        {"wall_material", "wall"}}},
      {"gravity", {0, 0, -9.81}},
      {"spacing", dx},
      {"solver", prm["solver"]},
      {"heat", {{"enabled", false}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"},
          {"density", rho_w},
          {"viscosity", 1e-3},
          {"conductivity", 0.56},
          {"specific_heat", 4217.0}}},
        {"ice",
         {{"kind", "ice"},
          {"density", rho_i},
          {"conductivity", 2.22},
          {"specific_heat", 2050.0},
          {"melts_into", "water"}}},
        {"wall", {{"kind", "solid"}, {"density", 2500.0}, {"conductivity", 1.0}, {"specific_heat", 840.0}}}}},
      {"fluids", {{{"material", "water"}, {"box", {{"min", {0, 0, 0}}, {"max", {W, W, level}}}}}}},
      {"ice",
       {{{"material", "ice"},
         {"box", {{"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}}},
         {"rotation", {0.0, double(prm["tilt"]), 0.0}},
         {"motion", "free"}}}},
  };
  const Scene scene = scene_from_json(doc);
  SimState st = initial_state(scene);
  Solver solver(cl, scene, st);
  solver.warm_up();
  const auto t0 = std::chrono::steady_clock::now();
  const double settle = prm["settle_time"], run_time = prm["run_time"], window = prm["average_time"];

  auto body = [&]() -> const RigidBody& {
    const RigidIce* rigid = solver.rigid_ice();
    if (!rigid || rigid->bodies().empty()) throw Error("floating: the prism is not a body");
    return rigid->bodies().front().body;
  };
  // The water levels away from the ice (see the top of the file), over the ring of columns one spacing
  // square within about half a margin of the walls. Columns are chosen by where they are,
  // not by where their particles are (a particle on a column's edge would leave it short), and the
  // median keeps a column whose top particle has moved next door from pulling the level down.
  const int columns = static_cast<int>(std::round(W / dx));
  // A whole number of spacings wide, so no particle centre ((k + 1/2) dx from a wall) lies on its edge.
  const double ring = std::max(1.0, std::floor(0.5 * margin / dx + 1e-9)) * dx;
  const auto in_ring = [&](double x, double y) { return std::min({x, y, W - x, W - y}) < ring; };
  struct Levels {
    double surface, mass;
  };
  auto water_levels = [&] {
    const HostParticles p = solver.particles();
    std::vector<double> top(std::size_t(columns * columns), -1.0);
    double mass = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.phase[i] != std::uint8_t(Phase::Water)) continue;
      const double x = p.position[i][0], y = p.position[i][1];
      if (in_ring(x, y)) mass += p.position[i][3];
      const int cx = std::clamp(static_cast<int>(x / dx), 0, columns - 1);
      const int cy = std::clamp(static_cast<int>(y / dx), 0, columns - 1);
      double& t = top[std::size_t(cy * columns + cx)];
      t = std::max(t, double(p.position[i][2]));
    }
    std::vector<double> tops;
    for (int cy = 0; cy < columns; ++cy)
      for (int cx = 0; cx < columns; ++cx) {
        const double t = top[std::size_t(cy * columns + cx)];
        if (t >= 0 && in_ring((cx + 0.5) * dx, (cy + 0.5) * dx)) tops.push_back(t);
      }
    if (tops.empty()) throw Error("floating: no water left near the walls to measure the level by");
    const auto mid = tops.begin() + std::ptrdiff_t(tops.size() / 2);
    std::nth_element(tops.begin(), mid, tops.end());
    const double ring_area = W * W - (W - 2 * ring) * (W - 2 * ring);
    return Levels{*mid + 0.5 * dx, mass / (rho_w * ring_area)};
  };

  // The labelling found the prism at warm-up, tilted by `tilt` about y: its height axis in the body frame.
  const double tilt0 = double(prm["tilt"]) * M_PI / 180.0;
  const Eigen::Vector3d height_axis =
      body().rotation().transpose() * Eigen::Vector3d(std::sin(tilt0), 0.0, std::cos(tilt0));
  solver.set_velocity_damping(prm["damping"]);
  solver.hold_ice(true);
  while (solver.time() < settle) solver.step();
  solver.hold_ice(false);
  solver.set_velocity_damping(0.0);
  double surface_sum = 0, mass_sum = 0, tilt_sum = 0;
  long samples = 0;
  auto sample = [&] {
    const RigidBody& r = body();
    const Levels l = water_levels();
    const double bottom_now = r.position.z() - 0.5 * h;
    surface_sum += l.surface - bottom_now;
    mass_sum += l.mass - bottom_now;
    tilt_sum += tilt_degrees(r, height_axis);
    ++samples;
  };
  const int every = std::max(1, static_cast<int>(std::round(0.005 / std::max(solver.dt(), 1e-6))));
  while (solver.time() < settle + run_time) {
    solver.step();
    if (solver.time() >= settle + run_time - window && solver.steps() % std::uint64_t(every) == 0) sample();
  }
  if (samples == 0) sample();

  CaseResult r;
  r.particles = solver.size();
  r.steps = solver.steps();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rest = heel_equilibrium(b, h, f, double(prm["tilt"]) * M_PI / 180.0) * 180.0 / M_PI;
  const double heel = tilt_sum / double(samples);
  r.metrics.push_back({"heel_degrees", {heel, rest, std::abs(heel - rest), prm["heel_gate"]}});
  if (rest == 0.0) {
    // Upright: the draft is Archimedes', below either level.
    const double gate = std::max(double(prm["draft_gate"]), 0.5 * dx / h);
    const double surface = surface_sum / double(samples) / h, mass = mass_sum / double(samples) / h;
    r.metrics.push_back({"draft_over_height", {surface, f, std::abs(surface - f), gate}});
    r.metrics.push_back({"draft_below_mass_level_over_height", {mass, f, std::abs(mass - f), gate}});
  }
  return r;
}

}  // namespace

ValidationCase floating_case() {
  return {
      "floating",
      "an ice prism floats: the heel it comes to rest at (upright if b/H > sqrt(6f(1-f)), else on its side, "
      "from the exact righting arm) and, upright, draft / height vs rho_ice / rho_water; res = particles "
      "across H",
      10, params, run};
}

}  // namespace thaw
