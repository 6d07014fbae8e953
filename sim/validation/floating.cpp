// Floating ice (shared/VALIDATION.md §5): a square ice prism, breadth b, height H, free in a tank of
// water, settles where its weight equals the weight of the water it displaces.
// References, from the parameters: the draft over the height is f = rho_ice / rho_water (Archimedes);
// the upright prism is stable when its metacentre lies above its centre of mass, b / H > sqrt(6 f (1 - f))
// (metacentric height b^2 / (12 f H) - H (1 - f) / 2 > 0, for rolling about either horizontal axis).
// The prism starts upright at the reference draft, turning about y at `kick` rad/s (a rotated prism
// would not sit on the water's lattice): a stable one rocks back, an unstable one capsizes. The draft is
// averaged over the last `average_time` seconds, from the water level near the walls (the top particle of
// each column, plus half a spacing) and the body's centre (draft = level - (c_z - H/2)).
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
          number("kick", "Initial rate of turn about the y axis")
              .in("rad/s")
              .def(0.5)
              .at_least(0)
              .at_most(50),
          number("margin", "Water beyond the prism on each side, in prism heights").def(0.6).above(0),
          number("depth", "Water depth, in prism heights").def(1.5).above(0),
          number("settle_time", "Damped settling of the water (the prism floats freely meanwhile)")
              .in("s")
              .def(0.3)
              .at_least(0),
          number("damping", "Velocity relaxation rate of the water while settling")
              .in("1/s")
              .def(10.0)
              .at_least(0),
          number("run_time", "Undamped run after settling").in("s").def(0.5).above(0),
          number("average_time", "The draft is averaged over the run's last ... seconds")
              .in("s")
              .def(0.2)
              .above(0),
          number("draft_gate",
                 "Gate on |draft - f H| as a fraction of H (or half a spacing, whichever is larger)")
              .def(0.01)
              .above(0),
          number("upright_gate", "A stable prism ends within this tilt").in("degrees").def(10.0).above(0),
          number("capsized_tilt", "An unstable prism has capsized past this tilt")
              .in("degrees")
              .def(30.0)
              .above(0),
          solver_schema_with({{"artificial_viscosity", 0.05}}),
      });
}

double tilt_degrees(const RigidBody& b) {
  // The angle between the body's height axis (the principal axis nearest the world's z at the start) and z.
  const Eigen::Matrix3d R = b.rotation();
  double best = 0;
  for (int a = 0; a < 3; ++a) best = std::max(best, std::abs(R(2, a)));
  return std::acos(std::min(1.0, best)) * 180.0 / M_PI;
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
  const double W = b + 2 * margin;
  const double level = depth;  // the water's top before the ice goes in
  // Centre at the reference draft: bottom f h below the level.
  const double bottom = level - f * h;
  const Eigen::Vector3d lo(margin, margin, bottom), hi(margin + b, margin + b, bottom + h);
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
         {"motion", "free"}}}},
  };
  const Scene scene = scene_from_json(doc);
  SimState st = initial_state(scene);
  const Eigen::Vector3d centre = 0.5 * (lo + hi), omega(0.0, double(prm["kick"]), 0.0);
  for (std::size_t i = 0; i < st.particles.size(); ++i) {
    if (st.particles.phase[i] != std::uint8_t(Phase::Ice)) continue;
    const auto& x = st.particles.position[i];
    const Eigen::Vector3d v = omega.cross(Eigen::Vector3d(x[0], x[1], x[2]) - centre);
    st.particles.velocity[i] = {float(v.x()), float(v.y()), float(v.z()), 0.f};
  }
  Solver solver(cl, scene, st);
  solver.warm_up();
  const auto t0 = std::chrono::steady_clock::now();
  const double settle = prm["settle_time"], run_time = prm["run_time"], window = prm["average_time"];

  auto body = [&]() -> const RigidBody& {
    const RigidIce* rigid = solver.rigid_ice();
    if (!rigid || rigid->bodies().empty()) throw Error("floating: the prism is not a body");
    return rigid->bodies().front().body;
  };
  // The water level away from the ice: in each column of one spacing square within half a margin of
  // the walls, the highest water particle; their mean plus half a spacing (a particle stands for the
  // cube around it).
  const int columns = static_cast<int>(std::round(W / dx));
  auto water_level = [&] {
    const HostParticles p = solver.particles();
    std::vector<double> top(std::size_t(columns * columns), -1.0);
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.phase[i] != std::uint8_t(Phase::Water)) continue;
      const double x = p.position[i][0], y = p.position[i][1];
      if (std::min({x, y, W - x, W - y}) >= 0.5 * margin) continue;
      const int cx = std::clamp(static_cast<int>(x / dx), 0, columns - 1);
      const int cy = std::clamp(static_cast<int>(y / dx), 0, columns - 1);
      double& t = top[std::size_t(cy * columns + cx)];
      t = std::max(t, double(p.position[i][2]));
    }
    double sum = 0;
    long count = 0;
    for (double t : top)
      if (t >= 0) sum += t, ++count;
    if (count == 0) throw Error("floating: no water left near the walls to measure the level by");
    return sum / double(count) + 0.5 * dx;
  };

  solver.set_velocity_damping(prm["damping"]);
  while (solver.time() < settle) solver.step();
  solver.set_velocity_damping(0.0);
  double draft_sum = 0, tilt_max_late = 0;
  long samples = 0;
  const int every = std::max(1, static_cast<int>(std::round(0.005 / std::max(solver.dt(), 1e-6))));
  while (solver.time() < settle + run_time) {
    solver.step();
    if (solver.time() >= settle + run_time - window && solver.steps() % std::uint64_t(every) == 0) {
      const RigidBody& r = body();
      draft_sum += water_level() - (r.position.z() - 0.5 * h);
      tilt_max_late = std::max(tilt_max_late, tilt_degrees(r));
      ++samples;
    }
  }
  if (samples == 0) {
    draft_sum = water_level() - (body().position.z() - 0.5 * h);
    tilt_max_late = tilt_degrees(body());
    samples = 1;
  }
  const double tilt_end = tilt_degrees(body());

  CaseResult r;
  r.particles = solver.size();
  r.steps = solver.steps();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const bool stable = b / h > std::sqrt(6.0 * f * (1.0 - f));
  if (stable) {
    // Only an upright prism has a draft to compare.
    const double draft = draft_sum / double(samples);
    const double gate = std::max(double(prm["draft_gate"]), 0.5 * dx / h);
    r.metrics.push_back({"draft_over_height", {draft / h, f, std::abs(draft / h - f), gate}});
    r.metrics.push_back({"tilt_degrees", {tilt_max_late, 0.0, tilt_max_late, prm["upright_gate"]}});
  } else {
    // Passes once the tilt exceeds capsized_tilt: the error is how far short of it the prism stayed.
    const double need = prm["capsized_tilt"];
    r.metrics.push_back({"capsized_tilt_degrees", {tilt_end, need, std::max(0.0, need - tilt_end), 0.0}});
  }
  return r;
}

}  // namespace

ValidationCase floating_case() {
  return {
      "floating",
      "an ice prism floats: draft / height vs rho_ice / rho_water; upright if b/H > sqrt(6f(1-f)), else it "
      "capsizes",
      10, params, run};
}

}  // namespace thaw
