#pragma once
// The density pass written by hand in C++ with OpenMP over the solver's own sorted particles and cell
// starts: the yardstick the OpenCL density stage is measured against. It computes what the device's
// density kernel (sim/kernels/density.cl) computes, for every particle (fluid and boundary): the
// summation density, the equation of state and the pair coefficients the forces pass reads, with the
// same neighbour walk (the rows of cells within `reach` of the particle's cell).
#include <cstdint>
#include <vector>

#include "sim/particles.h"

namespace thaw {

struct ReferenceGrid {
  float origin[3];
  float inv_cell;
  int nx, ny, nz;
  int reach;  // cells visited on each side: the cell size is H / reach
};

struct ReferenceParams {
  float H = 0;            // support radius
  float rho0 = 0;         // rest density
  float B = 0;            // EOS stiffness (Tait B, or rho0 c^2 for the linear EOS)
  float gamma = 7;        // Tait exponent
  bool tait = true;       // else linear
  bool wendland = false;  // else cubic spline
  float visc_fluid = 0, visc_boundary = 0;
};

// The sorted particles in both layouts the loops read: as the device stores them (x, y, z, m in one
// float4) and as structure-of-arrays blocks padded with 16 zeros (as the device's reorder writes them).
struct ReferenceParticles {
  ReferenceParticles(const std::vector<Float4>& pos, const std::vector<std::uint8_t>& phase,
                     const std::vector<std::uint32_t>& cell_start);
  std::vector<Float4> pos;
  std::vector<std::uint8_t> phase;
  std::vector<std::uint32_t> cell_start;
  std::vector<float> x, y, z, m;
  std::size_t size() const { return pos.size(); }
};

// state = (rho, p / rho^2, is_boundary, p); kv = k m / rho; mp = m p / rho^2 (see density.cl).
struct ReferenceDensity {
  std::vector<float> rho;
  std::vector<Float4> state;
  std::vector<float> kv, mp;
};

// The plain loop: one candidate at a time from the float4 positions, skipping those outside the
// support before the square root, the kernel from sim/kernels/sph_kernel.h.
void reference_density_scalar(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceParams& k,
                              ReferenceDensity& out);

// The device's scheme by hand: candidates 8 at a time from the structure-of-arrays copy, masked lanes,
// the kernel's normalisation factored out (compiled -O3 -march=native, the lanes loop vectorized by
// the compiler with `omp simd`).
void reference_density_lanes(const ReferenceParticles& p, const ReferenceGrid& g, const ReferenceParams& k,
                             ReferenceDensity& out);

}  // namespace thaw
