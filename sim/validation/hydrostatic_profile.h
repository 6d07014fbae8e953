#pragma once
// The exact hydrostatic state of the weakly compressible fluid the solver models: dp/dz = -g rho(p),
// rho(p) from the scene's equation of state, a column of height H at rest density (mass rho0 H per
// area) on a floor at z = 0. It tends to p = rho0 g (H - z) as the speed of sound grows. Starting a
// column on it avoids the acoustic transient of a lattice that first falls freely, then slams.
#include "sim/particles.h"
#include "sim/scene.h"

namespace thaw {

struct HydrostaticProfile {
  double rho0 = 0, g = 0, H = 0, B = 0, gamma = 7;
  bool tait = true;
  double F(double p) const;     // integral_0^p dp' / rho(p')
  double Finv(double f) const;  // its inverse
  double top() const;           // height of the free surface
  double pressure_at(double z) const;
  // Where a particle sits whose column above weighs rho0 g (H - z_nominal) per unit area.
  double height_of(double z_nominal) const;
};

// The profile of the scene's first fluid under its gravity (along -z), for a column of height H.
HydrostaticProfile hydrostatic_profile(const Scene& scene, double H);

// Moves every fluid particle from its lattice height to its height on the profile.
void compress_to_hydrostatic(HostParticles& p, const HydrostaticProfile& profile);

}  // namespace thaw
