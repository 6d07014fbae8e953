#include "sim/photons.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "sim/cl_launch.h"
#include "sim/error.h"
#include "sim/particles.h"

namespace thaw {
namespace {

static_assert(static_cast<int>(Phase::Ice) == 1 && static_cast<int>(Phase::Solid) == 2,
              "THAW_PHASE_ICE / THAW_PHASE_SOLID in sim/kernels/grid_common.h");

// Must match `VoxelGrid` in sim/kernels/photons.cl.
struct ClVoxelGrid {
  cl_float4 origin;
  cl_float cell;
  cl_int nx, ny, nz;
};
static_assert(sizeof(ClVoxelGrid) == 32, "VoxelGrid in sim/kernels/photons.cl is 32 bytes");

// Stefan-Boltzmann constant [W m^-2 K^-4] (CODATA 2018, exact).
constexpr double kStefanBoltzmann = 5.670374419e-8;

cl_float4 f4(const Eigen::Vector3f& v) { return {{v.x(), v.y(), v.z(), 0.0f}}; }

ClVoxelGrid cl_voxel_grid(const VoxelGridInfo& g) { return {f4(g.origin), g.cell, g.nx, g.ny, g.nz}; }

}  // namespace

PhotonTracer::PhotonTracer(ClRuntime& cl, const VoxelGridInfo& grid) : cl_(cl), grid_(grid) {
  const std::string dims =
      std::to_string(grid.nx) + " x " + std::to_string(grid.ny) + " x " + std::to_string(grid.nz);
  if (grid.nx <= 0 || grid.ny <= 0 || grid.nz <= 0)
    throw Error("photon voxel grid: " + dims + " voxels; every count must be positive");
  if (!(grid.cell > 0.0f) || !std::isfinite(grid.cell) || !grid.origin.allFinite())
    throw Error("photon voxel grid: cell " + std::to_string(grid.cell) + " m; must be positive and finite");
  const double cells = double(grid.nx) * grid.ny * grid.nz;
  if (cells > double(1u << 28))
    throw Error("photon voxel grid: " + dims + " = " + std::to_string(static_cast<long long>(cells)) +
                " voxels; at most 2^28 = " + std::to_string(1u << 28) + " are supported (use larger voxels)");
  ncells_ = static_cast<std::uint32_t>(cells);

  const auto program = cl.build({"grid_common.h", "photons.cl"});
  k_clear_ = cl::Kernel(program, "clear_occupancy");
  k_mark_ = cl::Kernel(program, "mark_occupancy");
  k_trace_ = cl::Kernel(program, "trace_photons");

  occupancy_ = cl::Buffer(cl.context(), CL_MEM_READ_WRITE, std::size_t(ncells_) * 4);
  absorbed_ = cl::Buffer(cl.context(), CL_MEM_READ_WRITE, 4);
  spare_ = cl::Buffer(cl.context(), CL_MEM_READ_WRITE, 16);
  // Until build_occupancy() runs, every photon escapes.
  set_args(k_clear_, occupancy_, static_cast<cl_uint>(ncells_));
  launch(cl.queue(), k_clear_, ncells_);
}

void PhotonTracer::build_occupancy(const cl::Buffer& position, const cl::Buffer& phase, std::uint32_t n) {
  auto& q = cl_.queue();
  set_args(k_clear_, occupancy_, static_cast<cl_uint>(ncells_));
  launch(q, k_clear_, ncells_);
  if (n == 0) return;
  set_args(k_mark_, position, phase, cl_voxel_grid(grid_), occupancy_, static_cast<cl_uint>(n));
  launch(q, k_mark_, n);
}

PhotonTally PhotonTracer::trace(const LampGeometry& lamp, std::uint32_t photons, std::uint64_t step,
                                std::uint32_t lamp_index, cl::Buffer& hits) {
  const float len = lamp.normal.norm();
  if (!(len > 0.0f) || !std::isfinite(len) || !lamp.centre.allFinite() || !lamp.half_u.allFinite() ||
      !lamp.half_v.allFinite())
    throw Error("photon lamp " + std::to_string(lamp_index) +
                ": centre, normal and edges must be finite and the normal non-zero");
  PhotonTally tally;
  tally.emitted = photons;
  if (photons == 0) return tally;

  auto& q = cl_.queue();
  q.enqueueFillBuffer(absorbed_, cl_uint(0), 0, 4);
  set_args(k_trace_, cl_voxel_grid(grid_), occupancy_, f4(lamp.centre), f4(lamp.normal / len),
           f4(lamp.half_u), f4(lamp.half_v), static_cast<cl_uint>(photons),
           static_cast<cl_uint>(step & 0xffffffffu), static_cast<cl_uint>(step >> 32),
           static_cast<cl_uint>(lamp_index), hits, absorbed_);
  launch(q, k_trace_, photons);
  cl_uint absorbed = 0;
  q.enqueueReadBuffer(absorbed_, CL_TRUE, 0, 4, &absorbed);
  tally.absorbed = absorbed;
  return tally;
}

void PhotonTracer::warm_up() {
  // Zero counts: every work-item returns at once, and no buffer changes.
  auto& q = cl_.queue();
  set_args(k_clear_, occupancy_, cl_uint(0));
  launch(q, k_clear_, 0);
  set_args(k_mark_, spare_, spare_, cl_voxel_grid(grid_), occupancy_, cl_uint(0));
  launch(q, k_mark_, 0);
  const cl_float4 z{{0.0f, 0.0f, 1.0f, 0.0f}};
  set_args(k_trace_, cl_voxel_grid(grid_), occupancy_, z, z, z, z, cl_uint(0), cl_uint(0), cl_uint(0),
           cl_uint(0), spare_, absorbed_);
  launch(q, k_trace_, 0);
  q.finish();
}

double photon_energy(double emissivity, double temperature_celsius, double area, double dt,
                     std::uint32_t photons) {
  if (photons == 0) throw Error("photon_energy: the number of photons per step must be positive");
  const double t = temperature_celsius + 273.15;
  return emissivity * kStefanBoltzmann * (t * t) * (t * t) * area * dt / photons;
}

}  // namespace thaw
