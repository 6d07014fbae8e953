#pragma once
// A run's books: its energy account, what left through open sides and each substance's account. The solver
// keeps them; state files carry them (sim/state_file.h); metrics close them (sim/metrics.h).
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace thaw {

// The run's energy account [J]: enthalpy at the start and the heat that came in since, by source.
// Closure: total enthalpy now - initial - heat_in() is round-off (conduction and phase change move
// heat only between particles).
struct EnergyBudget {
  double initial = 0;
  double ambient = 0, lamps = 0, dryers = 0, walls = 0, held = 0;
  double lamp_emitted = 0, lamp_escaped = 0;  // photons: emitted = absorbed (lamps) + escaped
  double outflow = 0;  // enthalpy m h carried out by water that left through an open side
  double inflow = 0;   // enthalpy m h brought in by emitters
  double heat_in() const { return ambient + lamps + dryers + walls + held - outflow + inflow; }
  std::vector<double> to_vector() const;
  // Throws Error on a wrong length; files written before outflow existed have 8 entries (outflow 0),
  // before inflow 9.
  static EnergyBudget from_vector(const std::vector<double>& v);
};

// What left through the domain's open sides (Scene::open_faces): particles, their physical mass [kg] and
// momentum [kg m/s]. Mass closes: the fluid's mass now + mass = its mass at the start.
struct OutflowBooks {
  std::uint64_t particles = 0;
  double mass = 0;
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  std::vector<double> to_vector() const {
    return {double(particles), mass, momentum.x(), momentum.y(), momentum.z()};
  }
  static OutflowBooks from_vector(const std::vector<double>& v);  // empty: nothing has left
};

// Each substance's account [kg] (sim/substance_stage.h), in the scene's order: its total at the start, what
// left through open sides since and what emitters poured. Closure: the total now + outflow = initial +
// inflow, to round-off.
struct SubstanceBooks {
  std::vector<double> initial, outflow, inflow;
  double closure(std::size_t s, double total) const { return total + outflow[s] - initial[s] - inflow[s]; }
  std::vector<double> to_vector() const;  // initial, outflow, inflow
  // Throws Error unless `v` holds three entries per substance (3 * count).
  static SubstanceBooks from_vector(const std::vector<double>& v, std::size_t count);
};

}  // namespace thaw
