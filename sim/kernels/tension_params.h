/* The tension passes' parameters, shared verbatim by the host (sim/tension_stage.cpp) and tension.cl; every
 * member is 4 bytes, so both layouts agree (static_assert below). Also Akinci et al. 2013's two kernel
 * shapes: the adhesion's for every device pass that needs it, and both in double for the host, which
 * integrates them to calibrate the coefficients (sim/tension_stage.cpp; tension.cl has the cohesion's on
 * lanes). */
#ifndef THAW_TENSION_PARAMS_H
#define THAW_TENSION_PARAMS_H

#ifdef __OPENCL_VERSION__
#define THAW_TENSION_FN
#else
#include <cmath>
#define THAW_TENSION_FN inline
namespace thaw::tension {
using std::fmax;
using std::pow;
using std::sqrt;
#endif

typedef struct {
  float support;      /* kernel support H [m] */
  float rest_density; /* rho0 of water [kg/m^3]: Akinci's K_ij = 2 rho0 / (rho_i + rho_j) */
  /* akinci2013: gamma of eqs. 1-2 (the same number scales eq. 2); iwasaki2010: k_w of eq. 4 [N m] */
  float cohesion;
  float curvature; /* 1: akinci2013's curvature term (eq. 2); 0: not */
  unsigned int n;
  unsigned int stride;
  /* brackbill1992 only: */
  float sigma;         /* the tension [N/m] */
  float volume;        /* dx^3: every inside particle's (water, ice, solid) volume in the colour */
  float spacing;       /* dx [m] */
  float layer_area;    /* dx^2 times the 2-D cubic spline's sum over a square lattice of spacing dx */
  float fit_radius;    /* radius [m] of the patch of surface points the quadric is fitted to */
  float smooth_radius; /* radius [m] over which the fitted curvatures are averaged */
  unsigned int pad0, pad1, pad2, pad3;
} TensionParams;

/* Akinci et al. 2013 eq. 7 (their A(r)) on support H, with q = r / H: 0.007 / H^3 a(q), where
 * a = (-4 q^2 + 6 q - 2)^(1/4) for 1/2 < q <= 1, else 0. The polynomial is -2 (2 q - 1)(q - 1), negative
 * outside (1/2, 1), so the clamp at 0 is the whole range test. One expression for scalars and lanes
 * (tension.cl's adhesion, rigid.cl's reaction to it) and, in double, for the host. */
#define THAW_AKINCI_ADHESION(q) sqrt(sqrt(fmax(-4.0f * (q) * (q) + 6.0f * (q)-2.0f, 0.0f)))

#ifndef __OPENCL_VERSION__
/* Akinci et al. 2013 eq. 3 (their C(r)) on support H, with q = r / H: 32 / (pi H^3) c(q), where
 * c = (1 - q)^3 q^3 for 1/2 < q <= 1 and 2 (1 - q)^3 q^3 - 1/64 for 0 < q <= 1/2: attraction past H/2,
 * repulsion close in. */
inline double akinci_cohesion_shape(double q) {
  const double a = (1.0 - q) * (1.0 - q) * (1.0 - q) * q * q * q;
  return q > 1.0 ? 0.0 : (q > 0.5 ? a : 2.0 * a - 1.0 / 64.0);
}

/* brackbill1992: the radius, in spacings, of the patch of surface points a particle's quadric is fitted to
 * (sim/tension_stage.cpp; its walk reaches ceil(3.5 dx / H) cells each way), and of the average of the fitted
 * curvatures. Measured with numpy on lattice spheres of R = 6-16 spacings jittered by 0.1 spacing
 * (docs/TENSION.md): the area-weighted mean of kappa R came within 10 % of 2; at the support (2 spacings) the
 * fits were too few to hold. */
constexpr double kFitRadius = 3.5, kSmoothRadius = 3.0;

/* THAW_AKINCI_ADHESION in double. */
inline double akinci_adhesion_shape(double q) {
  return std::pow(std::max(-4.0 * q * q + 6.0 * q - 2.0, 0.0), 0.25);
}

static_assert(sizeof(TensionParams) == 64, "TensionParams must match its OpenCL layout");
}  // namespace thaw::tension
#endif

#endif
