// Ice and brine below 0 °C settling to their phase diagram (issues 20 and 44; docs/SUBSTANCES.md): a column
// of ice under a column of brine, the brine above its liquidus, particles held in place (flow off), no heat
// in or out. Two cases share it:
//   brine-melting: both at T0 below 0 °C. Salt lowers the water's melting point (the salt's liquidus,
//     sim/kernels/liquidus.h), so the ice next to the brine melts, taking its latent heat from the column:
//     the column cools, and the meltwater dilutes the brine until its liquidus meets the temperature reached.
//   brine-freezing: the ice far colder than the eutectic. The brine cools, freezes part-way as its liquidus
//     falls (rejecting its salt into what is left), reaches the eutectic and freezes through there, and the
//     whole column ends solid below the eutectic.
// Reference, from the energy and salt balance of the closed, adiabatic column: the solid left m_I and the
// temperature T_f with
//   H0 = m_I c_s (T_f - T_m) + (M - m_I) (L + c_l (T_f - T_m)),   T_f = T_m - D(S, M - m_I),
// H0 the column's enthalpy at the start, M its mass, S its salt and D(S, melt) the liquidus of a melt of that
// mass holding S, capped at the eutectic (where the solid grows by the lever rule at T_e); past the eutectic
// with no melt left, T_f = T_m + H0 / (M c_s). Metrics: the solid left and the temperature reached against
// those, the coldest melt of the run against the eutectic (none may be colder), and the energy and salt
// closures. res = particles across the ice's height.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "sim/error.h"
#include "sim/kernels/liquidus.h"
#include "sim/solver.h"
#include "sim/thermal.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

struct Defaults {
  double ice_height, ice_temperature;
};

Field params(Defaults d) {
  return object(
      "",
      {
          number("ice_height", "Height of the ice column").in("m").def(d.ice_height).above(0),
          number("brine_height", "Height of the brine above it").in("m").def(0.006).above(0),
          number("temperature", "T0 of the brine at the start, above its liquidus")
              .in("°C")
              .def(-5.0)
              .above(-30)
              .below(0),
          number("ice_temperature", "T0 of the ice at the start")
              .in("°C")
              .def(d.ice_temperature)
              .above(-200)
              .at_most(0),
          number("salinity",
                 "The brine's salt at the start, kg per kg of brine (NaCl's eutectic 0.233, its "
                 "solubility 0.263)")
              .def(0.1)
              .above(0)
              .below(1),
          choice("liquidus", {"crc_nacl", "blagden"},
                 "The salt's liquidus: NaCl's measured one to its eutectic, or Blagden's dilute law (from "
                 "molar_mass, dissociation and cryoscopic_constant)")
              .def("crc_nacl"),
          number("molar_mass", "M of the salt (NaCl 0.05844; blagden)").in("kg/mol").def(0.05844).above(0),
          number("dissociation", "van 't Hoff's factor i of the salt (NaCl 2; blagden)").def(2.0).at_least(1),
          number("cryoscopic_constant", "K_f of water (blagden)").in("K kg/mol").def(1.86).above(0),
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
          number("ice_gate", "Gate on the solid left, relative to the reference's").def(0.02).above(0),
          number("temperature_gate", "Gate on T_f, relative to the reference's T_m - T_f").def(0.02).above(0),
          number("eutectic_gate",
                 "Gate on how far the coldest melt of the run lies below the eutectic, relative to T_m - T_e")
              .def(1e-5)
              .above(0),
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

// The balance above. E(m_I), the enthalpy at the liquidus with m_I of solid, falls as m_I grows (the melt
// shrinks, its liquidus falls, down to the eutectic, where the lever rule goes on): bisection on m_I in
// [0, M]. Past either end: all melted and warmer than the liquidus, or all solid and colder than the
// eutectic, where T_f follows from the energy alone.
Balance solve_balance(double M, double salt, double H0, double Tm, double L, double cs, double cl,
                      const thermal::Liquidus& lq, double Kf) {
  auto liquidus = [&](double mI) {
    const double q[1] = {salt};
    return Tm - thermal::liquidus_drop(&lq, 1, q, M - mI, Kf);
  };
  auto excess = [&](double mI) {  // enthalpy at the liquidus with mI of solid left, less H0
    const double T = liquidus(mI);
    return mI * cs * (T - Tm) + (M - mI) * (L + cl * (T - Tm)) - H0;
  };
  Balance b;
  if (excess(0.0) < 0.0) {  // all melted, and warmer than the liquidus
    b.ice = 0.0;
    b.temperature = Tm + (H0 / M - L) / cl;
    return b;
  }
  if (excess(M) > 0.0) {  // all solid, colder than the eutectic
    b.ice = M;
    b.temperature = Tm + H0 / (M * cs);
    return b;
  }
  double lo = 0.0, hi = M;  // excess(lo) >= 0 >= excess(hi)
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
  const double T_ice = prm["ice_temperature"];
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
          {"dissociation", prm["dissociation"]},
          {"liquidus", prm["liquidus"]}}}}},
      {"ice",
       {{{"material", "ice"},
         {"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {width, width, hi_ice}}}},
         {"temperature", T_ice}}}},
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
  const double Kf = scene.materials[static_cast<std::size_t>(scene.fluids[0].material)].cryoscopic_constant;
  const thermal::Liquidus lq = liquidus_table(scene).at(0);
  const Balance ref = solve_balance(ice0 + brine0, salt, H0, Tm, L, cs, cw, lq, Kf);
  const double eutectic = Tm - double(lq.cap);  // T_e [°C] as the kernels have it

  const double alpha =
      std::min({kw / (1000.0 * 4217.0), 2.22 / (917.0 * 2050.0), double(prm["diffusivity"])});
  const double height = hi_ice + hb;
  const double t_end = double(prm["equilibration"]) * height * height / alpha;
  // The coldest melt of the run: any particle with some liquid, at its temperature under its own shift,
  // looked at 200 times over the run (between, the stepping is timed).
  double coldest = std::numeric_limits<double>::infinity();
  auto look = [&] {
    const HostParticles p = solver.particles();
    const std::vector<float> shift = solver.melt_shifts();
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double h = double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]), d = double(shift.at(i));
      if (thermal::thermal_liquid_fraction_lowered(h, L, cs, cw, d) > 0)
        coldest = std::min(coldest, thermal::thermal_temperature_lowered(h, L, Tm, cs, cw, d));
    }
  };
  double wall = 0;
  for (int n = 1; n <= 200; ++n) {
    const auto t0 = std::chrono::steady_clock::now();
    while (solver.time() < t_end * n / 200.0 * (1.0 - 1e-12)) solver.step();
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    look();
  }

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
      {"coldest_melt",
       {std::isfinite(coldest) ? coldest : eutectic, eutectic,
        std::isfinite(coldest) ? std::max(0.0, eutectic - coldest) / (Tm - eutectic) : 0.0,
        prm["eutectic_gate"]}},
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
          "left and that temperature against the energy and salt balance (gates 2 %), no melt below the "
          "eutectic; res = particles across the ice's height",
          6,
          [] {
            return params({0.006, -5.0});
          },
          run};
}

ValidationCase brine_freezing_case() {
  return {"brine-freezing",
          "Brine on ice at -100 °C freezes through at its eutectic and the column ends solid below it: the "
          "solid and the temperature against the energy and salt balance (gates 2 %), no melt below the "
          "eutectic; res = particles across the ice's height",
          9,
          [] {
            return params({0.018, -100.0});
          },
          run};
}

}  // namespace thaw
