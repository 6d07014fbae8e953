// Ice melting in brine below 0 °C (issue 20; docs/SUBSTANCES.md): a column of ice under a column of brine,
// both at T0 below 0 °C but above the brine's liquidus, particles held in place (flow off), no heat in or
// out. Salt lowers the water's melting point by K_f i b (Blagden's law with van 't Hoff's factor, b the
// molality), so the ice next to the brine melts, taking its latent heat from the column: the column cools,
// and the meltwater dilutes the brine until its liquidus meets the temperature reached. Reference, from the
// energy and salt balance (closed, adiabatic): the ice left m_I and the temperature T_f with
//   H0 = m_I c_s (T_f - T_m) + (M - m_I) (L + c_l (T_f - T_m)),   T_f = T_m - K_f i (S / M_salt) / (M - m_I -
//   S),
// H0 the column's enthalpy at the start, M its mass and S its salt. Metrics: the ice left and the
// temperature reached against those, and the energy and salt closures. res = particles across the ice's
// height.
#include <chrono>
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/thermal.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

Field params() {
  return object(
      "",
      {
          number("ice_height", "Height of the ice column").in("m").def(0.006).above(0),
          number("brine_height", "Height of the brine above it").in("m").def(0.006).above(0),
          number("temperature", "T0 of both at the start").in("°C").def(-5.0).above(-30).below(0),
          number("salinity", "The brine's salt at the start, kg per kg of brine")
              .def(0.1)
              .above(0)
              .at_most(0.25),
          number("molar_mass", "M of the salt (NaCl 0.05844)").in("kg/mol").def(0.05844).above(0),
          number("dissociation", "van 't Hoff's factor i of the salt (NaCl 2)").def(2.0).at_least(1),
          number("cryoscopic_constant", "K_f of water").in("K kg/mol").def(1.86).above(0),
          number("diffusivity",
                 "D of the salt: NaCl's 1.5e-9 scaled up so the brine mixes within the run; the final state "
                 "does not depend on it")
              .in("m^2/s")
              .def(1e-7)
              .above(0),
          number("water_conductivity",
                 "k of water and brine (0.56); the final state does not depend on it, and the run's length "
                 "follows the slowest of the two diffusions")
              .in("W/m/K")
              .def(0.56)
              .above(0),
          number("equilibration",
                 "Run for this many of the slowest diffusion times, height^2 / min(D, alpha)")
              .def(2.0)
              .above(0)
              .at_most(50),
          number("ice_gate", "Gate on the ice left, relative to the reference's").def(0.02).above(0),
          number("temperature_gate", "Gate on T_f, relative to the reference's T_m - T_f").def(0.02).above(0),
          number("energy_gate", "Gate on the energy closure, relative to the column's latent heat")
              .def(1e-6)
              .above(0),
          number("salt_gate", "Gate on the salt's closure, relative to its total").def(1e-9).above(0),
          solver_schema_with({{"flow", false}, {"max_dt", 3600.0}}),
      });
}

struct Balance {
  double ice = 0, temperature = 0;  // m_I [kg], T_f [°C]
};

// The balance above, solved by bisection on m_I in [0, ice0]; all ice melts where even that leaves the
// column warmer than its liquidus (then T_f follows from the energy alone).
Balance solve_balance(double ice0, double brine0, double salt, double H0, double Tm, double L, double cs,
                      double cl, double moles_per_kg_salt, double Kf) {
  const double M = ice0 + brine0;
  auto liquidus = [&](double mI) { return Tm - Kf * moles_per_kg_salt * salt / (M - mI - salt); };
  auto excess = [&](double mI) {  // enthalpy at the liquidus with mI of ice left, less H0
    const double T = liquidus(mI);
    return mI * cs * (T - Tm) + (M - mI) * (L + cl * (T - Tm)) - H0;
  };
  Balance b;
  if (excess(0.0) < 0.0) {  // all melted, and warmer than the liquidus
    b.ice = 0.0;
    b.temperature = Tm + (H0 / M - L) / cl;
    return b;
  }
  double lo = 0.0, hi = ice0;  // excess(lo) >= 0 >= excess(hi)
  if (excess(hi) > 0.0)
    throw Error("brine-melting: the column does not melt any ice (its start is at the liquidus)");
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (excess(mid) >= 0.0 ? lo : hi) = mid;
  }
  b.ice = 0.5 * (lo + hi);
  b.temperature = liquidus(b.ice);
  return b;
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double hi_ice = prm["ice_height"], hb = prm["brine_height"], T0 = prm["temperature"];
  const double dx = hi_ice / res;
  const double width = 4.0 * dx;
  const Json settings = prm["solver"];
  if (settings["flow"].get<bool>())
    throw SceneError("solver.flow", "the brine-melting case holds particles in place: it needs flow = false");
  const double kw = prm["water_conductivity"];
  const Json doc = {
      {"name", "validation/brine-melting"},
      {"domain", {{"min", {0.0, 0.0, 0.0}}, {"max", {width, width, hi_ice + hb}}}},
      {"gravity", {0, 0, 0}},
      {"spacing", dx},
      {"solver", settings},
      {"ambient", {{"heat_transfer_coefficient", 0.0}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"},
          {"density", 1000.0},
          {"conductivity", kw},
          {"specific_heat", 4217.0},
          {"cryoscopic_constant", prm["cryoscopic_constant"]}}},
        {"ice",
         {{"kind", "ice"},
          {"density", 917.0},
          {"conductivity", 2.22},
          {"specific_heat", 2050.0},
          {"melts_into", "water"}}}}},
      {"substances",
       {{"salt",
         {{"diffusivity", prm["diffusivity"]},
          {"molar_mass", prm["molar_mass"]},
          {"dissociation", prm["dissociation"]}}}}},
      {"ice",
       {{{"material", "ice"},
         {"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {width, width, hi_ice}}}},
         {"temperature", T0}}}},
      {"fluids",
       {{{"material", "water"},
         {"box", {{"min", {0.0, 0.0, hi_ice}}, {"max", {width, width, hi_ice + hb}}}},
         {"temperature", T0},
         // kg of salt per m^3 of brine: the salinity times the particle's mass per its volume.
         {"substances", {{"salt", {{"concentration", double(prm["salinity"]) * 1000.0}}}}}}}},
  };
  const Scene scene = scene_from_json(doc);
  const SimState st = initial_state(scene);
  const std::vector<thermal::MaterialThermal> table = material_thermal_table(scene, 1000.0);
  auto physical = [&](const HostParticles& p, std::size_t i) {
    return double(p.position[i][3]) * table[p.material[i]].thermal_mass_scale;
  };

  Solver solver(cl, scene, st);
  solver.warm_up();
  const thermal::MaterialThermal& ice_law = table[static_cast<std::size_t>(scene.ice[0].material)];
  const double L = ice_law.latent, Tm = ice_law.melt, cs = ice_law.c_solid, cw = ice_law.c_liquid;
  // The start's masses and enthalpy, as the particles have them.
  const HostParticles p0 = solver.particles();
  double ice0 = 0, brine0 = 0, H0 = 0;
  for (std::size_t i = 0; i < p0.size(); ++i) {
    const double m = physical(p0, i);
    (p0.phase[i] == std::uint8_t(Phase::Ice) ? ice0 : brine0) += m;
    H0 += m * (double(p0.enthalpy[i][0]) + double(p0.enthalpy[i][1]));
  }
  const double salt = solver.substance_books().initial.at(0);
  const Substance& sub = scene.substances[0];
  const double Kf = scene.materials[static_cast<std::size_t>(scene.fluids[0].material)].cryoscopic_constant;
  const Balance ref =
      solve_balance(ice0, brine0, salt, H0, Tm, L, cs, cw, sub.dissociation / sub.molar_mass, Kf);

  const double alpha =
      std::min({kw / (1000.0 * 4217.0), 2.22 / (917.0 * 2050.0), double(prm["diffusivity"])});
  const double height = hi_ice + hb;
  const double t_end = double(prm["equilibration"]) * height * height / alpha;
  const auto t0 = std::chrono::steady_clock::now();
  while (solver.time() < t_end * (1.0 - 1e-12)) solver.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // The ice left: each particle's solid fraction under its own melt shift, times its mass.
  const HostParticles p = solver.particles();
  const std::vector<float> shift = solver.melt_shifts(), T = solver.temperatures();
  double ice = 0, mean_T = 0, mass = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double m = physical(p, i), h = double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]);
    ice += m * (1.0 - thermal::thermal_liquid_fraction_lowered(h, L, cs, cw, double(shift.at(i))));
    mean_T += m * T[i];
    mass += m;
  }
  mean_T /= mass;
  const EnergyBudget& budget = solver.energy_budget();
  const double energy_closure = solver.total_enthalpy() - budget.initial - budget.heat_in();
  const double salt_closure = solver.substance_totals().at(0) - salt;

  CaseResult r;
  r.particles = p.size();
  r.steps = solver.steps();
  r.wall_s = wall;
  r.metrics = {
      {"ice_left", {ice, ref.ice, std::abs(ice - ref.ice) / ref.ice, prm["ice_gate"]}},
      {"temperature",
       {mean_T, ref.temperature, std::abs(mean_T - ref.temperature) / (Tm - ref.temperature),
        prm["temperature_gate"]}},
      {"energy_closure",
       {energy_closure, 0.0, std::abs(energy_closure) / (L * (ice0 + brine0)), prm["energy_gate"]}},
      {"salt_closure", {salt_closure, 0.0, std::abs(salt_closure) / salt, prm["salt_gate"]}},
  };
  return r;
}

}  // namespace

ValidationCase brine_melting_case() {
  return {"brine-melting",
          "Ice in brine below 0 °C melts until the brine's liquidus meets the temperature reached: the ice "
          "left and that temperature against the energy and salt balance (gates 2 %); res = particles across "
          "the ice's height",
          6, params, run};
}

}  // namespace thaw
