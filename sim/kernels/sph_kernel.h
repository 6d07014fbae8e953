/* SPH smoothing kernels, shared verbatim by the OpenCL kernels and the host (tests, reference loops),
 * so the functions the tests check are the ones the device runs.
 * H is the support radius (the kernel is zero for r >= H), as in SPlisHSPlasH.
 * grad_factor(r) = (dW/dr) / r, so grad W(x_ij) = grad_factor(|x_ij|) * x_ij; finite at r = 0. */
#ifndef THAW_SPH_KERNEL_H
#define THAW_SPH_KERNEL_H

#ifdef __OPENCL_VERSION__
#define THAW_FN
#else
#include <algorithm>
#include <cmath>
#define THAW_FN inline
namespace thaw::sph {
using std::fmax;
using std::fmin;
#endif

#define THAW_PI_F 3.14159265358979f

/* Cubic B-spline (Monaghan 1992) on support H: h = H/2 in Monaghan's notation. */
THAW_FN float cubic_spline_w(float r, float H) {
  const float sigma = 8.0f / (THAW_PI_F * H * H * H);
  const float q = r / H;
  const float a = 1.0f - q;
  const float inner = 6.0f * q * q * (q - 1.0f) + 1.0f;
  const float outer = 2.0f * a * a * a;
  return q <= 0.5f ? sigma * inner : (q < 1.0f ? sigma * outer : 0.0f);
}

THAW_FN float cubic_spline_grad_factor(float r, float H) {
  const float sigma = 8.0f / (THAW_PI_F * H * H * H);
  const float q = r / H;
  const float a = 1.0f - q;
  /* dW/dr / r, written so the inner branch never divides by r. */
  const float inner = sigma / (H * H) * (18.0f * q - 12.0f);
  const float outer = -6.0f * sigma * a * a / (H * fmax(r, 1e-30f));
  return q <= 0.5f ? inner : (q < 1.0f ? outer : 0.0f);
}

/* Wendland C2 in 3-D (Wendland 1995; Dehnen & Aly 2012) on support H. */
THAW_FN float wendland_c2_w(float r, float H) {
  const float sigma = 21.0f / (2.0f * THAW_PI_F * H * H * H);
  const float q = fmin(r / H, 1.0f);
  const float a = 1.0f - q;
  return sigma * a * a * a * a * (1.0f + 4.0f * q);
}

THAW_FN float wendland_c2_grad_factor(float r, float H) {
  const float sigma = 21.0f / (2.0f * THAW_PI_F * H * H * H);
  const float q = fmin(r / H, 1.0f);
  const float a = 1.0f - q;
  return -20.0f * sigma * a * a * a / (H * H);
}

#ifndef __OPENCL_VERSION__
/* Host only: sum_j dx^3 W(|x_j|) over a simple cubic lattice of `spacing` around one of its points, the
 * density a resting lattice of fluid sums to as a fraction of its rest density (the cubic spline at
 * H = 2 dx: 0.99997; Wendland C2: 1.0338 at 2 dx, 1.0031 at 3 dx; tests/sim/sph_kernel_test.cpp). DFSPH's
 * density solve aims at it (sim/dfsph_stage.cpp). */
inline double lattice_sum(float (*w)(float, float), double spacing, double support) {
  const auto H = static_cast<float>(support);
  const int m = static_cast<int>(std::ceil(support / spacing)) + 1;
  double sum = 0;
  for (int i = -m; i <= m; ++i)
    for (int j = -m; j <= m; ++j)
      for (int l = -m; l <= m; ++l)
        sum += w(static_cast<float>(spacing * std::sqrt(double(i * i + j * j + l * l))), H);
  return sum * spacing * spacing * spacing;
}
}  // namespace thaw::sph
#endif
#endif
