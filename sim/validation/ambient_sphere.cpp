// An ice sphere melting in warm air (issue 19, docs/SURFACE.md): a sphere of ice of radius R0 at its
// melting point, held (no flow), in air at T_a with a fixed heat-transfer coefficient h. The air's heat
// melts its surface; the meltwater is drained: every `drain_every` steps the particles that have melted
// through are taken away with their mass booked as melted. Reference: the quasi-steady shrinking sphere,
// R(t) = R0 - h (T_a - T_m) t / (rho L), so the melted mass is rho 4/3 pi (R0^3 - R(t)^3), all from the
// parameters. Metric: the melted mass at the end (taken, plus the liquid fraction of what is left),
// against it. The exchange's area is heat.exposed_area (`model`), so the case measures how well each area
// model carries the air's heat. res = particles across R0.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/thermal.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

Field params() {
  return object("",
                {
                    number("radius", "R0").in("m").def(0.01).above(0),
                    number("air_temperature", "T_a").in("°C").def(20.0).above(0),
                    number("heat_transfer_coefficient", "h").in("W/m^2/K").def(500.0).above(0),
                    number("radius_loss", "Run until the reference radius has lost this fraction of R0")
                        .def(0.2)
                        .above(0)
                        .at_most(0.8),
                    number("density", "rho of ice").in("kg/m^3").def(917.0).above(0),
                    number("conductivity", "k of ice").in("W/m/K").def(2.22).above(0),
                    number("specific_heat", "c of ice").in("J/kg/K").def(2050.0).above(0),
                    number("latent_heat", "L").in("J/kg").def(334000.0).above(0),
                    choice("model", {"brackbill1992", "orthmann2013", "iwasaki2010"},
                           "heat.exposed_area: the area model")
                        .def("brackbill1992"),
                    integer("drain_every", "Steps between drainings of the meltwater").def(1).at_least(1),
                    number("mass_gate", "Gate on the relative error of the melted mass").def(0.03).above(0),
                    solver_schema_with({{"flow", false}, {"max_dt", 3600.0}}),
                });
}

// Keeps the particles for which keep[i] is true, in order, with every column.
void keep_only(HostParticles& p, const std::vector<bool>& keep) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!keep[i]) continue;
    p.position[n] = p.position[i];
    p.velocity[n] = p.velocity[i];
    p.density[n] = p.density[i];
    p.phase[n] = p.phase[i];
    p.material[n] = p.material[i];
    p.id[n] = p.id[i];
    p.enthalpy[n] = p.enthalpy[i];
    p.anchored[n] = p.anchored[i];
    for (HostColumn& c : p.columns) {
      const std::size_t b = c.spec.bytes();
      std::copy(c.bytes.begin() + long(i * b), c.bytes.begin() + long((i + 1) * b),
                c.bytes.begin() + long(n * b));
    }
    ++n;
  }
  p.resize(n);
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double R0 = prm["radius"], Ta = prm["air_temperature"], h = prm["heat_transfer_coefficient"];
  const double rho = prm["density"], L = prm["latent_heat"];
  const double dx = R0 / res;
  const double rate = h * Ta / (rho * L);  // dR/dt [m/s], T_m = 0 °C
  const double t_end = double(prm["radius_loss"]) * R0 / rate;
  const double half = R0 + 3 * dx;
  const Json ice = {{"density", rho},
                    {"conductivity", prm["conductivity"]},
                    {"specific_heat", prm["specific_heat"]},
                    {"latent_heat", L}};
  const Json sphere = {
      {"material", "ice"}, {"shape", "sphere"}, {"centre", {0, 0, 0}}, {"radius", R0}, {"temperature", 0.0}};
  const Json doc = ice_in_air_scene("validation/ambient-sphere", half, dx, prm["solver"], h, Ta, prm["model"],
                                    ice, sphere);
  const Scene scene = scene_from_json(doc);
  const auto table = material_thermal_table(scene, 1000.0);
  SimState st = initial_state(scene);
  const int every = prm["drain_every"];
  double taken = 0, heat_in = 0;
  std::uint64_t steps = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t particles = st.particles.size();
  while (st.time < t_end * (1.0 - 1e-12) && st.particles.size() > 0) {
    Solver solver(cl, scene, st);
    bool melted = false;
    while (!melted && solver.time() < t_end * (1.0 - 1e-12)) {
      for (int k = 0; k < every && solver.time() < t_end * (1.0 - 1e-12); ++k) solver.step();
      const HostParticles p = solver.particles();
      melted = p.count(Phase::Water) > 0;
    }
    heat_in += solver.energy_budget().ambient;
    steps += solver.steps() - st.step;
    st = solver.state();
    std::vector<bool> keep(st.particles.size());
    for (std::size_t i = 0; i < keep.size(); ++i) {
      keep[i] = st.particles.phase[i] != std::uint8_t(Phase::Water);
      if (!keep[i])
        taken += double(st.particles.position[i][3]) * table[st.particles.material[i]].thermal_mass_scale;
    }
    keep_only(st.particles, keep);
    // The areas the state carries are the old surface's: held particles keep a state's areas for the whole
    // run (Solver::surface_due), so the ice the drained water uncovered would never take the air's heat.
    // Without them the next solver finds the new surface.
    std::erase_if(st.particles.columns,
                  [](const HostColumn& c) { return c.spec.name.rfind("surface_", 0) == 0; });
    st.energy_budget.clear();
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double melted = taken;
  for (std::size_t i = 0; i < st.particles.size(); ++i) {
    const MaterialThermal& m = table[st.particles.material[i]];
    const double e = double(st.particles.enthalpy[i][0]) + double(st.particles.enthalpy[i][1]);
    melted += double(st.particles.position[i][3]) * m.thermal_mass_scale * liquid_fraction_at(m, e);
  }
  const double t = st.time;
  const double R = R0 - rate * t;
  const double reference = rho * 4.0 / 3.0 * M_PI * (R0 * R0 * R0 - R * R * R);
  CaseResult r;
  r.particles = particles;
  r.steps = steps;
  r.wall_s = wall;
  r.metrics = {
      {"melted_mass", {melted, reference, std::abs(melted - reference) / reference, prm["mass_gate"]}},
      // The air's heat over L: what melting would take if every joule melted ice.
      {"heat_in_over_latent", {heat_in / L, reference, std::abs(heat_in / L - reference) / reference, 1e30}}};
  return r;
}

}  // namespace

ValidationCase ambient_sphere_case() {
  return {
      "ambient-sphere",
      "An ice sphere at 0 °C melting in air through a fixed h, meltwater drained: melted mass against the "
      "shrinking-sphere law (gate 3 %); res = particles across R0. The melted sphere's rough surface carries "
      "more area than the smooth one, within the gate from res 20 (docs/SURFACE.md)",
      20, params, run};
}

}  // namespace thaw
