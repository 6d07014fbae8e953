#pragma once
// What a run reports per output interval (`--metrics FILE.jsonl`): conserved sums in double.
#include "sim/books.h"
#include "sim/emitters.h"
#include "sim/particles.h"
#include "sim/scene.h"

namespace thaw {

class Solver;

struct Metrics {
  double time = 0, dt = 0;
  std::uint64_t steps = 0;
  std::uint64_t clamped = 0;
  std::size_t count[kPhaseCount] = {};
  double max_speed = 0;          // over moving particles [m/s]
  double max_density_error = 0;  // max (rho - rho0) / rho0 over fluid particles (compression)
  double mean_density_error = 0;
  double fluid_mass = 0;  // [kg], summed in double
  double kinetic = 0;     // [J]
  double potential = 0;   // [J], -sum m g.x
  // Heat (scenes with heat.enabled): physical masses, temperatures over ice and water, and the budget.
  bool heat = false;
  double water_mass = 0, ice_mass = 0;                                    // [kg]
  double min_temperature = 0, mean_temperature = 0, max_temperature = 0;  // [°C]
  // Air particles (scenes with `air`): their mass and temperatures, apart from the ice and water's.
  double air_mass = 0;                                                                // [kg]
  double air_min_temperature = 0, air_mean_temperature = 0, air_max_temperature = 0;  // [°C]
  double enthalpy = 0;                                                                // total sum m h [J]
  double enthalpy_scale = 0;  // sum m |h| [J]: the size round-off is measured against
  EnergyBudget budget;
  OutflowBooks outflow;  // what left through open sides
  InflowBooks inflow;    // what came in through emitters
  double closure() const { return enthalpy - budget.initial - budget.heat_in(); }
  // Rigid ice (scenes with free ice): one object per body (label, particles, mass, fixed, centre,
  // velocity, angular velocity) and the labelling counters; null otherwise.
  Json bodies;
  // DFSPH (solver.pressure dfsph): the last step's solves and the run's counts; null otherwise.
  Json pressure_solve;
  // Substances (scenes that declare them): by name, the total now, at the start, what left through open
  // sides and what emitters poured [kg], and the closure total + outflow - initial - inflow (absolute, and
  // relative to initial + inflow); null otherwise.
  Json substances;
};

// What a solver reports of its substances, as Metrics::substances (null without substances).
Json substances_json(const Solver& solver);

// What a DFSPH solver reports of its solves (null for WCSPH).
Json pressure_solve_json(const Solver& solver);

// The bodies of a solver's rigid ice as Metrics::bodies writes them (null without rigid ice).
Json bodies_json(const Solver& solver);

Metrics measure(const HostParticles& p, const Scene& scene, double rest_density);
Metrics measure(const Solver& solver);

// One JSON line: the metrics plus the wall-clock figures of the interval.
Json metrics_json(const Metrics& m, double wall_ms_per_step, const Json& stage_ms_per_step);

}  // namespace thaw
