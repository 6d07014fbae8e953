// Substance conservation with everything on (issue 20; docs/SUBSTANCES.md): a tank where dyed and painted
// brine melts a block of ice, a plate held cold freezes the dyed fresh water over it, a tap pours dyed and
// painted water in and the water runs out through the open +x side, with the flow on; the paint (a coating)
// sticks to the walls and the ice, and the salt cleanses a tile of the paint it starts with. Reference:
// each substance's total now plus what left equals its start plus what was poured, to round-off. Metrics:
// the largest closure over the run's output times, relative to start plus poured, for each substance; and
// how many of the six mechanisms (melting, freezing, pouring, outflow, coating the ice, cleansing the tile)
// the run exercised, which must be all. res = particles across the ice block.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/substance_stage.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

Field params() {
  return object("",
                {
                    number("duration", "Simulated time").in("s").def(0.3).above(0).at_most(10),
                    number("time_scale",
                           "heat.time_scale: heat runs this much faster than the flow, so ice melts and "
                           "water freezes within the run")
                        .def(1000.0)
                        .above(0)
                        .at_most(1e4),
                    number("salinity", "Salt in the brine").in("kg/m^3").def(35.0).at_least(0).at_most(250),
                    number("dye", "Dye in the brine and in what the tap pours")
                        .in("kg/m^3")
                        .def(2.0)
                        .above(0)
                        .at_most(100),
                    number("paint",
                           "A coating in the brine and in what the tap pours; it sticks to the walls and the "
                           "ice, and the salt takes it back off a painted tile")
                        .in("kg/m^3")
                        .def(2.0)
                        .above(0)
                        .at_most(100),
                    number("closure_gate", "Gate on the largest closure, relative to start plus poured")
                        .def(1e-9)
                        .above(0),
                    solver_schema_with({}),
                });
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double side = 0.008, dx = side / res;
  const Json doc = {
      {"name", "validation/conservation"},
      {"domain",
       {{"min", {0.0, 0.0, 0.0}},
        {"max", {0.04, 0.02, 0.04}},
        {"walls", {"-x", "-y", "+y", "-z"}},
        {"wall_material", "glass"},
        {"open", {"+x"}}}},
      {"spacing", dx},
      {"solver", prm["solver"]},
      {"heat", {{"time_scale", prm["time_scale"]}}},
      {"ambient", {{"temperature", 10.0}, {"heat_transfer_coefficient", 0.0}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"},
          {"density", 1000.0},
          {"viscosity", 0.001},
          {"conductivity", 0.56},
          {"specific_heat", 4217.0}}},
        {"ice",
         {{"kind", "ice"},
          {"density", 917.0},
          {"conductivity", 2.22},
          {"specific_heat", 2050.0},
          {"melts_into", "water"}}},
        {"glass", {{"kind", "solid"}, {"density", 2500.0}, {"conductivity", 1.0}, {"specific_heat", 800.0}}},
        {"tile", {{"kind", "solid"}, {"density", 2300.0}, {"conductivity", 1.5}, {"specific_heat", 850.0}}},
        {"steel",
         {{"kind", "solid"}, {"density", 7800.0}, {"conductivity", 50.0}, {"specific_heat", 500.0}}}}},
      {"substances",
       {{"salt", {{"diffusivity", 1.5e-9}, {"liquidus", "crc_nacl"}}},
        {"dye", {{"diffusivity", 1e-9}}},
        // Filling its capacity within 5 ms at the paint's concentration, and cleansed by the brine at 3.5 /
        // s.
        {"paint",
         {{"kind", "coating"},
          {"diffusivity", 1e-9},
          {"coating_rate", 1e-4},
          {"coating_capacity", 4e-5},
          {"cleansed_by", "salt"},
          {"cleansing_rate", 0.1}}}}},
      {"solids",
       {{{"material", "steel"},
         {"shape", "box"},
         {"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {0.012, 0.02, 0.004}}}},
         {"temperature", -30.0},
         {"hold_temperature", true}},
        // A tile in the brine, painted to the paint's capacity: the salt takes paint off and none sticks.
        {{"material", "tile"},
         {"shape", "box"},
         {"box", {{"min", {0.014, 0.002, 0.0}}, {"max", {0.018, 0.006, 0.004}}}},
         {"temperature", 10.0},
         {"deposits", {{"paint", {{"deposit", 4e-5}}}}}}}},
      {"ice",
       {{{"material", "ice"},
         {"box", {{"min", {0.02, 0.006, 0.0}}, {"max", {0.02 + side, 0.006 + side, side}}}},
         // At its melting point, so the brine's first touch melts it, however the flow goes.
         {"temperature", 0.0}}}},
      // Fresh dyed water over the cold plate freezes (brine would not freeze through: docs/SUBSTANCES.md);
      // dyed brine beside the ice melts it.
      {"fluids",
       {{{"material", "water"},
         {"box", {{"min", {0.0, 0.0, 0.004}}, {"max", {0.012, 0.02, 0.012}}}},
         {"temperature", 1.0},
         {"substances", {{"dye", {{"concentration", prm["dye"]}}}}}},
        {{"material", "water"},
         {"box", {{"min", {0.012, 0.0, 0.0}}, {"max", {0.02, 0.02, 0.016}}}},
         {"temperature", 10.0},
         {"substances",
          {{"salt", {{"concentration", prm["salinity"]}}},
           {"dye", {{"concentration", prm["dye"]}}},
           {"paint", {{"concentration", prm["paint"]}}}}}}}},
      {"emitters",
       {{{"material", "water"},
         {"position", {0.03, 0.01, 0.034}},
         {"radius", std::max(0.003, 1.5 * dx)},
         {"speed", 0.5},
         {"temperature", 5.0},
         {"substances",
          {{"dye", {{"concentration", prm["dye"]}}}, {"paint", {{"concentration", prm["paint"]}}}}}}}},
  };
  const Scene scene = scene_from_json(doc);
  Solver solver(cl, scene, initial_state(scene));
  solver.warm_up();
  const std::size_t ice0 = solver.particles().count(Phase::Ice);
  std::vector<double> worst(scene.substances.size(), 0.0);
  std::size_t melted = 0, frozen = 0;
  auto check = [&] {
    const std::vector<double> total = solver.substance_totals();
    const SubstanceBooks& b = solver.substance_books();
    for (std::size_t k = 0; k < total.size(); ++k)
      worst[k] = std::max(worst[k], std::abs(b.closure(k, total[k])) / (b.initial[k] + b.inflow[k]));
  };
  // Melting and freezing, from the particles' phases by id (ice that melted, water that froze).
  std::vector<std::uint8_t> phase_of;
  auto phases = [&](bool count) {
    const HostParticles p = solver.particles();
    // Sized by the largest id, not the count: the tap's particles take new ids while the open side removes
    // others (docs/ARCHITECTURE.md, Determinism).
    const std::uint32_t top = p.size() ? *std::max_element(p.id.begin(), p.id.end()) : 0;
    if (phase_of.size() <= top) phase_of.resize(std::size_t(top) + 1, 255);
    for (std::size_t i = 0; i < p.size(); ++i) {
      std::uint8_t& before = phase_of[p.id[i]];
      if (count && before == std::uint8_t(Phase::Ice) && p.phase[i] == std::uint8_t(Phase::Water)) ++melted;
      if (count && before == std::uint8_t(Phase::Water) && p.phase[i] == std::uint8_t(Phase::Ice)) ++frozen;
      before = p.phase[i];
    }
  };
  // The coating: what sticks to the ice (coating), and what is left on the tile (cleansing takes it off).
  const std::string paint = deposited_field("paint").name;
  std::size_t tile = scene.materials.size();
  for (std::size_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].name == "tile") tile = m;
  double on_ice = 0, on_tile_start = -1, on_tile = 0;
  auto deposits = [&] {
    const HostParticles p = solver.particles();
    const HostColumn* c = p.column(paint);
    double ice = 0, on = 0;
    for (std::size_t i = 0; c && i < p.size(); ++i) {
      const double d = double(c->as<Float2>()[i][0]) + c->as<Float2>()[i][1];
      if (p.phase[i] == std::uint8_t(Phase::Ice)) ice += d;
      if (p.material[i] == tile) on += d;
    }
    on_ice = std::max(on_ice, ice);
    if (on_tile_start < 0) on_tile_start = on;
    on_tile = on;
  };
  phases(false);
  deposits();
  const double duration = prm["duration"], every = duration / 20.0;
  double next = every;
  const auto t0 = std::chrono::steady_clock::now();
  while (solver.time() < duration * (1.0 - 1e-12)) {
    solver.step();
    if (solver.time() >= next) {
      check();
      phases(true);
      deposits();
      next += every;
    }
  }
  check();
  phases(true);
  deposits();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int mechanisms = (melted > 0) + (frozen > 0) + (solver.inflow().particles > 0) +
                         (solver.outflow().particles > 0) + (on_ice > 0) + (on_tile < on_tile_start);
  if (mechanisms < 6)
    std::fprintf(
        stderr,
        "conservation: melted %zu, froze %zu, poured %llu, out %llu particles (of %zu ice); paint on "
        "ice %g kg at most, on the tile %g kg of %g\n",
        melted, frozen, (unsigned long long)solver.inflow().particles,
        (unsigned long long)solver.outflow().particles, ice0, on_ice, on_tile, on_tile_start);

  CaseResult r;
  r.particles = solver.size();
  r.steps = solver.steps();
  r.wall_s = wall;
  for (std::size_t k = 0; k < scene.substances.size(); ++k)
    r.metrics.push_back(
        {scene.substances[k].name + "_closure", {worst[k], 0.0, worst[k], prm["closure_gate"]}});
  r.metrics.push_back({"mechanisms", {double(mechanisms), 6.0, double(6 - mechanisms), 0.0}});
  return r;
}

}  // namespace

ValidationCase conservation_case() {
  return {
      "conservation",
      "Every substance's total through melting, freezing, a tap, an open side, coating and cleansing, with "
      "the flow on: the "
      "largest closure over the run against start plus poured (gate 1e-9); res = particles across the "
      "ice block",
      4, params, run};
}

}  // namespace thaw
