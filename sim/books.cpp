#include "sim/books.h"

#include <string>

#include "sim/error.h"

namespace thaw {

std::vector<double> EnergyBudget::to_vector() const {
  return {initial, ambient, lamps, dryers, walls, held, lamp_emitted, lamp_escaped, outflow, inflow};
}

OutflowBooks OutflowBooks::from_vector(const std::vector<double>& v) {
  OutflowBooks b;
  if (v.empty()) return b;
  if (v.size() != 5) throw Error("outflow has " + std::to_string(v.size()) + " entries, expected 5");
  b.particles = static_cast<std::uint64_t>(v[0]);
  b.mass = v[1];
  b.momentum = {v[2], v[3], v[4]};
  return b;
}

std::vector<double> SubstanceBooks::to_vector() const {
  std::vector<double> v = initial;
  v.insert(v.end(), outflow.begin(), outflow.end());
  v.insert(v.end(), inflow.begin(), inflow.end());
  return v;
}

SubstanceBooks SubstanceBooks::from_vector(const std::vector<double>& v, std::size_t count) {
  if (v.size() != 3 * count)
    throw Error("state: the substances' account has " + std::to_string(v.size()) + " entries; the scene's " +
                std::to_string(count) + " substances need " + std::to_string(3 * count));
  SubstanceBooks b;
  const auto at = [&](std::size_t k) { return v.begin() + static_cast<std::ptrdiff_t>(k * count); };
  b.initial.assign(at(0), at(1));
  b.outflow.assign(at(1), at(2));
  b.inflow.assign(at(2), at(3));
  return b;
}

EnergyBudget EnergyBudget::from_vector(const std::vector<double>& v) {
  if (v.size() < 8 || v.size() > 10)
    throw Error("energy budget has " + std::to_string(v.size()) +
                " entries, expected 10 (8 before outflow, 9 before inflow)");
  EnergyBudget b;
  b.initial = v[0];
  b.ambient = v[1];
  b.lamps = v[2];
  b.dryers = v[3];
  b.walls = v[4];
  b.held = v[5];
  b.lamp_emitted = v[6];
  b.lamp_escaped = v[7];
  if (v.size() > 8) b.outflow = v[8];
  if (v.size() > 9) b.inflow = v[9];
  return b;
}

}  // namespace thaw
