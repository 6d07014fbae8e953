#pragma once
// The heat stage's conduction loop written by hand in C++ with OpenMP over the solver's own sorted
// particles, cell starts and thermal inputs: the yardstick the OpenCL heat stage is measured against. It
// computes what the device's heat kernel (sim/kernels/heat.cl) computes in its neighbour loop, for every
// particle: the Cleary & Monaghan conduction power
//   Q_i = 2 V_i sum_j V_j k_ij (T_i - T_j) (x_ij . grad W_ij) / (r_ij^2 + eta^2),  k_ij = 2 k_i k_j / (k_i +
//   k_j),
// the count of neighbours within the exposed radius, and from it the exchange with the ambient air
// (Iwasaki 2010: exposed area (6 - n_i) dx^2). Dryers, lamps, held particles and wall heat are not
// modelled: scenes with those are outside its scope.
#include <cstdint>
#include <vector>

#include "bench/reference_density.h"

namespace thaw {

struct ReferenceHeatParams {
  float H = 0;            // support radius
  float eta2 = 0;         // 0.01 h^2, h = H / 2: keeps the pair term finite at r -> 0
  float exposed_r2 = 0;   // neighbours within this squared distance cover one face (1.44 dx^2)
  bool wendland = false;  // else cubic spline
  float face_area = 0;    // dx^2
  float ambient_temperature = 0, ambient_coefficient = 0;  // [°C], h [W/m^2/K]
};

// The heat stage's per-particle inputs in sorted order (Solver::thermal_inputs()), as blocks padded with
// 16 zeros like the device's, and whether each particle's material exchanges heat with the air.
struct ReferenceThermal {
  ReferenceThermal(const std::vector<float>& temperature, const std::vector<float>& conductivity,
                   const std::vector<float>& volume, const std::vector<std::uint8_t>& air_exchange);
  std::vector<float> T, k, V;
  std::vector<std::uint8_t> air_exchange;
};

struct ReferenceHeat {
  std::vector<float> q_conduction;  // [W], into the particle
  std::vector<float> q_ambient;     // [W], from the ambient air through the exposed area
  std::vector<int> neighbours;      // within sqrt(exposed_r2), the particle itself not counted
};

// The plain loop: one candidate at a time from the float4 positions, skipping those outside the support
// before the square root, the kernel gradient from sim/kernels/sph_kernel.h.
void reference_conduction(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceThermal& t,
                          const ReferenceHeatParams& k, ReferenceHeat& out);

// The device's scheme by hand: candidates 8 at a time from the structure-of-arrays copies, masked lanes,
// the kernel's normalisation factored out (vectorized by the compiler through GCC vector types).
void reference_conduction_lanes(const ReferenceParticles& p, const ReferenceGrid& g,
                                const ReferenceThermal& t, const ReferenceHeatParams& k, ReferenceHeat& out);

}  // namespace thaw
