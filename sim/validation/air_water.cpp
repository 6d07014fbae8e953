// Air over water at rest (docs/VALIDATION-RESULTS.md): a tank open at the top, water of depth H under a
// layer of air, both at the same temperature, at the real density ratio (1.2 : 1000 by default). Reference:
// the interface stays flat and both fluids still; the mean speed of each below 1e-3 sqrt(g H) (issue 18's
// gate), the water level of the tank's quarters within half a spacing, no particle lost. After a damped
// settle as in the hydrostatic case, the speeds are averaged over an undamped window.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

Field params() {
  return air_case_schema({
      number("height", "Water depth H").in("m").def(0.1).above(0),
      number("air_height", "Air layer above the water").in("m").def(0.05).above(0),
      number("width", "Tank width in x and y").in("m").def(0.1).above(0),
      number("gravity", "Gravitational acceleration g").in("m/s^2").def(9.81).above(0),
      number("water_density", "Rest density of the water").in("kg/m^3").def(1000.0).above(0),
      number("water_viscosity", "Dynamic viscosity of the water").in("Pa s").def(1.0e-3).at_least(0),
      number("settle_time", "Damped settling before the free run").in("s").def(1.5).at_least(0),
      number("damping", "Velocity relaxation rate while settling").in("1/s").def(5.0).at_least(0),
      number("free_time", "Undamped run after settling, over which the speeds are averaged")
          .in("s")
          .def(0.2)
          .above(0),
      integer("sample_every", "Sample the speeds every k steps of the undamped run").def(5).at_least(1),
      number("speed_gate", "Gate on each fluid's mean speed, fraction of sqrt(g H)").def(1e-3).above(0),
      number("level_gate", "Gate on the spread of the water level between the tank's quarters, in spacings")
          .def(0.5)
          .above(0),
      solver_schema_with({{"pressure", "dfsph"}, {"artificial_viscosity", 0.05}}),
  });
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double H = prm["height"], g = prm["gravity"];
  const double dx = H / res;
  // Whole numbers of spacings, so both lattices fill the tank and the interface lies on a lattice plane.
  auto whole = [&](double v) { return std::max(1.0, std::round(v / dx)) * dx; };
  const double W = whole(prm["width"]), top = H + whole(prm["air_height"]);
  Json water = air_material(prm);
  water["kind"] = "fluid";
  water["density"] = prm["water_density"];
  water["viscosity"] = prm["water_viscosity"];
  water["conductivity"] = 0.56;
  water["specific_heat"] = 4217.0;
  const Json doc = {
      {"name", "validation/air-water"},
      {"domain",
       {{"min", {0.0, 0.0, 0.0}},
        {"max", {W, W, top}},
        // Open at the top, to the room: in a closed box the two incompressible fluids must fill it
        // exactly, and what the water's 0.1 % tolerance leaves over went to the air, which the solve
        // found uniformly compressed by 0.4 % and could not relieve (100 sweeps, unconverged): at res 30
        // it blew up at step 24. A real closed box's air would give way; ours has no compressibility.
        {"walls", {"-x", "+x", "-y", "+y", "-z"}},
        {"wall_material", "wall"}}},
      {"gravity", {0.0, 0.0, -g}},
      {"spacing", dx},
      {"solver", prm["solver"]},
      {"heat", {{"enabled", false}}},
      {"materials",
       {{"air", air_material(prm)},
        {"water", water},
        {"wall", {{"kind", "solid"}, {"density", 2500.0}, {"conductivity", 1.0}, {"specific_heat", 840.0}}}}},
      {"fluids", {{{"material", "water"}, {"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {W, W, H}}}}}}},
      {"air", {{"material", "air"}, {"buoyancy", "none"}}},
  };
  const Scene scene = scene_from_json(doc);
  SimState st = initial_state(scene);
  auto count = [](const HostParticles& p, Phase ph) {
    return std::count(p.phase.begin(), p.phase.end(), static_cast<std::uint8_t>(ph));
  };
  const auto water0 = count(st.particles, Phase::Water), air0 = count(st.particles, Phase::Air);

  Solver solver(cl, scene, st);
  solver.warm_up();
  const auto t0 = std::chrono::steady_clock::now();
  const double settle = prm["settle_time"], free = prm["free_time"];
  solver.set_velocity_damping(prm["damping"]);
  while (solver.time() < settle) solver.step();
  solver.set_velocity_damping(0.0);

  double speed[2] = {0, 0};
  long samples[2] = {0, 0};
  auto sample = [&] {
    const auto p = solver.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      const int k = p.phase[i] == static_cast<std::uint8_t>(Phase::Water) ? 0
                    : p.phase[i] == static_cast<std::uint8_t>(Phase::Air) ? 1
                                                                          : -1;
      if (k < 0) continue;
      const auto& v = p.velocity[i];
      speed[k] += std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
      ++samples[k];
    }
  };
  const int every = std::max(1, int(prm["sample_every"]));
  while (solver.time() < settle + free) {
    solver.step();
    if (solver.steps() % every == 0) sample();
  }
  if (samples[0] == 0) sample();

  // The interface: the water's height in each quarter of the tank (2 x 2 columns), from the volume of
  // water it holds, V N / A: one particle that moves into the next column of the lattice does not read as
  // a spacing's step, a tilt or a bulge does.
  const auto p = solver.particles();
  double n_quarter[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.phase[i] != static_cast<std::uint8_t>(Phase::Water)) continue;
    const auto& x = p.position[i];
    n_quarter[(x[0] < 0.5 * W ? 0 : 1) + (x[1] < 0.5 * W ? 0 : 2)] += 1;
  }
  const double per_particle = dx * dx * dx / (0.25 * W * W);
  double lo = 1e300, hi = -1e300, mean_level = 0;
  for (double n : n_quarter) lo = std::min(lo, n * per_particle), hi = std::max(hi, n * per_particle);
  for (double n : n_quarter) mean_level += 0.25 * n * per_particle;
  const double lost = double(water0 - count(p, Phase::Water)) + double(air0 - count(p, Phase::Air));

  const double u = std::sqrt(g * H);
  const double ws = speed[0] / double(std::max(1L, samples[0])),
               as = speed[1] / double(std::max(1L, samples[1]));
  CaseResult r;
  r.particles = p.size();
  r.steps = solver.steps();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.metrics = {
      {"water_mean_speed", {ws, 0.0, ws / u, prm["speed_gate"]}},
      {"air_mean_speed", {as, 0.0, as / u, prm["speed_gate"]}},
      // Value: the mean level; reference: H. Error: the highest quarter's level less the lowest's.
      {"interface_spread", {mean_level, H, (hi - lo) / dx, prm["level_gate"]}},
      {"lost_particles", {lost, 0.0, std::abs(lost), 0.0}},
  };
  return r;
}

}  // namespace

ValidationCase air_water_case() {
  return {"air-water",
          "air over water at rest at the real density ratio: both still (1e-3 sqrt(g H)), the interface flat",
          20, params, run};
}

}  // namespace thaw
