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
#include <vector>
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

/* Host only: the particles a full neighbourhood holds, (4/3) pi (H / dx)^3 (33.5 at H = 2 dx; the simple
 * cubic lattice has 33 within it); the share of it below which a particle is at a surface or in a sheet
 * (DFSPH's divergence solve, sim/dfsph_stage.cpp; the surface stage, sim/surface_stage.cpp). */
inline double full_neighbourhood(double spacing, double support) {
  return 4.0 / 3.0 * M_PI * std::pow(support / spacing, 3);
}

/* Host only: sum over a row of particles running in from a flat boundary of v |grad c_i|, grad c_i = sum_j v
 * grad W_ij over the particles on the boundary's inner side (v = dx^3, the first particle dx/2 in), divided
 * by dx^2: for a half-space of the simple cubic lattice (`one_layer` false), under one dx^2 of its face; for
 * a sheet one particle thick (`one_layer` true), behind one dx^2 of its rim (one spacing high, one long).
 * `grad` is grad_factor: (dW/dr) / r. */
inline double flat_colour_gradient(float (*grad)(float, float), double spacing, double support,
                                   bool one_layer) {
  const auto H = static_cast<float>(support);
  const int m = static_cast<int>(std::ceil(support / spacing)) + 1;
  const int across = one_layer ? 0 : m;  // the sheet's own layer only
  const double v = spacing * spacing * spacing;
  double total = 0;
  for (int k = 0; k <= m; ++k) {  // the particle k spacings in
    double g = 0;
    for (int i = -across; i <= across; ++i)
      for (int j = -m; j <= m; ++j)
        for (int l = 0; l <= k + m; ++l) {  // neighbours l - k further in, on the inner side
          const int d = l - k;
          const double r = spacing * std::sqrt(double(i * i + j * j + d * d));
          if (r == 0 || r >= support) continue;
          g += grad(static_cast<float>(r), H) * (-d * spacing);  // (x_i - x_j) along the row
        }
    total += v * std::abs(v * g);
  }
  return total / (spacing * spacing);
}

/* A flat face's value: the continuum gives 1/2 (c falls from 1 to 1/2 inside); the lattice sums to 0.510 for
 * the cubic spline at H = 2 dx. Its inverse scales brackbill1992's areas (sim/kernels/surface.cl). */
inline double flat_face_colour_gradient(float (*grad)(float, float), double spacing, double support) {
  return flat_colour_gradient(grad, spacing, support, false);
}
/* A one-layer sheet's rim: its inverse scales the colour gradient along a sheet to its rim (surface.cl). */
inline double flat_edge_colour_gradient(float (*grad)(float, float), double spacing, double support) {
  return flat_colour_gradient(grad, spacing, support, true);
}

/* Host only: the largest eigenvalue of the Jacobi-preconditioned pressure system D^-1 A of DFSPH's
 * solves (sim/kernels/dfsph.cl) on a resting simple cubic lattice, from its Fourier symbol. A pressure
 * wave pi_j = exp(i k.x_j) changes each particle's density by -dt^2 V^2 / rho0 |s(k)|^2 pi, with
 * s(k) = sum_j gradW(x_j) sin(k.x_j), while the diagonal (DFSPH's alpha, 2015 eq 10, where sum_j V_j
 * gradW_ij is 0) is dt^2 V^2 / rho0 sum_j |gradW(x_j)|^2; so the eigenvalue of wave k is
 * |s(k)|^2 / sum_j |gradW(x_j)|^2, here maximised over the Brillouin zone [0, pi/dx]^3 (the symbol is even
 * in each component). Relaxed Jacobi applied in full (both signs) diverges where omega times it exceeds 2:
 * 2.82 for the cubic spline at H = 2 dx (IISPH's omega 0.5 holds), 6.24 for Wendland C2 at 3 dx (omega
 * 0.5 doubled the error every sweep). `grad` is grad_factor: (dW/dr) / r. */
inline double jacobi_spectral_bound(float (*grad)(float, float), double spacing, double support) {
  const auto H = static_cast<float>(support);
  const int m = static_cast<int>(std::ceil(support / spacing)) + 1;
  struct Term {
    double dx, dy, dz, gx, gy, gz;
  };
  std::vector<Term> terms;
  double diagonal = 0;
  for (int i = -m; i <= m; ++i)
    for (int j = -m; j <= m; ++j)
      for (int l = -m; l <= m; ++l) {
        const double r = spacing * std::sqrt(double(i * i + j * j + l * l));
        if (r == 0 || r >= support) continue;
        const double f = grad(static_cast<float>(r), H);
        const Term t{double(i), double(j), double(l), f * i * spacing, f * j * spacing, f * l * spacing};
        terms.push_back(t);
        diagonal += t.gx * t.gx + t.gy * t.gy + t.gz * t.gz;
      }
  constexpr int kSamples = 24;  // pi / 24 apart: Wendland C2's peak 6.240, against 6.248 at 40
  double worst = 0;
  for (int a = 0; a <= kSamples; ++a)
    for (int b = 0; b <= kSamples; ++b)
      for (int c = 0; c <= kSamples; ++c) {
        const double kx = M_PI * a / kSamples, ky = M_PI * b / kSamples, kz = M_PI * c / kSamples;
        double sx = 0, sy = 0, sz = 0;
        for (const Term& t : terms) {
          const double s = std::sin(kx * t.dx + ky * t.dy + kz * t.dz);
          sx += s * t.gx;
          sy += s * t.gy;
          sz += s * t.gz;
        }
        worst = std::max(worst, (sx * sx + sy * sy + sz * sz) / diagonal);
      }
  return worst;
}
}  // namespace thaw::sph
#endif
#endif
