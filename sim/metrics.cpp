#include "sim/metrics.h"

#include <cmath>

#include "sim/solver.h"

namespace thaw {

Metrics measure(const HostParticles& p, const Scene& scene, double rest_density) {
  Metrics m;
  double err_sum = 0;
  std::size_t fluid = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto phase = static_cast<Phase>(p.phase[i]);
    ++m.count[static_cast<int>(phase)];
    if (phase == Phase::Solid) continue;
    const auto& x = p.position[i];
    const auto& v = p.velocity[i];
    const double mass = x[3];
    const double v2 = double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2];
    m.max_speed = std::max(m.max_speed, std::sqrt(v2));
    m.fluid_mass += mass;
    m.kinetic += 0.5 * mass * v2;
    m.potential -= mass * (scene.gravity.x() * x[0] + scene.gravity.y() * x[1] + scene.gravity.z() * x[2]);
    // Compression only: a free-surface particle's summation density is low for lack of neighbours,
    // not because the fluid expanded.
    const double e = std::max(0.0, (p.density[i] - rest_density) / rest_density);
    m.max_density_error = std::max(m.max_density_error, e);
    err_sum += e;
    ++fluid;
  }
  m.mean_density_error = fluid ? err_sum / double(fluid) : 0.0;
  return m;
}

Metrics measure(const Solver& s) {
  Metrics m = measure(s.particles(), s.scene(), s.constants().rest_density);
  m.time = s.time();
  m.dt = s.dt();
  m.steps = s.steps();
  m.clamped = s.clamped();
  return m;
}

Json metrics_json(const Metrics& m, double wall_ms_per_step, const Json& stage_ms_per_step) {
  Json j;
  j["time"] = m.time;
  j["steps"] = m.steps;
  j["dt"] = m.dt;
  j["wall_ms_per_step"] = wall_ms_per_step;
  j["stage_ms_per_step"] = stage_ms_per_step;
  Json counts;
  for (int i = 0; i < kPhaseCount; ++i) counts[phase_name(static_cast<Phase>(i))] = m.count[i];
  j["particles"] = counts;
  j["clamped"] = m.clamped;
  j["max_speed"] = m.max_speed;
  j["max_density_error"] = m.max_density_error;
  j["mean_density_error"] = m.mean_density_error;
  j["total_mass"] = m.fluid_mass;
  j["energy"] = {{"kinetic", m.kinetic}, {"potential", m.potential}, {"mechanical", m.kinetic + m.potential}};
  return j;
}

}  // namespace thaw
