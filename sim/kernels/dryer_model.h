/* The first hair-dryer model, for scenes without air particles, shared verbatim by the heat kernel and
 * the host (tests). A dryer is a round jet of warm air leaving a nozzle of diameter D at speed u0 and
 * temperature T0. Inside the cone (axis d, half-angle theta_half, length `reach`) a surface at axial
 * distance a and angle theta from the axis sees
 *   decay   = min(1, 6 D / a)                  the jet's potential core (about 6 D), then the 1/a decay of a
 *                                              round free jet's centreline (Pope, Turbulent Flows, sec. 5.1)
 *   profile = exp(-2 (theta / theta_half)^2)   a Gaussian across the jet, e^-2 at the cone's edge
 *   u       = u0 decay profile                 local air speed
 *   T_air   = T_amb + (T0 - T_amb) decay profile   the temperature excess decays like the speed
 *   h       = C sqrt(u),  C = 0.664 Pr^(1/3) k_air / sqrt(nu_air D)
 * h is the laminar flat-plate average Nu = 0.664 Re^(1/2) Pr^(1/3) over the length D (Incropera, eq. 7.30),
 * with air near 40 °C. Exposed particles then take h (T_air - T) dA; outside the cone, nothing. */
#ifndef THAW_DRYER_MODEL_H
#define THAW_DRYER_MODEL_H

#ifdef __OPENCL_VERSION__
#define THAW_DM_FN
#else
#include <cmath>
#define THAW_DM_FN inline
namespace thaw::dryer {
using std::acos;
using std::exp;
using std::fmin;
using std::sqrt;
struct float2_ {
  float x, y;
};
#define THAW_DM_FLOAT2 float2_
#endif
#ifdef __OPENCL_VERSION__
#define THAW_DM_FLOAT2 float2
#endif

/* Air properties at about 40 °C. */
#define THAW_AIR_CONDUCTIVITY 0.0271f /* W/m/K */
#define THAW_AIR_VISCOSITY 1.70e-5f   /* kinematic, m^2/s */
#define THAW_AIR_PRANDTL 0.71f

/* A dryer as the kernels see it; every member 4 bytes. */
typedef struct {
  float px, py, pz;        /* nozzle position [m] */
  float dx, dy, dz;        /* unit direction */
  float half_angle;        /* [rad] */
  float reach;             /* [m] */
  float temperature;       /* at the nozzle [°C] */
  float speed;             /* at the nozzle [m/s]; 0 when switched off */
  float diameter;          /* nozzle [m] */
  float coefficient;       /* C of h = C sqrt(u) [W/m^2/K / sqrt(m/s)] */
} DryerJet;

THAW_DM_FN float dryer_coefficient(float diameter) {
  return 0.664f * 0.8921f /* 0.71^(1/3) */ * THAW_AIR_CONDUCTIVITY / sqrt(THAW_AIR_VISCOSITY * diameter);
}

/* (h [W/m^2/K], T_air [°C]) that a surface at (x, y, z) sees from one dryer; h = 0 outside its cone. */
THAW_DM_FN THAW_DM_FLOAT2 dryer_air(const DryerJet j, float x, float y, float z, float ambient) {
  THAW_DM_FLOAT2 out;
  out.x = 0.0f;
  out.y = ambient;
  const float rx = x - j.px, ry = y - j.py, rz = z - j.pz;
  const float a = rx * j.dx + ry * j.dy + rz * j.dz;
  const float r = sqrt(rx * rx + ry * ry + rz * rz);
  if (!(j.speed > 0.0f) || !(a > 0.0f) || a > j.reach) return out;
  const float theta = acos(fmin(a / r, 1.0f));
  if (theta > j.half_angle) return out;
  const float ratio = theta / j.half_angle;
  const float decay = fmin(1.0f, 6.0f * j.diameter / a);
  const float share = decay * exp(-2.0f * ratio * ratio);
  out.x = j.coefficient * sqrt(j.speed * share);
  out.y = ambient + (j.temperature - ambient) * share;
  return out;
}

#ifndef __OPENCL_VERSION__
static_assert(sizeof(DryerJet) == 48, "DryerJet must match its OpenCL layout");
}  // namespace thaw::dryer
#endif
#undef THAW_DM_FN
#undef THAW_DM_FLOAT2
#endif
