#pragma once
// The solver: builds the stages a scene needs (sim/stage.h), loads a state into them and steps it on an
// OpenCL device, walking the step's passes in sim/step_plan.h's order; it keeps the run's books
// (sim/books.h). Stages a scene does not need are not built: docs/ARCHITECTURE.md says which and when.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sim/books.h"
#include "sim/cl_runtime.h"
#include "sim/dfsph_stage.h"
#include "sim/emitters.h"
#include "sim/fluid_stage.h"
#include "sim/heat_stage.h"
#include "sim/kernels/thermal_law.h"
#include "sim/neighbour_grid.h"
#include "sim/particle_store.h"
#include "sim/particles.h"
#include "sim/scene.h"
#include "sim/scene_sampling.h"
#include "sim/solver_constants.h"
#include "sim/stage_timers.h"
#include "sim/state_file.h"
#include "sim/step_plan.h"
#include "sim/substance_stage.h"
#include "sim/surface_stage.h"
#include "sim/tension_stage.h"

namespace thaw {

class PhotonTracer;
class RigidIce;
struct ParticleBuffers;

class RunDigest;

class Solver {
 public:
  // Starts from a state: a fresh one from initial_state(), or one read from a state file.
  Solver(ClRuntime& cl, const Scene& scene, const SimState& state);
  ~Solver();

  // One time step. Throws BlowUpError naming the step and the particle when the state is not finite
  // or runs away, or when the adaptive time step collapses below the scene's min_dt.
  void step();

  // Builds and first-enqueues every kernel on the current state without advancing it, so the
  // JIT compilation of the first launch is not timed.
  void warm_up();

  // Velocity relaxation rate zeta [1/s] for settling an initial state (validation cases); 0 = none.
  void set_velocity_damping(double zeta) { damping_ = zeta; }
  // Holds every free ice body in place (RigidIce::hold) while the water settles around it; no-op
  // without free ice.
  void hold_ice(bool held);

  // Heat sources a running simulation may change (the server calls these between steps). Values are
  // checked like the scene's (Error naming the field on a bad one); index out of range is an Error.
  void set_dryer(std::size_t index, const Dryer& dryer);
  void set_lamp(std::size_t index, const Lamp& lamp);
  const std::vector<Dryer>& dryers() const { return scene_.dryers; }
  const std::vector<Lamp>& lamps() const { return scene_.lamps; }
  // An emitter's tap, speed, place, direction, radius, times and temperature; returns false, changing
  // nothing, when this run cannot take the change between steps: another material, a temperature that
  // needs the heat stage this run did not build, or a jet faster (or falling further) than the sound
  // speed was chosen for (the caller rebuilds the solver from its state).
  bool set_emitter(std::size_t index, const Emitter& emitter);
  const std::vector<Emitter>& emitters() const { return scene_.emitters; }

  // Heat accounting: the total enthalpy sum m h over all particles now (double, read from the device),
  // and the budget so far.
  double total_enthalpy() const;
  const EnergyBudget& energy_budget() const { return budget_; }
  const OutflowBooks& outflow() const { return outflow_; }
  // What came in through emitters (zero without them).
  InflowBooks inflow() const { return emitters_ ? emitters_->books() : InflowBooks{}; }
  // Substances (empty in scenes without them): each one's total over all particles now [kg], summed in
  // double, and its account.
  std::vector<double> substance_totals() const;
  // Where each substance is (dissolved, on the surface, on solids and ice) [kg]; empty without substances.
  std::vector<SubstanceStage::Parts> substance_parts() const;
  const SubstanceBooks& substance_books() const { return substance_books_; }
  // Puts `amount` kg of substance s into the water and ice around `at` [m] (substance.drop): shared by the
  // kernel's weight among those within its support, else given to the nearest within three supports, and
  // booked as inflow. Returns how many particles took a share; throws Error when none is near enough.
  std::size_t drop_substance(std::size_t s, double amount, const Eigen::Vector3d& at);
  // How far below its material's melting point each particle melts [K], as the last step's substance stage
  // left it (sim/substance_stage.h); empty unless substances lower the melting point.
  std::vector<float> melt_shifts() const;
  // Particles the buffers hold room for: size() plus the spare that emitters fill (sim/stage.h).
  std::size_t capacity() const { return layout_.capacity; }

  SimState state() const;  // copies the device state to the host
  HostParticles particles() const;

  double time() const { return time_; }
  double dt() const { return dt_; }
  const ParticleLayout& layout() const { return layout_; }  // the tiles of the per-tile passes
  std::uint64_t steps() const { return steps_; }
  std::uint64_t clamped() const;
  std::size_t size() const { return n_; }
  const SolverConstants& constants() const { return k_; }
  const StageTimers& timers() const { return timers_; }
  StageTimers& timers() { return timers_; }
  const Scene& scene() const { return scene_; }

  // Stage entry points, exposed for benchmarks and tests; step() is their composition.
  // build_grid() also writes the copies that compute_density() and compute_forces() read: call it
  // first after anything that moves particles.
  // intake false: the air dryers take nothing in (a warm-up changes no state).
  void build_grid(bool intake = true);
  void compute_density();
  void compute_forces();
  double choose_time_step();
  void trace_photons(double dt);  // lamps: photons absorbed this step, as energy per particle
  void compute_heat(double dt);   // conduction, sources, enthalpy update, phase change, budget
  void integrate(double dt);
  // Rigid ice only (no-ops otherwise): label the ice into bodies now, and the ice-force pass; the force
  // on each particle [N] as that pass left it (zero for all but ice of free bodies).
  void label_ice();
  void compute_ice_forces();
  std::vector<Float4> ice_forces() const;

  // The passes of its steps, in order (sim/step_plan.h).
  const std::vector<Pass>& plan() const { return plan_; }
  // The timers its passes add to, in step order (`thaw run` prints them so).
  std::vector<Stage> timed_stages() const;
  // The stages this run built, in step order, e.g. {"grid", "density", "forces", "time step",
  // "integrate"}; heat names why it was built ("heat (the scene has dryers)").
  std::vector<std::string> stages() const;
  // Why heat was or was not built (plan_heat in sim/thermal.h).
  const std::string& heat_reason() const { return heat_reason_; }

  // Rigid ice (scenes with free ice; null otherwise): the bodies, labelling and its counters.
  const RigidIce* rigid_ice() const { return rigid_.get(); }
  const DfsphStage* dfsph() const { return dfsph_.get(); }  // null unless solver.pressure is dfsph

  // Cell geometry of the neighbour grid (for reference loops and tests).
  using GridInfo = thaw::GridInfo;
  const GridInfo& grid() const { return grid_->info(); }
  std::vector<std::uint32_t> cell_starts() const;
  std::vector<float> densities() const;
  std::vector<Float4> pressure_state() const;  // per particle (rho, p/rho^2, is_boundary, p)
  // Each particle's surface area [m^2] from the surface stage (sim/surface_stage.h), as the last step left
  // it; empty when the scene does not build that stage.
  std::vector<float> surface_areas() const;
  std::vector<float> temperatures() const;  // per particle [°C], from the last heat stage's state
  // The heat stage's inputs as its neighbour loop reads them (for reference loops and tests): T [°C],
  // k [W/m/K] and V [m^3] per particle, from the last compute_heat(); empty without heat.
  struct ThermalInputs {
    std::vector<float> temperature, conductivity, volume;
  };
  ThermalInputs thermal_inputs() const;
  // The power [W] each material's held particles gave the rest in the last heat step (negative: took),
  // one entry per Scene::materials (0 for those not held); empty without heat. A hot and a cold held
  // wall are materials of their own, so this splits what the energy budget's `held` sums.
  std::vector<double> held_power() const;

 private:
  // Builds the stages this scene needs for `capacity` particles (0: as the state says, or its particles
  // and the emitters' first second) and loads the state into them: the constructor, and growing.
  void build(const SimState& state, std::size_t capacity);
  void compute_boundary_psi(const std::string& program_options);  // Akinci 2012 eq. 4 volumes, at the start
  void remove_particles_from(std::size_t kept);                   // water past an open side: books, then drop
  void emit(double dt);  // the emitters' particles for the step just taken, growing the capacity if need be
  ParticleBuffers buffers() const;
  void upload(const HostParticles& p);
  NeighbourView neighbours() const;
  double heat_time_step() const;
  template <class F>
  void timed(Stage s, F&& f);
  // Reports the state to the thread's RunDigest, if one is installed (sim/run_digest.h).
  void report(const char* stage);
  // The RunDigest this solver reports to: the one installed when it was made, while it still is; else null.
  RunDigest* listening() const;

  ClRuntime& cl_;
  Scene scene_;
  SolverConstants k_;
  std::size_t n_ = 0;
  double time_ = 0, dt_ = 0;
  std::uint64_t steps_ = 0;
  std::uint64_t clamped_base_ = 0;
  std::uint32_t next_id_ = 0;  // the id the next emitted particle gets
  double damping_ = 0;
  StageTimers timers_;
  ParticleLayout layout_;
  // The RunDigest installed when this solver was made (it reports while that one is still installed), and
  // its number there.
  RunDigest* digest_ = nullptr;
  std::uint32_t digest_number_ = 0;

  // The step's stages, in step order (see step()); null where the scene does not need one.
  // Per-particle state, one buffer per declared field, reordered with the sort (sim/particle_store.h).
  ParticleStore store_;
  CoreFields f_;
  std::unique_ptr<NeighbourGrid> grid_;
  bool grid_built_ = false;
  // The water's passes (sim/fluid_stage.h), built only for scenes with flow.
  std::unique_ptr<FluidStage> fluid_;
  // The incompressible pressure solver (sim/dfsph_stage.h), built only when solver.pressure is dfsph.
  std::unique_ptr<DfsphStage> dfsph_;
  std::vector<Pass> plan_;  // the step's passes (build() makes it from the stages built)
  void run_pass(Pass p, double& dt);
  bool surface_due() const;  // the surface stage's areas are due this step (heat.area_interval)
  // DFSPH with free ice: the velocities the forces pass saw, kept for rigid ice's viscous reaction (the
  // solves change the water's velocities before the ice takes it).
  cl::Buffer forces_velocity_;
  // Particles clamped back into the domain (counted by the grid's cell-key pass).
  cl::Buffer clamped_;

  // Heat (sim/heat_stage.h), built only when plan_heat says the scene needs it. Without it the enthalpy
  // never changes and stays on the host, by particle id (fixed_enthalpy_). The budget is the run's
  // whatever is built; the thermal table gives the masses its enthalpy sum needs.
  std::unique_ptr<HeatStage> heat_;
  std::unique_ptr<SurfaceStage> surface_;       // only when heat_ takes its exposed areas from it
  std::unique_ptr<TensionStage> tension_;       // only with flow and tension.model other than none
  std::unique_ptr<SubstanceStage> substances_;  // only where the scene declares substances
  SubstanceBooks substance_books_;
  bool surface_done_ = false;  // the areas are there: computed in this run, or brought by its state
  std::string heat_reason_;
  std::vector<Float2> fixed_enthalpy_;
  std::vector<thermal::MaterialThermal> table_;
  EnergyBudget budget_;
  OutflowBooks outflow_;

  // Rigid ice (built only when the scene has free ice and flow).
  std::unique_ptr<RigidIce> rigid_;
  // Emitters (built only when the scene has some); kept when the solver grows its capacity.
  std::unique_ptr<EmitterStage> emitters_;
};

}  // namespace thaw
