#pragma once
// The water's passes, weakly compressible SPH: summation density with the equation of state (Tait:
// Monaghan 1994, Becker & Teschner 2007; or linear), the forces (symmetric pressure, Monaghan 2005
// viscosity, gravity, the boundary push; sim/kernels/forces.cl), the per-tile limits of the adaptive
// time step, and symplectic Euler integration. Boundary particles (walls, solids, ice) enter as Akinci
// et al. 2012 boundaries. Flow properties come per material from a device table (MaterialFlow in
// sim/kernels/fluid_params.h), so a second fluid is a row of data; built only for scenes with flow.
#include <CL/opencl.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/cl_runtime.h"
#include "sim/kernels/fluid_params.h"
#include "sim/particle_store.h"
#include "sim/scene.h"
#include "sim/stage.h"

namespace thaw {

struct SolverConstants;

// One material's flow row: the EOS stiffness (Tait B = rho0 c^2 / gamma, or rho0 c^2) and the viscosity
// coefficient of the pair term, from its rest density and kinematic viscosity (derive_constants gives the
// first fluid's the same way).
fluid::MaterialFlow flow_row(const SolverSettings& s, float rest_density, float kinematic_viscosity,
                             float sound_speed, float smoothing);

// Each material's flow properties, one per Scene::materials (fluid_params.h). Fluids of several rest
// densities need DFSPH's multiphase form (check_multiphase throws SceneError at solver.pressure
// otherwise). `with_heat`: the heat stage runs, so Boussinesq air reads its temperature (THAW_BUOYANCY);
// without it the air's buoyancy is the constant of its starting temperature.
std::vector<fluid::MaterialFlow> material_flow_table(const Scene& scene, const SolverConstants& k,
                                                     bool with_heat = false);

// Whether the DFSPH columns read each air particle's temperature for its rest density (eq 7).
bool rest_density_reads_temperature(const Scene& scene, bool with_heat);

// Whether the forces pass reads each particle's temperature: Boussinesq air in a run with heat.
bool buoyancy_reads_temperature(const Scene& scene, bool with_heat);

// The fastest particle and largest acceleration of the last forces pass, from the per-tile limits.
struct FlowLimits {
  double vmax2 = 0, amax2 = 0;
  std::uint32_t fastest = 0;        // the fastest particle's index (sorted order)
  std::uint32_t bad = 0xffffffffu;  // the first particle with a non-finite state (bit 31: acceleration only)
};

class FluidStage {
 public:
  FluidStage(const StageContext& c, bool with_heat);
  // With buoyancy_reads_temperature(): the enthalpy field the forces pass reads (the heat stage's).
  void buoyancy_from(ParticleStore::Field enthalpy) { enthalpy_ = enthalpy; }

  void density(const NeighbourView& nv);
  // Under DFSPH the density pass also writes the solver's alpha columns (sim/kernels/density.cl): the
  // solver's column buffer, owned by the DFSPH stage, which the solver builds and drops with this one.
  void compute_dfsph_alpha(const cl::Buffer& columns, cl_uint min_neighbours) {
    dfsph_columns_ = &columns;
    dfsph_min_neighbours_ = min_neighbours;
  }
  void forces(const NeighbourView& nv);
  FlowLimits limits();
  // Symplectic Euler over dt, velocities scaled by damping_factor (1: none).
  void integrate(double dt, double damping_factor);

  // Per particle: (rho, p / rho^2, is_boundary, p) from the density pass; accelerations from forces.
  const cl::Buffer& state() const { return state_; }
  const cl::Buffer& accel() const { return accel_; }
  const cl::Buffer& flow() const { return flow_; }  // the material table (fluid_params.h)

 private:
  ClRuntime& cl_;
  ParticleStore& store_;
  CoreFields f_;
  const ParticleLayout& layout_;  // the solver's: the particle count changes when water leaves
  fluid::DensityParams density_params_{};
  fluid::ForcesParams forces_params_{};
  cl::Kernel k_density_, k_forces_, k_limits_, k_integrate_;
  cl::Buffer flow_, state_, accel_, derived_, limits_f_, limits_i_;
  const cl::Buffer* dfsph_columns_ = nullptr;
  cl_uint dfsph_min_neighbours_ = 0;
  bool buoyancy_ = false;
  ParticleStore::Field enthalpy_ = 0;
  bool no_slip_ = false;  // solver.no_slip adami2012: the density pass writes ghost velocities
  cl::Buffer ghost_;
};

}  // namespace thaw
