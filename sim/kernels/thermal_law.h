/* Enthalpy, temperature and liquid fraction of one material, shared verbatim by the OpenCL kernels and
 * the host (scene sampling, metrics, tests), so that both sides convert with the same arithmetic.
 *
 * Each particle carries its specific enthalpy h [J/kg]; temperature and liquid fraction follow from it
 * (docs/ARCHITECTURE.md, Numerics). For a material pair that melts and freezes (ice <-> water) h = 0 is the solid
 * at its melting point T_m:
 *   h < 0        solid,  T = T_m + h / c_solid,              liquid fraction 0
 *   0 <= h <= L  at the melting point, T = T_m,               liquid fraction h / L
 *   h > L        liquid, T = T_m + (h - L) / c_liquid,        liquid fraction 1
 * Both members of the pair use this same reference, so a particle keeps its h when it changes phase and
 * the latent heat is conserved exactly. A material that does not change phase has L = 0 and
 * c_solid = c_liquid = c, i.e. h = c (T - T_m). */
#ifndef THAW_THERMAL_LAW_H
#define THAW_THERMAL_LAW_H

/* The conversions run in float on the device and in double on the host (metrics, sampling, tests). */
#ifdef __OPENCL_VERSION__
#define THAW_TL_FN
#define THAW_TL_REAL float
#else
#include <cstdint>
#define THAW_TL_FN inline
#define THAW_TL_REAL double
namespace thaw::thermal {
#endif

/* Flags of MaterialThermal. */
#define THAW_MAT_HELD 1u        /* held at held_enthalpy (a thermostat): the heat that takes is accounted */
#define THAW_MAT_MELTS 2u       /* ice: becomes `partner` (a fluid) when its liquid fraction reaches 1 */
#define THAW_MAT_FREEZES 4u     /* fluid: becomes `partner` (ice) when its liquid fraction reaches 0 */
#define THAW_MAT_WALL_HEAT 8u   /* tank wall: exchanges heat with the outside (Domaradzki & Martyn sec. 7) */
#define THAW_MAT_AIR_EXCHANGE 16u /* exposed surface exchanges heat with the ambient air and the dryers */
#define THAW_MAT_ADIABATIC 32u    /* an ideal insulator: mirrors the temperature around it (heat.cl) */

/* One material's thermal data; every member is 4 bytes, so host and device layouts agree. */
typedef struct {
  float k_solid, k_liquid;  /* conductivity below / above the melting point [W/m/K] */
  float c_solid, c_liquid;  /* specific heat below / above the melting point [J/kg/K] */
  float latent;             /* L [J/kg]; 0 for materials that do not change phase */
  float melt;               /* T_m [°C] */
  float thermal_mass_scale; /* physical mass / the particle's SPH mass (solids, ice: rho / rho0) */
  float held_enthalpy;      /* THAW_MAT_HELD: the enthalpy the particle is held at [J/kg] */
  float wall_coefficient;   /* THAW_MAT_WALL_HEAT: U * A / layers per particle [W/K] */
  float wall_temperature;   /* THAW_MAT_WALL_HEAT: the outside temperature [°C] */
  int partner;              /* material a phase change turns the particle into; -1 none */
  unsigned int flags;       /* THAW_MAT_* */
} MaterialThermal;

THAW_TL_FN THAW_TL_REAL thermal_temperature(THAW_TL_REAL h, THAW_TL_REAL latent, THAW_TL_REAL melt,
                                            THAW_TL_REAL c_solid, THAW_TL_REAL c_liquid) {
  return h < 0 ? melt + h / c_solid : (h > latent ? melt + (h - latent) / c_liquid : melt);
}

/* The enthalpy of the solid (liquid = 0) or the liquid (liquid = 1) at T; at T_m the solid has h = 0
 * and the liquid h = L. */
THAW_TL_FN THAW_TL_REAL thermal_enthalpy(THAW_TL_REAL T, int liquid, THAW_TL_REAL latent, THAW_TL_REAL melt,
                                         THAW_TL_REAL c_solid, THAW_TL_REAL c_liquid) {
  return liquid ? latent + c_liquid * (T - melt) : c_solid * (T - melt);
}

/* With the melting point lowered by d >= 0 (a dissolved substance, Blagden's law: docs/SUBSTANCES.md): each
 * pure phase keeps its enthalpy curve, c_solid (T - T_m) below and L + c_liquid (T - T_m) above, and the two
 * meet at T_m - d, where the solid has -c_solid d and the liquid L - c_liquid d. Between those the particle
 * is at T_m - d, part melted. d = 0 is the law above; a particle keeps its h, so energy is conserved
 * whatever d does. */
THAW_TL_FN THAW_TL_REAL thermal_solid_limit(THAW_TL_REAL c_solid, THAW_TL_REAL d) { return -c_solid * d; }
THAW_TL_FN THAW_TL_REAL thermal_liquid_limit(THAW_TL_REAL latent, THAW_TL_REAL c_liquid, THAW_TL_REAL d) {
  return latent - c_liquid * d;
}
THAW_TL_FN THAW_TL_REAL thermal_temperature_lowered(THAW_TL_REAL h, THAW_TL_REAL latent, THAW_TL_REAL melt,
                                                    THAW_TL_REAL c_solid, THAW_TL_REAL c_liquid,
                                                    THAW_TL_REAL d) {
  return h < -c_solid * d ? melt + h / c_solid
                          : (h > latent - c_liquid * d ? melt + (h - latent) / c_liquid : melt - d);
}
/* The liquid fraction under the same law (materials that change phase). */
THAW_TL_FN THAW_TL_REAL thermal_liquid_fraction_lowered(THAW_TL_REAL h, THAW_TL_REAL latent,
                                                        THAW_TL_REAL c_solid, THAW_TL_REAL c_liquid,
                                                        THAW_TL_REAL d) {
  const THAW_TL_REAL lo = -c_solid * d, hi = latent - c_liquid * d;
  return h <= lo ? 0 : (h >= hi ? 1 : (h - lo) / (hi - lo));
}

/* Conductivity of a particle. At the melting point the particle holds the front: it is part converted
 * (the phase forming: liquid while an ice particle melts, solid while a water particle freezes) and
 * pinned at T_m, so the temperature drop to a converted neighbour happens over the distance to the
 * front, dx/2 + phi dx for a converted fraction phi, not over dx. The harmonic-mean pair conductivity
 * 2 k_n k / (k_n + k) gives exactly that flux in 1-D when k = k_n / (2 phi) (k_n: the forming phase's),
 * a sub-particle front position recovered from the enthalpy. Without it the front lags by about one
 * spacing (measured with `thaw validate stefan`: 17 % at 10 particles across the front when freezing).
 * phi is kept above 1/20, so k stays finite. */
THAW_TL_FN float thermal_conductivity(float h, float latent, float k_solid, float k_liquid, int melting) {
  if (h <= 0.0f) return k_solid;
  if (h >= latent) return k_liquid;
  const float liquid = h / latent;
  const float converted = melting ? liquid : 1.0f - liquid;
  return (melting ? k_liquid : k_solid) / (2.0f * (converted > 0.05f ? converted : 0.05f));
}

/* For materials that change phase; 0 or 1 otherwise. */
THAW_TL_FN THAW_TL_REAL thermal_liquid_fraction(THAW_TL_REAL h, THAW_TL_REAL latent) {
  return latent > 0 ? (h <= 0 ? 0 : (h >= latent ? 1 : h / latent)) : (h > 0 ? 1 : 0);
}

#ifndef __OPENCL_VERSION__
static_assert(sizeof(MaterialThermal) == 48, "MaterialThermal must match its OpenCL layout");
}  // namespace thaw::thermal
#endif
#undef THAW_TL_FN
#undef THAW_TL_REAL
#endif
