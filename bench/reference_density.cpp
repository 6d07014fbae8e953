#include "bench/reference_density.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bench/reference_lanes.h"
#include "sim/kernels/sph_kernel.h"

namespace thaw {
namespace {

using namespace reference;

constexpr int kLanes = 8;
constexpr float kPi = 3.14159265358979f;

// Equation of state and the per-particle outputs, as at the end of density.cl.
inline void finish(const ReferenceParticles& p, const ReferenceParams& k, std::size_t i, float rho,
                   ReferenceDensity& out) {
  float pr;
  if (k.tait) {
    const float x = rho / k.rho0;
    if (k.gamma == 7.0f) {
      const float x2 = x * x, x4 = x2 * x2;
      pr = k.B * (x4 * x2 * x - 1.0f);
    } else {
      pr = k.B * (std::pow(x, k.gamma) - 1.0f);
    }
  } else {
    pr = k.B * (rho / k.rho0 - 1.0f);
  }
  pr = std::max(pr, 0.0f);
  const bool boundary = p.phase[i] == static_cast<std::uint8_t>(Phase::Solid);
  const float dp = pr / (rho * rho);
  const float m = p.pos[i][3];
  out.rho[i] = rho;
  out.state[i] = {rho, dp, boundary ? 1.0f : 0.0f, pr};
  out.kv[i] = (boundary ? k.visc_boundary : k.visc_fluid) * m / rho;
  out.mp[i] = m * dp;
}

void resize(ReferenceDensity& out, std::size_t n) {
  out.rho.resize(n);
  out.state.resize(n);
  out.kv.resize(n);
  out.mp.resize(n);
}

template <bool kWendland>
void scalar_loop(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceParams& k,
                 ReferenceDensity& out) {
  const long n = static_cast<long>(p.size());
  const float H = k.H, H2 = H * H;
  const Float4* pos = p.pos.data();
  const std::uint32_t* cs = p.cell_start.data();
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    const Float4 pi = pos[i];
    float rho = 0.0f;
    for_each_row(g, cs, pi[0], pi[1], pi[2], [&](std::uint32_t jb, std::uint32_t je) {
      for (std::uint32_t j = jb; j < je; ++j) {
        const float dx = pi[0] - pos[j][0], dy = pi[1] - pos[j][1], dz = pi[2] - pos[j][2];
        const float r2 = dx * dx + dy * dy + dz * dz;
        if (r2 < H2)
          rho += pos[j][3] *
                 (kWendland ? sph::wendland_c2_w(std::sqrt(r2), H) : sph::cubic_spline_w(std::sqrt(r2), H));
      }
    });
    finish(p, k, static_cast<std::size_t>(i), rho, out);
  }
}

// W / sigma as a function of q = r / H (the lanes' factorised kernel, as in sim/kernels/density.cl).
template <bool kWendland>
inline v8f w_shape(v8f q) {
  const v8f one = splat8(1.0f);
  if constexpr (kWendland) {
    q = q < one ? q : one;
    const v8f a = one - q;
    return a * a * a * a * (one + 4.0f * q);
  } else {
    const v8f a = one - q;
    const v8f inner = 6.0f * q * q * (q - one) + one;
    const v8f outer = 2.0f * a * a * a;
    return q <= splat8(0.5f) ? inner : outer;  // both computed and selected, as on the device
  }
}

template <bool kWendland>
void lanes_loop(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceParams& k,
                ReferenceDensity& out) {
  const long n = static_cast<long>(p.size());
  const float H = k.H, H2 = H * H, inv_H = 1.0f / H;
  const float sigma = kWendland ? 21.0f / (2.0f * kPi * H * H * H) : 8.0f / (kPi * H * H * H);
  const float* X = p.x.data();
  const float* Y = p.y.data();
  const float* Z = p.z.data();
  const float* M = p.m.data();
  const std::uint32_t* cs = p.cell_start.data();
  const v8i lane_ids = {0, 1, 2, 3, 4, 5, 6, 7};
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    const float px = X[i], py = Y[i], pz = Z[i];
    v8f acc = {};
    for_each_row(g, cs, px, py, pz, [&](std::uint32_t jb, std::uint32_t je) {
      for (std::uint32_t j = jb; j < je; j += kLanes) {
        const v8f dx = px - load8(X + j), dy = py - load8(Y + j), dz = pz - load8(Z + j);
        const v8f r2 = dx * dx + dy * dy + dz * dz;
        const v8i in = (lane_ids < static_cast<int>(je - j)) & (r2 < H2);
        const v8f w = load8(M + j) * w_shape<kWendland>(sqrt8(r2) * inv_H);
        acc += in ? w : v8f{};
      }
    });
    // The device's lane tree (lanes_sum8): ((0+4) + (1+5)) + ((2+6) + (3+7)).
    const float s0 = acc[0] + acc[4], s1 = acc[1] + acc[5], s2 = acc[2] + acc[6], s3 = acc[3] + acc[7];
    const float rho = sigma * ((s0 + s1) + (s2 + s3));
    finish(p, k, static_cast<std::size_t>(i), rho, out);
  }
}

}  // namespace

ReferenceParticles::ReferenceParticles(const std::vector<Float4>& position,
                                       const std::vector<std::uint8_t>& ph,
                                       const std::vector<std::uint32_t>& starts)
    : pos(position), phase(ph), cell_start(starts) {
  const std::size_t padded = pos.size() + 16;
  x.assign(padded, 0.0f);
  y.assign(padded, 0.0f);
  z.assign(padded, 0.0f);
  m.assign(padded, 0.0f);
  for (std::size_t i = 0; i < pos.size(); ++i) {
    x[i] = pos[i][0];
    y[i] = pos[i][1];
    z[i] = pos[i][2];
    m[i] = pos[i][3];
  }
}

void reference_density_scalar(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceParams& k,
                              ReferenceDensity& out) {
  resize(out, p.size());
  if (k.wendland)
    scalar_loop<true>(p, g, k, out);
  else
    scalar_loop<false>(p, g, k, out);
}

void reference_density_lanes(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceParams& k,
                             ReferenceDensity& out) {
  resize(out, p.size());
  if (k.wendland)
    lanes_loop<true>(p, g, k, out);
  else
    lanes_loop<false>(p, g, k, out);
}

}  // namespace thaw
