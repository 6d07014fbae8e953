#pragma once
// The heat stage (Iwasaki et al. 2010 sec. 3-4): conduction between all particles, the exposed surface's
// exchange with the ambient air and the dryers, the tank walls' exchange with the outside, absorbed lamp
// photons (sim/photons.h), and the phase change that follows from each particle's enthalpy. Built by the
// solver only when plan_heat (sim/thermal.h) says the scene needs it; each source is compiled in only
// when the scene has it. Declares the "enthalpy" field.
#include <CL/opencl.hpp>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sim/cl_runtime.h"
#include "sim/kernels/thermal_law.h"
#include "sim/particle_store.h"
#include "sim/photons.h"
#include "sim/scene.h"
#include "sim/stage.h"
#include "sim/thermal.h"

namespace thaw {

struct EnergyBudget;
struct SolverConstants;

class HeatStage {
 public:
  // `scene` must outlive the stage (the solver's own copy, whose dryers and lamps change live);
  // `particle_bounds` (min, max over every particle) sizes the photon grid.
  HeatStage(const StageContext& c, const HeatPlan& plan, const Eigen::Vector3f& particle_min,
            const Eigen::Vector3f& particle_max);
  ~HeatStage();

  ParticleStore::Field enthalpy() const { return enthalpy_; }

  // Whether the exchange with the air takes each particle's area from the surface stage (heat.exposed_area
  // other than iwasaki2010, with ambient exchange or cone dryers); then the solver builds that stage and
  // hands its "surface_area" field here before the first run.
  bool uses_surface() const;
  void surface_from(ParticleStore::Field area) { surface_area_ = area; }

  // Where substances lower the melting point (substances_lower_melting in sim/substance_stage.h), the
  // substance stage's "melt_shift" field [K], handed here by the solver before the first run.
  void melt_shift_from(ParticleStore::Field shift) {
    melt_shift_ = shift;
    has_melt_shift_ = true;
  }

  // The stage's limit on dt [s]: diffusion, the tank walls, exchange with the air and the dryers.
  double max_dt() const;

  // Lamps that are on: photons absorbed this step become each particle's lamp energy.
  void trace_photons(double dt, std::uint64_t step, EnergyBudget& budget);
  // Conduction, sources, enthalpy update, phase change and the budget's sums for a step of dt. Throws
  // BlowUpError naming `step`, `time` and the particle when an enthalpy is not finite. Returns whether a
  // particle changed phase (read back only when `want_phase_change`; false otherwise).
  bool run(double dt, const NeighbourView& nv, EnergyBudget& budget, std::uint64_t step, double time,
           bool want_phase_change);

  // The scene's dryers or lamps changed (the solver has checked and stored them).
  void dryers_changed() { dryers_dirty_ = true; }
  void lamps_changed();  // builds the photon tracer once a lamp is on
  bool tracing_photons() const { return photons_ != nullptr; }

  // First-enqueues every kernel with nothing to do (dt = 0 adds no heat).
  void warm_up(const NeighbourView& nv, EnergyBudget& budget);

  // T [°C], k [W/m/K] and V [m^3] per particle as the last run's neighbour loop read them.
  void thermal_inputs(std::vector<float>& T, std::vector<float>& k, std::vector<float>& V) const;
  // The power [W] the held particles of each of `materials` materials gave the rest in the last run().
  std::vector<double> held_power(const cl::Buffer& material, std::size_t materials) const;

 private:
  void upload_dryers();

  ClRuntime& cl_;
  ParticleStore& store_;
  CoreFields core_;
  const Scene& scene_;
  HeatPlan plan_;
  double diffusion_dt_ = 0, wall_dt_ = 0, exposed_capacity_ = 0;
  double last_dt_heat_ = 0;  // of the last run() [s]
  float support_ = 0, smoothing_ = 0, rest_density_ = 0;
  const ParticleLayout& layout_;  // the solver's: the particle count changes when water leaves
  ParticleStore::Field enthalpy_ = 0, surface_area_ = 0;
  ParticleStore::Field melt_shift_ = 0;
  bool has_melt_shift_ = false;
  cl::Kernel k_thermal_state_, k_heat_, k_absorb_, k_budget_, k_adiabatic_;
  cl::Buffer materials_, thermal_, lamp_energy_, hits_, budget_parts_, budget_tiles_, budget_bad_, dryers_,
      phase_changed_;
  bool dryers_dirty_ = true;
  VoxelGridInfo photon_grid_;
  std::unique_ptr<PhotonTracer> photons_;
};

}  // namespace thaw
