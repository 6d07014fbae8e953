#pragma once
// What the renderer draws: a read-only copy of the particles taken between simulation steps, so that
// rendering never touches the simulation's buffers (docs/ARCHITECTURE.md: render reads a snapshot).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "sim/particles.h"
#include "sim/scene.h"

namespace thaw {

// A hair dryer as drawn: a nozzle (a short cylinder behind `position`, pointing along `direction`) and,
// while it blows, a faint cone of its reach and half-angle, so aiming shows in the picture.
struct DryerMarker {
  Eigen::Vector3f position = Eigen::Vector3f::Zero(), direction = -Eigen::Vector3f::UnitZ();  // [m], unit
  float nozzle_radius = 0.02f, half_angle = 15.0f, reach = 0.3f;                              // m, deg, m
  bool on = true;
};

// A radiant lamp as drawn: its emitting rectangle, centre +- half_u +- half_v (the axes the photon
// tracer uses), glowing by its temperature while on, a dark panel when off or seen from behind.
struct LampMarker {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero(), half_u = Eigen::Vector3f::UnitX(),
                  half_v = Eigen::Vector3f::UnitY();  // [m]
  float temperature = 500.0f;                         // [°C]
  bool on = true;
};

struct RenderSnapshot {
  std::vector<Eigen::Vector3f> position;  // [m]
  std::vector<std::uint8_t> phase;        // thaw::Phase
  std::vector<std::uint8_t> glass;        // 1 for a solid particle of a transparent material; empty: none
  std::vector<float> temperature;         // [°C]; empty when the scene has no heat
  std::vector<float> speed;               // |v| [m/s]
  // Each substance the scene declares, by name: its concentration in each particle [kg/m^3 = g/L], bulk and
  // surface amounts over the particle's volume at its material's rest density (0 where it holds none).
  std::vector<std::pair<std::string, std::vector<float>>> substances;
  std::vector<std::array<float, 3>>
      substance_colours;  // each one's colour (Substance::colour), in that order
  // Each coating the scene declares, by name: what sticks to each solid or ice particle per area of its face
  // [kg/m^2] (0 elsewhere).
  std::vector<std::pair<std::string, std::vector<float>>> deposits;
  std::vector<float> deposit_capacity;  // each coating's Gamma_R,max [kg/m^2] in that order; 0: no limit
  // The scene's dryers as they are at this step, then its taps (emitters): a tap is drawn as a dryer's
  // nozzle that never blows (on = false), its radius the nozzle's.
  std::vector<DryerMarker> dryers;
  std::vector<LampMarker> lamps;  // and its lamps
  float spacing = 0;              // particle spacing [m]
  Eigen::Vector3f domain_min = Eigen::Vector3f::Zero(), domain_max = Eigen::Vector3f::Zero();
  Eigen::Vector3f bounds_min = Eigen::Vector3f::Zero(),
                  bounds_max = Eigen::Vector3f::Zero();  // of every particle
  double time = 0;
  std::uint64_t step = 0;
};

// `temperature` may be empty; otherwise one per particle in p's order.
RenderSnapshot make_snapshot(const HostParticles& p, const std::vector<float>& temperature,
                             const Scene& scene, double time, std::uint64_t step);

}  // namespace thaw
