/* The smoothing kernel and its gradient on SIMD lanes (grid_common.h), for the neighbour passes
 * (density.cl, forces.cl, heat.cl), with the normalisation sigma factored out of the sums. */
#ifndef THAW_SPH_LANES_H
#define THAW_SPH_LANES_H

/* The smoothing kernel of sph_kernel.h on lanes, with its normalisation sigma factored out of the sum:
 * W(q H, H) = sigma w_shape(q) for q = r / H in [0, 1) (lanes outside the support are masked). */
#ifdef THAW_WENDLAND
#define THAW_SIGMA(H) (21.0f / (2.0f * THAW_PI_F * (H) * (H) * (H)))
floatV w_shape(floatV q) {
  q = fmin(q, 1.0f);
  const floatV a = 1.0f - q;
  return a * a * a * a * (1.0f + 4.0f * q);
}
#else
#define THAW_SIGMA(H) (8.0f / (THAW_PI_F * (H) * (H) * (H)))
floatV w_shape(floatV q) {
  const floatV a = 1.0f - q;
  const floatV inner = 6.0f * q * q * (q - 1.0f) + 1.0f;
  const floatV outer = 2.0f * a * a * a;
  return select(outer, inner, q <= 0.5f);
}
#endif

/* The kernel gradient of sph_kernel.h on lanes, its normalisation factored out of the sum:
 * grad_factor(q H, H) = sigma / H^2 grad_shape(q) for q = r / H in [0, 1) (lanes outside the support
 * are masked). */
#ifdef THAW_WENDLAND
floatV grad_shape(floatV q) {
  q = fmin(q, 1.0f);
  const floatV a = 1.0f - q;
  return -20.0f * a * a * a;
}
#else
floatV grad_shape(floatV q) {
  const floatV a = 1.0f - q;
  const floatV inner = 18.0f * q - 12.0f;
  /* -6 sigma a^2 / (H r) = sigma / H^2 (-6 a^2 / q), only taken for q > 0.5 */
  const floatV outer = -6.0f * a * a / fmax(q, 0.25f);
  return select(outer, inner, q <= 0.5f);
}
#endif
#endif
