#include "sim/validation/hydrostatic_profile.h"

#include <cmath>

#include "sim/solver.h"

namespace thaw {

double HydrostaticProfile::F(double p) const {
  if (tait) return B / rho0 * gamma / (gamma - 1) * (std::pow(1 + p / B, (gamma - 1) / gamma) - 1);
  return B / rho0 * std::log1p(p / B);
}

double HydrostaticProfile::Finv(double f) const {
  if (tait) return B * (std::pow(1 + f * rho0 * (gamma - 1) / (B * gamma), gamma / (gamma - 1)) - 1);
  return B * std::expm1(f * rho0 / B);
}

double HydrostaticProfile::top() const { return F(rho0 * g * H) / g; }

double HydrostaticProfile::pressure_at(double z) const { return z >= top() ? 0.0 : Finv(g * (top() - z)); }

double HydrostaticProfile::height_of(double z_nominal) const {
  return top() - F(rho0 * g * (H - z_nominal)) / g;
}

HydrostaticProfile hydrostatic_profile(const Scene& scene, double H) {
  const SolverConstants k = derive_constants(scene);
  return {k.rest_density, -scene.gravity.z(), H,
          k.stiffness,    scene.solver.gamma, scene.solver.eos == Eos::Tait};
}

void compress_to_hydrostatic(HostParticles& p, const HydrostaticProfile& profile) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.phase[i] != static_cast<std::uint8_t>(Phase::Solid))
      p.position[i][2] = static_cast<float>(profile.height_of(p.position[i][2]));
}

}  // namespace thaw
