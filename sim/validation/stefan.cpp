// The Stefan problem (docs/VALIDATION-RESULTS.md): a slab x > 0, initially at initial_temperature, with the
// wall at x < 0 held at wall_temperature from t = 0. Melting when the wall is above the melting point and
// the slab is ice at or below it; freezing when the wall is below and the slab is water at or above it.
// Reference: Neumann's similarity solution for these parameters (sim/validation/heat_reference.h).
// The slab is thin and periodic in y and z (a 1-D problem), particles stay in place (solver.flow =
// false, equal densities), and its far end is insulated at far_length diffusion lengths of the far phase.
// Metrics: the front s = sum(converted fraction * V) / A against s(t), and the energy balance: the heat
// the held wall gave equals the slab's enthalpy gain. res = particles across the reference front s(time).
#include <chrono>
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/thermal.h"
#include "sim/validation/case.h"
#include "sim/validation/heat_reference.h"

namespace thaw {
namespace {

Field params() {
  return object(
      "",
      {
          number("wall_temperature", "T_w, held from t = 0").in("°C").def(10.0).above(-273.15),
          number("initial_temperature", "T_0 of the slab").in("°C").def(-10.0).above(-273.15),
          number("time", "Simulated time").in("s").def(600.0).above(0),
          number("melting_point", "T_m").in("°C").def(0.0),
          number("latent_heat", "L").in("J/kg").def(334000.0).above(0),
          number("density", "rho of both phases (equal, so the melt neither shrinks nor moves)")
              .in("kg/m^3")
              .def(1000.0)
              .above(0),
          number("water_conductivity", "k of water").in("W/m/K").def(0.56).above(0),
          number("water_specific_heat", "c of water").in("J/kg/K").def(4217.0).above(0),
          number("ice_conductivity", "k of ice").in("W/m/K").def(2.22).above(0),
          number("ice_specific_heat", "c of ice").in("J/kg/K").def(2050.0).above(0),
          integer("cross_section", "Particles across the periodic y and z extent")
              .def(6)
              .at_least(6)
              .at_most(64),
          number("far_length", "Slab length beyond the front, in diffusion lengths sqrt(alpha_far t)")
              .def(4.0)
              .at_least(1),
          number("front_gate", "Gate on |s - s_exact| / s_exact").def(0.02).above(0),
          number("energy_gate", "Gate on |enthalpy gain - wall heat| / wall heat").def(0.001).above(0),
          solver_schema_with({{"flow", false}, {"periodic", Json::array({"y", "z"})}, {"max_dt", 3600.0}}),
      });
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double Tw = prm["wall_temperature"], T0 = prm["initial_temperature"], Tm = prm["melting_point"];
  const double L = prm["latent_heat"], rho = prm["density"], t_end = prm["time"];
  const ThermalPhase water{prm["water_conductivity"], prm["water_specific_heat"], rho};
  const ThermalPhase ice{prm["ice_conductivity"], prm["ice_specific_heat"], rho};
  if (Tw == Tm) throw SceneError("wall_temperature", "equals the melting point: nothing melts or freezes");
  const bool melting = Tw > Tm;
  if (melting && T0 > Tm)
    throw SceneError("initial_temperature", "melting needs ice at or below the melting point");
  if (!melting && T0 < Tm)
    throw SceneError("initial_temperature", "freezing needs water at or above the melting point");
  const ThermalPhase near = melting ? water : ice, far = melting ? ice : water;
  const NeumannStefan ref = solve_neumann_stefan(near, far, Tw, T0, Tm, L);
  const double s_end = ref.front(t_end);
  const double dx = s_end / res;
  // An isothermal far side (T0 = T_m) has no diffusion to contain: a few spacings past the front do.
  const double far_len =
      T0 == Tm ? 0.5 * s_end + 4 * dx : double(prm["far_length"]) * std::sqrt(far.diffusivity() * t_end);
  const double length = std::ceil((s_end + far_len) / dx) * dx;
  const double W = int(prm["cross_section"]) * dx;
  const Json settings = prm["solver"];
  if (settings["flow"].get<bool>())
    throw SceneError("solver.flow", "the Stefan case holds particles in place: it needs flow = false");
  const double wall = std::ceil(double(settings["support_ratio"])) * dx;

  const Json block = {{"min", {0.0, 0.0, 0.0}}, {"max", {length, W, W}}};
  Json doc = {
      {"name", "validation/stefan"},
      {"domain", {{"min", {-wall, 0.0, 0.0}}, {"max", {length, W, W}}}},
      {"gravity", {0, 0, 0}},
      {"spacing", dx},
      {"solver", settings},
      {"ambient", {{"heat_transfer_coefficient", 0.0}, {"temperature", T0}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"},
          {"density", rho},
          {"conductivity", water.conductivity},
          {"specific_heat", water.specific_heat}}},
        {"ice",
         {{"kind", "ice"},
          {"density", rho},
          {"conductivity", ice.conductivity},
          {"specific_heat", ice.specific_heat},
          {"melts_into", "water"},
          {"latent_heat", L},
          {"melting_point", Tm}}},
        // The wall conducts like the phase that forms at it, so holding its particles at T_w holds the
        // material just left of x = 0 at T_w: the boundary sits at x = 0, not half a spacing inside.
        {"wall",
         {{"kind", "solid"},
          {"density", rho},
          {"conductivity", near.conductivity},
          {"specific_heat", near.specific_heat}}}}},
      {"solids",
       {{{"shape", "box"},
         {"material", "wall"},
         {"box", {{"min", {-wall, 0.0, 0.0}}, {"max", {0.0, W, W}}}},
         {"temperature", Tw},
         {"hold_temperature", true}}}},
  };
  if (melting)
    doc["ice"] = {{{"material", "ice"}, {"box", block}, {"temperature", T0}}};
  else
    doc["fluids"] = {{{"material", "water"}, {"box", block}, {"temperature", T0}}};
  const Scene scene = scene_from_json(doc);
  const SimState st = initial_state(scene);

  Solver solver(cl, scene, st);
  solver.warm_up();
  const auto t0 = std::chrono::steady_clock::now();
  while (solver.time() < t_end * (1.0 - 1e-12)) solver.step();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // The front as the converted volume per area: each slab particle holds dx^3 and converts by its
  // liquid fraction f (melting) or 1 - f (freezing).
  const auto table = material_thermal_table(scene, rho);
  const HostParticles q = solver.particles();
  double converted = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (q.phase[i] == static_cast<std::uint8_t>(Phase::Solid)) continue;
    const double f = liquid_fraction_at(table[q.material[i]], double(q.enthalpy[i][0]) + q.enthalpy[i][1]);
    converted += (melting ? f : 1.0 - f) * dx * dx * dx;
  }
  const double t = solver.time();
  const double s = converted / (W * W);
  const double s_ref = ref.front(t);
  const EnergyBudget& b = solver.energy_budget();
  const double gain = solver.total_enthalpy() - b.initial;
  const double wall_heat = b.held;
  const double closure = std::abs(gain - wall_heat) / std::abs(wall_heat);

  CaseResult r;
  r.particles = q.size();
  r.steps = solver.steps();
  r.wall_s = wall_s;
  r.metrics = {
      {"front", {s, s_ref, std::abs(s - s_ref) / s_ref, prm["front_gate"]}},
      {"energy_balance", {gain, wall_heat, closure, prm["energy_gate"]}},
  };
  return r;
}

}  // namespace

ValidationCase stefan_case() {
  return {
      "stefan",
      "melting or freezing slab against Neumann's solution: front within 2 %, energy balance within 0.1 %; "
      "res = particles across the front; its error is flat in res (docs/VALIDATION-RESULTS.md), so the "
      "default is the smallest, 5",
      5, params, run};
}

}  // namespace thaw
