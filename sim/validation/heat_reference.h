#pragma once
// Exact solutions of the heat equation that the conduction and phase-change validation cases compare
// against (docs/VALIDATION-RESULTS.md: conduction and Stefan). They are computed from the case's own parameters, so a
// case whose materials or temperatures are overridden still has its reference.

#include <vector>

#include "sim/particles.h"

namespace thaw {

// Thermal properties of one phase.
struct ThermalPhase {
  double conductivity = 0;                                                         // k [W/m/K]
  double specific_heat = 0;                                                        // c [J/kg/K]
  double density = 0;                                                              // rho [kg/m^3]
  double diffusivity() const { return conductivity / (density * specific_heat); }  // alpha [m^2/s]
};

// Neumann's similarity solution of the two-phase Stefan problem on the half-line x > 0 (Carslaw & Jaeger,
// Conduction of Heat in Solids, 2nd ed., section 11.2): the wall at x = 0 held at wall_temperature from
// t = 0, the material initially at initial_temperature, phase change at melt_temperature with latent
// heat L. `near` is the phase that forms at the wall (water when melting: wall warmer than the melt
// temperature, initial <= melt; ice when freezing: wall colder, initial >= melt), `far` the phase that is
// initially present. The front is s(t) = 2 lambda sqrt(alpha_near t).
//
// Neither phase moves: with unequal densities this is the conduction-only model, in which a unit volume
// that changes phase absorbs rho_near L (releases it when freezing). With equal densities, the case of
// docs/VALIDATION-RESULTS.md, it is the exact solution.
struct NeumannStefan {
  ThermalPhase near, far;
  double wall_temperature = 0, initial_temperature = 0, melt_temperature = 0, latent_heat = 0;
  double lambda = 0;  // root of the transcendental equation, see solve_neumann_stefan

  bool freezing() const { return wall_temperature < melt_temperature; }
  double nu() const;                             // sqrt(alpha_near / alpha_far)
  double front(double t) const;                  // s(t) [m]
  double temperature(double x, double t) const;  // T(x, t) for x >= 0, both regions; T_0 for t <= 0
  // Heat per unit area that entered through the wall by time t, the integral of -k_near dT/dx at x = 0
  // [J/m^2]; negative when freezing.
  double wall_heat(double t) const;
  // Enthalpy per unit area gained by the half-line since t = 0 (sensible heat of both regions plus the
  // latent heat of the converted layer) [J/m^2]. Equals wall_heat(t) exactly: the energy balance.
  double stored_heat(double t) const;
};

// Solves for lambda (Carslaw & Jaeger section 11.2, in Stefan numbers)
//   St_n / (exp(l^2) erf l) - St_f / (nu exp(nu^2 l^2) erfc(nu l)) = l sqrt(pi),
//   St_n = c_near |T_w - T_m| / L,   St_f = (rho_far c_far / rho_near) |T_m - T_0| / L,
//   nu = sqrt(alpha_near / alpha_far),
// (St_f = c_far |T_m - T_0| / L for equal densities), by bracketing and bisection to round-off. Freezing is
// the same equation with the solid as the near phase. Throws thaw::Error when the parameters describe
// neither melting nor freezing, or a property is not positive.
NeumannStefan solve_neumann_stefan(ThermalPhase near, ThermalPhase far, double wall_temperature,
                                   double initial_temperature, double melt_temperature, double latent_heat);

// exp(z^2) erfc(z), finite for all z >= 0 where erfc(z) itself underflows (z > 26.5).
double erfcx(double z);

// A Gaussian pulse of excess temperature in `dimensions` dimensions (docs/VALIDATION-RESULTS.md, conduction):
//   T = T_inf + A (s0^2 / (s0^2 + 2 alpha t))^(d/2) exp(-|x|^2 / (2 (s0^2 + 2 alpha t))).
// Its excess heat, integral of (T - T_inf) dV = A (2 pi s0^2)^(d/2), is constant, and its second moment
// (integral of |x|^2 (T - T_inf) dV over the excess) is d variance(t): growth of the variance measures the
// effective diffusivity.
struct GaussianPulse {
  double background = 0;   // T_inf
  double amplitude = 0;    // A, the excess at the centre at t = 0
  double sigma0 = 0;       // s0 [m]
  double diffusivity = 0;  // alpha [m^2/s]
  int dimensions = 3;

  double temperature(double r2, double t) const;  // r2 = |x - centre|^2
  double variance(double t) const;                // s0^2 + 2 alpha t
  double excess_heat() const;                     // integral of (T - T_inf) dV, per unit rho c

  // A field sampled on particles of equal volume at `x` (the centre at the origin), such as the
  // conduction case's temperatures or the diffusion case's mass fractions: the second moment of its excess
  // over the background, whose growth 2 d alpha t measures the effective diffusivity; and its L2 error
  // against the pulse at time t, relative to the pulse's excess.
  double second_moment(const std::vector<Float4>& x, const std::vector<double>& value) const;
  double l2_error(const std::vector<Float4>& x, const std::vector<double>& value, double t) const;
};

}  // namespace thaw
