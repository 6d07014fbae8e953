// Hydrostatic column (shared/VALIDATION.md §3): water at rest in a walled tank.
// Reference: the exact hydrostatic profile of the weakly compressible fluid the solver models,
// dp/dz = -g rho(p) with rho(p) from the scene's equation of state and the column's mass per area
// rho0 H; it tends to rho0 g (H - z) as the speed of sound grows. The particles start on that
// profile (layers compressed as rho(z) requires), which avoids the acoustic transient.
#include <chrono>
#include <cmath>

#include "sim/metrics.h"
#include "sim/solver.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

// Height above the floor at which the column above carries pressure p: z(p) = top - F(p)/g,
// F(p) = integral_0^p dp'/rho(p').
struct Profile {
  double rho0, g, H, B, gamma;
  bool tait;
  double F(double p) const {
    if (tait) return B / rho0 * gamma / (gamma - 1) * (std::pow(1 + p / B, (gamma - 1) / gamma) - 1);
    return B / rho0 * std::log1p(p / B);
  }
  double Finv(double f) const {
    if (tait) return B * (std::pow(1 + f * rho0 * (gamma - 1) / (B * gamma), gamma / (gamma - 1)) - 1);
    return B * std::expm1(f * rho0 / B);
  }
  double top() const { return F(rho0 * g * H) / g; }
  double pressure_at(double z) const { return z >= top() ? 0.0 : Finv(g * (top() - z)); }
  // Where a particle whose column above weighs rho0 g (H - z_nominal) per area sits.
  double height_of(double z_nominal) const { return top() - F(rho0 * g * (H - z_nominal)) / g; }
};

Field params() {
  return object("", {
      number("height", "Water column height H").in("m").def(0.2).above(0),
      number("width", "Tank width in x and y").in("m").def(0.1).above(0),
      number("gravity", "Gravitational acceleration g").in("m/s^2").def(9.81).above(0),
      number("density", "Rest density rho0").in("kg/m^3").def(1000.0).above(0),
      number("viscosity", "Dynamic viscosity").in("Pa s").def(1.0e-3).at_least(0),
      number("settle_time", "Damped settling before the free run").in("s").def(0.3).at_least(0),
      number("damping", "Velocity relaxation rate while settling").in("1/s").def(20.0).at_least(0),
      number("free_time", "Undamped run after settling, then measure").in("s").def(0.1).at_least(0),
      number("pressure_gate", "Gate on max |p - p_exact| in the interior, fraction of rho0 g H").def(0.01).above(0),
      number("speed_gate", "Gate on the mean speed, fraction of sqrt(g H)").def(1e-3).above(0),
      solver_schema_with({{"artificial_viscosity", 0.05}}),
  });
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double H = prm["height"], W = prm["width"], g = prm["gravity"], rho0 = prm["density"];
  const double dx = H / res;
  Json doc = {
      {"name", "validation/hydrostatic"},
      {"domain", {{"min", {0, 0, 0}}, {"max", {W, W, 1.25 * H}}, {"walls", {"-x", "+x", "-y", "+y", "-z"}},
                  {"wall_material", "wall"}}},
      {"gravity", {0, 0, -g}},
      {"spacing", dx},
      {"solver", prm["solver"]},
      {"materials", {{"water", {{"kind", "fluid"}, {"density", rho0}, {"viscosity", prm["viscosity"]}}},
                     {"wall", {{"kind", "solid"}, {"density", 2500.0}}}}},
      {"fluids", {{{"material", "water"}, {"box", {{"min", {0, 0, 0}}, {"max", {W, W, H}}}}}}},
  };
  const Scene scene = scene_from_json(doc);
  const SolverConstants k = derive_constants(scene);
  const Profile prof{rho0, g, H, k.stiffness, scene.solver.gamma, scene.solver.eos == "tait"};

  SimState st = initial_state(scene);
  for (std::size_t i = 0; i < st.particles.size(); ++i)
    if (st.particles.phase[i] != static_cast<std::uint8_t>(Phase::Solid))
      st.particles.position[i][2] = static_cast<float>(prof.height_of(st.particles.position[i][2]));
  const double mass0 = measure(st.particles, scene, rho0).fluid_mass;

  Solver solver(cl, scene, st);
  solver.warm_up();
  const auto t0 = std::chrono::steady_clock::now();
  const double settle = prm["settle_time"], free = prm["free_time"];
  solver.set_velocity_damping(prm["damping"]);
  while (solver.time() < settle) solver.step();
  solver.set_velocity_damping(0.0);
  while (solver.time() < settle + free) solver.step();

  // Layer-averaged pressure of interior particles (a support radius away from walls and the surface).
  const auto p = solver.particles();
  const auto ps = solver.pressure_state();
  const double margin = k.support, top = prof.top();
  const int layers = static_cast<int>(std::ceil(top / dx)) + 1;
  std::vector<double> sum_p(layers, 0), sum_z(layers, 0);
  std::vector<int> cnt(layers, 0);
  double speed_sum = 0;
  std::size_t fluid = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.phase[i] == static_cast<std::uint8_t>(Phase::Solid)) continue;
    const auto& x = p.position[i];
    const auto& v = p.velocity[i];
    speed_sum += std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
    ++fluid;
    if (x[0] < margin || x[0] > W - margin || x[1] < margin || x[1] > W - margin || x[2] < margin ||
        x[2] > top - margin)
      continue;
    const int l = std::clamp(static_cast<int>(x[2] / dx), 0, layers - 1);
    sum_p[l] += ps[i][3];
    sum_z[l] += x[2];
    ++cnt[l];
  }
  const double scale = rho0 * g * H;
  MetricResult pressure{0, 0, 0, prm["pressure_gate"]};
  for (int l = 0; l < layers; ++l) {
    if (cnt[l] == 0) continue;
    const double pm = sum_p[l] / cnt[l], zm = sum_z[l] / cnt[l];
    const double err = std::abs(pm - prof.pressure_at(zm)) / scale;
    if (err >= pressure.error) pressure = {pm, prof.pressure_at(zm), err, pressure.gate};
  }
  const double mean_speed = fluid ? speed_sum / double(fluid) : 0.0;
  const double mass = measure(p, scene, rho0).fluid_mass;

  CaseResult r;
  r.particles = p.size();
  r.steps = solver.steps();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.metrics = {
      {"pressure_max_layer_error", pressure},
      {"mean_speed", {mean_speed, 0.0, mean_speed / std::sqrt(g * H), prm["speed_gate"]}},
      {"mass", {mass, mass0, std::abs(mass - mass0) / mass0, 0.0}},
  };
  return r;
}

}  // namespace

ValidationCase hydrostatic_case() {
  return {"hydrostatic", "water column at rest: pressure profile vs the exact hydrostatic one, gate 1 % of rho0 g H",
          20, params, run};
}

}  // namespace thaw
