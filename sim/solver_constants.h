#pragma once
// The constants a scene implies (speed of sound, kernel radius, stiffness, the fixed limits on the time
// step), derived once when a run starts; every stage is built with them (sim/stage.h).
#include "sim/scene.h"

namespace thaw {

// Constants the scene implies, derived once (speed of sound, kernel radius, EOS stiffness).
struct SolverConstants {
  float support = 0;              // kernel support radius H [m]
  float smoothing = 0;            // h = H / 2 (CFL and viscosity length) [m]
  float rest_density = 0;         // rho0 of the fluid [kg/m^3]
  float sound_speed = 0;          // c [m/s]
  float stiffness = 0;            // Tait B = rho0 c^2 / gamma, or rho0 c^2 for the linear EOS [Pa]
  float kinematic_viscosity = 0;  // physical nu [m^2/s]
  float max_speed = 0;            // blow-up threshold [m/s]
  // Viscosity coefficients of the forces pass: 2(d+2) nu + alpha c h between fluid particles (Monaghan
  // 2005 eq. 4.8 and its artificial-viscosity equivalent), alpha_b c h against boundary particles.
  float visc_fluid = 0, visc_boundary = 0;
  // Solid particles push fluid particles closer than repulsion_range (0.95 dx) apart, a spring of pair
  // stiffness m_i m_b repulsion [1/(kg s^2)] = c^2 / (dx^2 rho0 dx^3), as stiff as the ice contacts, with
  // a dashpot of time repulsion_damping = dx / c [s] (forces.cl).
  float repulsion = 0, repulsion_range = 0, repulsion_damping = 0;
  // Tension's capillary limit on dt, sqrt(rho0 dx^3 / (2 pi sigma)) (Brackbill et al. 1992) [s]; infinite
  // without tension.
  double capillary_dt = 0;
  // Heat: the diffusion limit on dt [s] (infinite without conduction), and the smallest heat capacity
  // per exposed area rho c dx / 6 over the materials that exchange heat with the air [J/m^2/K].
  double diffusion_dt = 0;
  double exposed_capacity = 0;
  double wall_dt = 0;  // the tank walls' exchange limit on dt [s] (infinite without wall heat)
};

SolverConstants derive_constants(const Scene& scene);

}  // namespace thaw
