// Hydrostatic column (docs/VALIDATION-RESULTS.md): water at rest in a walled tank.
// Reference: the exact hydrostatic profile of the weakly compressible fluid the solver models,
// dp/dz = -g rho(p) with rho(p) from the scene's equation of state and the column's mass per area
// rho0 H; it tends to rho0 g (H - z) as the speed of sound grows. The particles start on that
// profile (layers compressed as rho(z) requires), which avoids the acoustic transient.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "sim/error.h"
#include "sim/metrics.h"
#include "sim/solver.h"
#include "sim/validation/case.h"
#include "sim/validation/hydrostatic_profile.h"
#include "sim/validation/tank_scene.h"

namespace thaw {
namespace {

Field params() {
  return object(
      "",
      {
          number("height", "Water column height H").in("m").def(0.2).above(0),
          number("width", "Tank width in x and y").in("m").def(0.15).above(0),
          number("gravity", "Gravitational acceleration g").in("m/s^2").def(9.81).above(0),
          number("density", "Rest density rho0").in("kg/m^3").def(1000.0).above(0),
          number("viscosity", "Dynamic viscosity").in("Pa s").def(1.0e-3).at_least(0),
          number("settle_time", "Damped settling before the free run").in("s").def(1.5).at_least(0),
          number("damping", "Velocity relaxation rate while settling").in("1/s").def(5.0).at_least(0),
          number("interior_margin", "Interior: this many kernel support radii from walls and the surface")
              .def(2.0)
              .at_least(0),
          number("free_time",
                 "Undamped run after settling, over which pressure and speed are averaged; 0: by the "
                 "solver, 0.1 s under wcsph and 0.5 s under dfsph, whose pressure is a per-step impulse that "
                 "swings with the iterations a step took (docs/VALIDATION-RESULTS.md)")
              .in("s")
              .def(0.0)
              .at_least(0),
          integer("sample_every",
                  "Sample the profile every k steps of the undamped run; 0: by the solver, 5 under wcsph and "
                  "1 under dfsph")
              .def(0)
              .at_least(0),
          number("pressure_gate", "Gate on max |p - p_exact| of the interior profile, fraction of rho0 g H")
              .def(0.01)
              .above(0),
          number("layer_noise_gate", "Bound on one layer's deviation from the profile, fraction of rho0 g H")
              .def(0.05)
              .above(0),
          number("speed_gate", "Gate on the mean speed, fraction of sqrt(g H)").def(1e-3).above(0),
          solver_schema_with({{"artificial_viscosity", 0.05}}),
      });
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double H = prm["height"], g = prm["gravity"], rho0 = prm["density"];
  const double dx = H / res;
  // A whole number of spacings, so the fluid lattice fills the tank and the column keeps height H.
  const double W = std::max(1.0, std::floor(double(prm["width"]) / dx + 1e-9)) * dx;
  const Json doc = tank_scene_json(
      {"validation/hydrostatic", {W, W, 1.25 * H}, {W, W, H}, dx, g, rho0, prm["viscosity"], prm["solver"]});
  const Scene scene = scene_from_json(doc);
  const SolverConstants k = derive_constants(scene);
  const HydrostaticProfile prof = hydrostatic_profile(scene, H);
  SimState st = initial_state(scene);
  compress_to_hydrostatic(st.particles, prof);
  const double mass0 = measure(st.particles, scene, rho0).fluid_mass;

  Solver solver(cl, scene, st);
  solver.warm_up();
  const auto t0 = std::chrono::steady_clock::now();
  // The sampling that suits the solver where the parameters leave it to the case.
  const bool dfsph = prm["solver"]["pressure"] == "dfsph";
  const double settle = prm["settle_time"],
               free = double(prm["free_time"]) > 0 ? double(prm["free_time"]) : (dfsph ? 0.5 : 0.1);
  solver.set_velocity_damping(prm["damping"]);
  while (solver.time() < settle) solver.step();
  solver.set_velocity_damping(0.0);

  // Layer-averaged pressure of interior particles (interior_margin support radii from walls and surface),
  // averaged over the undamped window as well: WCSPH pressure carries acoustic noise.
  const double margin = double(prm["interior_margin"]) * k.support, top = prof.top();
  const int layers = static_cast<int>(std::ceil(top / dx)) + 1;
  std::vector<double> sum_p(layers, 0), sum_z(layers, 0);
  std::vector<long> cnt(layers, 0);
  double speed_sum = 0;
  long speed_samples = 0;
  auto sample = [&] {
    const auto p = solver.particles();
    const auto ps = solver.pressure_state();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.phase[i] == static_cast<std::uint8_t>(Phase::Solid)) continue;
      const auto& x = p.position[i];
      const auto& v = p.velocity[i];
      speed_sum += std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
      ++speed_samples;
      if (x[0] < margin || x[0] > W - margin || x[1] < margin || x[1] > W - margin || x[2] < margin ||
          x[2] > top - margin)
        continue;
      const int l = std::clamp(static_cast<int>(x[2] / dx), 0, layers - 1);
      sum_p[l] += ps[i][3];
      sum_z[l] += x[2];
      ++cnt[l];
    }
  };
  const int every = int(prm["sample_every"]) > 0 ? int(prm["sample_every"]) : (dfsph ? 1 : 5);
  while (solver.time() < settle + free) {
    solver.step();
    if (solver.steps() % every == 0) sample();
  }
  if (speed_samples == 0) sample();
  const auto p = solver.particles();
  // The profile: the least-squares line through the interior layers' time-averaged pressures, compared
  // with the exact profile over the interior. Single layers deviate from it by the WCSPH pressure noise
  // c^2 delta_rho (1 % of rho0 g H is a density deviation of ~4e-5 here), reported as its own metric.
  const double scale = rho0 * g * H;
  std::vector<double> zs, ps, ws;
  double zlo = 1e300, zhi = -1e300;
  for (int l = 0; l < layers; ++l) {
    if (cnt[l] == 0) continue;
    const double w = double(cnt[l]), zm = sum_z[l] / w, pm = sum_p[l] / w;
    zs.push_back(zm), ps.push_back(pm), ws.push_back(w);
    zlo = std::min(zlo, zm), zhi = std::max(zhi, zm);
  }
  if (zs.empty() || zhi - zlo < dx)
    throw SceneError("interior_margin",
                     "no interior left to measure: widen the tank (width) or lower interior_margin");
  const auto [slope, intercept] = least_squares_line(zs, ps, ws);
  MetricResult profile{0, 0, 0, prm["pressure_gate"]};
  for (double z : {zlo, zhi}) {  // a line against a (nearly linear) exact profile: worst at an end
    const double fit = intercept + slope * z, exact = prof.pressure_at(z);
    const double err = std::abs(fit - exact) / scale;
    if (err >= profile.error) profile = {fit, exact, err, profile.gate};
  }
  MetricResult noise{0, 0, 0, prm["layer_noise_gate"]};
  for (int l = 0; l < layers; ++l) {
    if (cnt[l] == 0) continue;
    const double zm = sum_z[l] / double(cnt[l]), pm = sum_p[l] / double(cnt[l]), fit = intercept + slope * zm;
    if (std::abs(pm - fit) / scale >= noise.error) noise = {pm, fit, std::abs(pm - fit) / scale, noise.gate};
  }
  const double mean_speed = speed_sum / double(speed_samples);
  const double mass = measure(p, scene, rho0).fluid_mass;

  CaseResult r;
  r.particles = p.size();
  r.steps = solver.steps();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.metrics = {
      {"pressure_profile", profile},
      {"pressure_layer_noise", noise},
      {"mean_speed", {mean_speed, 0.0, mean_speed / std::sqrt(g * H), prm["speed_gate"]}},
      {"mass", {mass, mass0, std::abs(mass - mass0) / mass0, 0.0}},
  };
  return r;
}

}  // namespace

ValidationCase hydrostatic_case() {
  return {"hydrostatic",
          "water column at rest: pressure profile vs the exact hydrostatic one, gate 1 % of rho0 g H", 20,
          params, run};
}

}  // namespace thaw
