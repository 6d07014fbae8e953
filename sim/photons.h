#pragma once
// Thermal photons (Iwasaki et al. 2010, sec. 4 and 6): lamps emit photons that a 3D-DDA walk through a
// voxel grid (Amanatides & Woo 1987) hands to the first ice or solid particle in their way. The tracer
// counts hits per particle on the device; the heat stage turns counts into energy with photon_energy().
#include <Eigen/Core>
#include <cstdint>

#include "sim/cl_runtime.h"

namespace thaw {

// Voxel (i, j, k) covers origin + cell * [i, i+1) x [j, j+1) x [k, k+1); voxels are keyed x-fastest.
struct VoxelGridInfo {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();  // [m]
  float cell = 0;                                    // voxel edge [m]
  int nx = 0, ny = 0, nz = 0;
};

// A rectangular lamp: corners centre +- half_u +- half_v. normal is the emitting side; half_u and
// half_v are perpendicular to it (and to each other).
struct LampGeometry {
  Eigen::Vector3f centre, normal, half_u, half_v;  // [m], unit, [m], [m]
};

struct PhotonTally {
  std::uint64_t emitted = 0, absorbed = 0;
  std::uint64_t escaped() const { return emitted - absorbed; }
};

class PhotonTracer {
 public:
  // Builds the kernels; the voxel grid is fixed for the tracer's life. Throws Error if the grid is
  // empty, its cell is not positive, or it has more than 2^28 voxels.
  PhotonTracer(ClRuntime& cl, const VoxelGridInfo& grid);

  // Marks the voxels holding ice or solid particles (phase: uchar per particle; position: float4, xyz
  // used) among the first n particles; where several share a voxel the largest index owns it.
  void build_occupancy(const cl::Buffer& position, const cl::Buffer& phase, std::uint32_t n);

  // Emits `photons` photons from the lamp for step `step` (lamp_index keeps lamps' random streams
  // apart; the same arguments give the same photons) and adds one to hits[particle] for each one
  // absorbed. hits is a caller-owned uint buffer of at least n entries (of build_occupancy), zeroed by
  // the caller when it wants per-step counts. Reads back one counter.
  PhotonTally trace(const LampGeometry& lamp, std::uint32_t photons, std::uint64_t step,
                    std::uint32_t lamp_index, cl::Buffer& hits);

  // First-enqueues every kernel (pocl compiles on the first launch) with nothing to do.
  void warm_up();

  const VoxelGridInfo& grid() const { return grid_; }

 private:
  ClRuntime& cl_;
  VoxelGridInfo grid_;
  std::uint32_t ncells_ = 0;
  cl::Kernel k_clear_, k_mark_, k_trace_;
  cl::Buffer occupancy_;  // int per voxel: owning particle, or -1
  cl::Buffer absorbed_;   // uint: photons absorbed by the last trace
  cl::Buffer spare_;      // stands in for particle buffers in warm_up()
};

// Energy carried by one photon, E_p = eps sigma T_s^4 H dt / N (Iwasaki et al. 2010, sec. 4), with
// T_s = temperature_celsius + 273.15 K and H the lamp's area (4 |half_u| |half_v| for LampGeometry) [J].
// Throws Error for photons == 0.
double photon_energy(double emissivity, double temperature_celsius, double area, double dt,
                     std::uint32_t photons);

}  // namespace thaw
