#include "bench/reference_heat.h"

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

void resize(ReferenceHeat& out, std::size_t n) {
  out.q_conduction.resize(n);
  out.q_ambient.resize(n);
  out.neighbours.resize(n);
}

// The per-particle outputs and the air exchange, as after the neighbour loop in heat.cl.
inline void finish(const ReferenceThermal& t, const ReferenceHeatParams& k, std::size_t i, float q,
                   int neighbours, ReferenceHeat& out) {
  const float exposed =
      t.air_exchange[i] ? k.face_area * static_cast<float>(std::max(6 - neighbours, 0)) : 0.0f;
  out.q_conduction[i] = q;
  out.q_ambient[i] =
      exposed > 0.0f ? k.ambient_coefficient * (k.ambient_temperature - t.T[i]) * exposed : 0.0f;
  out.neighbours[i] = neighbours;
}

template <bool kWendland>
void scalar_loop(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceThermal& t,
                 const ReferenceHeatParams& k, ReferenceHeat& out) {
  const long n = static_cast<long>(p.size());
  const float H = k.H, H2 = H * H, eta2 = k.eta2, exposed_r2 = k.exposed_r2;
  const Float4* pos = p.pos.data();
  const float* T = t.T.data();
  const float* K = t.k.data();
  const float* V = t.V.data();
  const std::uint32_t* cs = p.cell_start.data();
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    const Float4 pi = pos[i];
    const float Ti = T[i], ki = K[i];
    float acc = 0.0f;
    int covered = 0;
    for_each_row(g, cs, pi[0], pi[1], pi[2], [&](std::uint32_t jb, std::uint32_t je) {
      for (std::uint32_t j = jb; j < je; ++j) {
        const float dx = pi[0] - pos[j][0], dy = pi[1] - pos[j][1], dz = pi[2] - pos[j][2];
        const float r2 = dx * dx + dy * dy + dz * dz;
        covered += r2 < exposed_r2 ? 1 : 0;  // as the device: not limited to the support
        if (r2 < H2) {
          const float kij = 2.0f * ki * K[j] / std::max(ki + K[j], 1e-30f);
          const float r = std::sqrt(r2);
          // x . grad W = grad_factor r^2
          const float gf =
              kWendland ? sph::wendland_c2_grad_factor(r, H) : sph::cubic_spline_grad_factor(r, H);
          acc += V[j] * kij * (Ti - T[j]) * gf * r2 / (r2 + eta2);
        }
      }
    });
    finish(t, k, static_cast<std::size_t>(i), 2.0f * V[i] * acc, covered - 1, out);
  }
}

// grad_factor / (sigma / H^2) as a function of q = r / H (sim/kernels/sph_lanes.h).
template <bool kWendland>
inline v8f grad_shape(v8f q) {
  const v8f one = splat8(1.0f);
  if constexpr (kWendland) {
    q = q < one ? q : one;
    const v8f a = one - q;
    return -20.0f * a * a * a;
  } else {
    const v8f a = one - q;
    const v8f inner = 18.0f * q - 12.0f;
    const v8f quarter = splat8(0.25f);
    const v8f outer = -6.0f * a * a / (q > quarter ? q : quarter);
    return q <= splat8(0.5f) ? inner : outer;  // both computed and selected, as on the device
  }
}

template <bool kWendland>
void lanes_loop(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceThermal& t,
                const ReferenceHeatParams& k, ReferenceHeat& out) {
  const long n = static_cast<long>(p.size());
  const float H = k.H, H2 = H * H, inv_H = 1.0f / H, eta2 = k.eta2, exposed_r2 = k.exposed_r2;
  const float sigma = kWendland ? 21.0f / (2.0f * kPi * H * H * H) : 8.0f / (kPi * H * H * H);
  const float* X = p.x.data();
  const float* Y = p.y.data();
  const float* Z = p.z.data();
  const float* T = t.T.data();
  const float* K = t.k.data();
  const float* V = t.V.data();
  const std::uint32_t* cs = p.cell_start.data();
  const v8i lane_ids = {0, 1, 2, 3, 4, 5, 6, 7};
  const v8f tiny = splat8(1e-30f);
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    const float px = X[i], py = Y[i], pz = Z[i];
    const float Ti = T[i], ki = K[i];
    v8f acc = {};
    v8i covered = {};
    for_each_row(g, cs, px, py, pz, [&](std::uint32_t jb, std::uint32_t je) {
      for (std::uint32_t j = jb; j < je; j += kLanes) {
        const v8f dx = px - load8(X + j), dy = py - load8(Y + j), dz = pz - load8(Z + j);
        const v8f r2 = dx * dx + dy * dy + dz * dz;
        const v8i lane = lane_ids < static_cast<int>(je - j);
        const v8i in = lane & (r2 < H2);
        const v8f kj = load8(K + j);
        const v8f ksum = ki + kj;
        const v8f kij = 2.0f * ki * kj / (ksum > tiny ? ksum : tiny);
        const v8f term = load8(V + j) * kij * (Ti - load8(T + j)) * grad_shape<kWendland>(sqrt8(r2) * inv_H) *
                         r2 / (r2 + eta2);
        acc += in ? term : v8f{};
        covered -= lane & (r2 < exposed_r2);  // masks are -1
      }
    });
    // The device's lane tree (lanes_sum8): ((0+4) + (1+5)) + ((2+6) + (3+7)).
    const float s0 = acc[0] + acc[4], s1 = acc[1] + acc[5], s2 = acc[2] + acc[6], s3 = acc[3] + acc[7];
    int neighbours = -1;  // the particle itself is in its own range
    for (int l = 0; l < kLanes; ++l) neighbours += covered[l];
    const float q = 2.0f * V[i] * sigma * (1.0f / H) * (1.0f / H) * ((s0 + s1) + (s2 + s3));
    finish(t, k, static_cast<std::size_t>(i), q, neighbours, out);
  }
}

std::vector<float> padded(const std::vector<float>& v) {
  std::vector<float> out(v.size() + 16, 0.0f);
  std::copy(v.begin(), v.end(), out.begin());
  return out;
}

}  // namespace

ReferenceThermal::ReferenceThermal(const std::vector<float>& temperature,
                                   const std::vector<float>& conductivity, const std::vector<float>& volume,
                                   const std::vector<std::uint8_t>& air)
    : T(padded(temperature)), k(padded(conductivity)), V(padded(volume)), air_exchange(air) {}

void reference_conduction(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceThermal& t,
                          const ReferenceHeatParams& k, ReferenceHeat& out) {
  resize(out, p.size());
  if (k.wendland)
    scalar_loop<true>(p, g, t, k, out);
  else
    scalar_loop<false>(p, g, t, k, out);
}

void reference_conduction_lanes(const ReferenceParticles& p, const ReferenceGrid& g,
                                const ReferenceThermal& t, const ReferenceHeatParams& k, ReferenceHeat& out) {
  resize(out, p.size());
  if (k.wendland)
    lanes_loop<true>(p, g, t, k, out);
  else
    lanes_loop<false>(p, g, t, k, out);
}

}  // namespace thaw
