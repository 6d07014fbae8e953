#pragma once
// Divergence-free SPH (Bender & Koschier 2015, 2017): the pressure solver of `solver.pressure: "dfsph"`.
// The fluid stage's density pass (without an equation of state) and forces pass (viscosity, gravity, the
// walls' push) stay, the density pass computing alpha too; this stage replaces the pressure force by two
// Jacobi solves on the velocities, the density solve warm-started from the last step (the divergence solve
// from zero unless solver.divergence_warm_start), each stopped at its tolerance or the iteration cap
// (sim/kernels/dfsph.cl has the equations). Its passes in the step (2017 Algorithm 1) are sim/step_plan.h's:
// the divergence solve with the last step's dt after the densities and alpha, the density solve after v += dt
// a. Built only for scenes that ask for it.
#include <CL/opencl.hpp>
#include <cstdint>
#include <string>
#include <utility>

#include "sim/cl_runtime.h"
#include "sim/particle_store.h"
#include "sim/scene.h"
#include "sim/stage.h"

namespace thaw {

struct SolverConstants;

// One solve of one step: iterations done, the mean error last measured (density: mean (rho* - rho0) /
// rho0; divergence: mean (D rho / Dt) dt / rho0; measured before the last correction where the solve
// stopped after the two it always makes) and whether that met the tolerance.
struct PressureSolve {
  int iterations = 0;
  double error = 0;
  bool converged = true;
};

// The density DFSPH's density solve holds resting water at, as a fraction of rho0: what a resting lattice
// of the scene's spacing sums to with its kernel (sph::lattice_sum: 1.003 for Wendland C2 over 3 spacings,
// 0.99997 for the cubic spline over 2). The solve aims at it (dfsph.cl) and the metrics measure
// compression against it (sim/metrics.cpp).
double dfsph_rest_ratio(const Scene& scene);

// Counts over a run, for the metrics and the run's warning: steps whose solve stopped at the cap.
struct PressureSolveTotals {
  std::uint64_t steps = 0, density_iterations = 0, divergence_iterations = 0;
  std::uint64_t density_unconverged = 0, divergence_unconverged = 0;
  double worst_density_error = 0;  // of the unconverged steps
};

class DfsphStage {
 public:
  // `flow` is the fluid stage's material table (each particle's rest density). `with_heat`: the heat stage
  // runs, so ideal-gas air's rest density follows its temperature (rest_density_reads_temperature).
  DfsphStage(const StageContext& c, const cl::Buffer& flow, bool with_heat);
  // With rest_density_reads_temperature(): the enthalpy field the columns read (the heat stage's).
  void rest_density_from(ParticleStore::Field enthalpy) { enthalpy_ = enthalpy; }

  // After the grid's sort, before the density pass: who is fluid (the density pass then computes alpha for
  // both solves into columns(): FluidStage::compute_dfsph_alpha).
  void mark_fluid();
  const cl::Buffer& columns() const { return col_; }
  cl_uint min_neighbours() const { return min_neighbours_; }
  // Makes the velocities divergence-free with the step that produced them (dt: the last step's; none
  // before the first step).
  PressureSolve divergence_solve(const NeighbourView& nv, double dt);
  // v += dt a (non-pressure accelerations), damped by damping_factor.
  void predict(const cl::Buffer& accel, const NeighbourView& nv, double dt, double damping_factor);
  PressureSolve density_solve(const NeighbourView& nv, double dt);
  // The step's pressure into the fluid stage's state buffer (rho, p / rho^2, boundary, p), as rigid ice
  // and the metrics read it.
  void write_pressure(const cl::Buffer& state, double dt);
  void drift(double dt);

  const PressureSolve& last_density() const { return last_density_; }
  const PressureSolve& last_divergence() const { return last_divergence_; }
  const PressureSolveTotals& totals() const { return totals_; }
  // Ideal-gas air that fills a closed domain (air.buoyancy ideal_gas, no open side, no air.region): the
  // room's pressure over the domain's, by which the last mark_fluid() scaled the air's rest volumes
  // (Gay-Lussac's law: (1 + theta T0) / (1 + theta T) for air warmed evenly to T); 1 otherwise.
  double gas_volume_factor() const { return gas_volume_factor_; }
  bool closed_gas() const { return closed_gas_; }

 private:
  // Runs one solve: warm start, then error / correct sweeps until the mean error is within tolerance
  // (after at least two sweeps) or the cap.
  PressureSolve solve(const NeighbourView& nv, double dt, bool density_mode);
  double mean_error(double rest_density);
  // count dx^3 / sum_i m_i / rho0(T_i) over the ideal-gas air (dfsph_gas_volume).
  double closed_gas_volume_factor();
  // Runs a per-tile sum kernel (its arguments set, writing sums_) and adds its (sum, count) pairs up.
  std::pair<double, double> tile_sums(cl::Kernel& k);

  ClRuntime& cl_;
  ParticleStore& store_;
  CoreFields f_;
  const ParticleLayout& layout_;
  const cl::Buffer& flow_;
  ParticleStore::Field kappa_ = 0;
  float support_ = 0;
  cl_uint min_neighbours_ = 0;
  double rest_density_ = 1000;
  double error_scale_ = 1000;  // the errors' unit: rho0 (kg/m^3), or 1 where they are fractions
  double density_tolerance_ = 0, divergence_tolerance_ = 0;
  int max_iterations_ = 100;
  cl::Kernel k_columns_, k_error_, k_warm_, k_correct_, k_sum_, k_predict_, k_drift_, k_pressure_,
      k_extrapolate_;
  cl_float4 gravity_{};
  bool divergence_warm_start_ = false;  // solver.divergence_warm_start
  bool ideal_gas_ = false;              // THAW_IDEAL_GAS: the columns read the enthalpy (eq 7)
  ParticleStore::Field enthalpy_ = 0;
  // Ideal-gas air that fills a domain without open sides: its rest volumes are scaled so that together
  // they keep one lattice volume per particle (the domain's pressure rises as its air warms).
  bool closed_gas_ = false;
  double lattice_volume_ = 0;  // dx^3
  double gas_volume_factor_ = 1.0;
  cl::Kernel k_gas_volume_;
  bool extrapolate_ = true;  // solver.boundary_pressure adami2012; akinci2012 leaves the boundary's kappa 0
  cl::Buffer col_, sums_;
  PressureSolve last_density_, last_divergence_;
  PressureSolveTotals totals_;
};

}  // namespace thaw
