#include "sim/particles.h"

#include <algorithm>

namespace thaw {

const char* phase_name(Phase p) {
  switch (p) {
    case Phase::Water: return "water";
    case Phase::Ice: return "ice";
    case Phase::Solid: return "solid";
    case Phase::Air: return "air";
  }
  return "unknown";
}

std::array<std::uint8_t, 3> phase_colour(std::uint8_t phase) {
  switch (static_cast<Phase>(phase)) {
    case Phase::Water: return {40, 110, 230};
    case Phase::Ice: return {200, 240, 255};
    case Phase::Solid: return {150, 150, 150};
    case Phase::Air: return {255, 255, 255};
  }
  return {255, 0, 255};
}

void HostParticles::resize(std::size_t n) {
  position.resize(n);
  velocity.resize(n);
  density.resize(n);
  phase.resize(n);
  material.resize(n);
  id.resize(n);
  enthalpy.resize(n);
  anchored.resize(n);
}

std::size_t HostParticles::count(Phase p) const {
  return static_cast<std::size_t>(std::count(phase.begin(), phase.end(), static_cast<std::uint8_t>(p)));
}

}  // namespace thaw
