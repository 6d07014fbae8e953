#include "sim/solver.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "sim/cl_grid.h"
#include "sim/cl_launch.h"
#include "sim/error.h"
#include "sim/kernels/dryer_model.h"
#include "sim/kernels/sph_kernel.h"
#include "sim/photons.h"
#include "sim/rigid_ice.h"
#include "sim/run_digest.h"
#include "sim/thermal.h"

namespace thaw {
namespace {

static_assert(static_cast<int>(Phase::Solid) == 2, "THAW_PHASE_SOLID in sim/kernels/grid_common.h");

// Cells of H / kGridReach. A finer grid visits fewer candidates per neighbour but walks more, shorter
// rows; with the neighbour loops on SIMD lanes, cells of H (9 rows of about 24 candidates) were the
// fastest of H, H/2 and H/3 (`thaw bench throughput`: see docs/BENCHMARKS.md).
constexpr int kGridReach = 1;

// SIMD lanes of the neighbour loops (sim/kernels/grid_common.h): candidates read at a time. 8 (AVX2
// width) beat 4 and 16 on the AVX-512 machine of docs/BENCHMARKS.md.
constexpr int kLanes = 8;

std::vector<float> rigid_mass_scales(const Scene& scene, double rest_density) {
  std::vector<float> out;
  for (const Material& m : scene.materials) out.push_back(static_cast<float>(mass_scale(m, rest_density)));
  return out;
}

RigidIce::Settings rigid_settings(const Scene& scene, const SolverConstants& k) {
  RigidIce::Settings r;
  r.spacing = scene.spacing;
  r.support = k.support;
  r.smoothing = k.smoothing;
  r.visc_boundary = k.visc_boundary;
  r.rest_density = k.rest_density;
  r.gravity = scene.gravity;
  r.domain_min = scene.domain.min;
  r.domain_max = scene.domain.max;
  r.grid_reach = kGridReach;
  // Contact springs as stiff as the water: k = rho0 c^2 dx oscillates a particle at about c / dx, which
  // the acoustic time step already resolves, and a resting body sinks into a floor by only
  // n dx g / c^2 (n particles high): a fraction of a percent of a spacing. Damping half the critical
  // value of an ice particle's mass; friction of wet ice on ice or glass.
  const double dx = scene.spacing;
  double rho_ice = k.rest_density;
  for (const Material& m : scene.materials)
    if (m.kind == MaterialKind::Ice) rho_ice = m.density;
  r.contact.stiffness = double(k.rest_density) * k.sound_speed * k.sound_speed * dx;
  r.contact.damping = 2.0 * 0.5 * std::sqrt(r.contact.stiffness * rho_ice * dx * dx * dx);
  r.contact.friction = 0.1;
  r.contact.distance = dx;
  return r;
}

}  // namespace

namespace {

// Only the kernel and EOS this scene uses are compiled in.
std::string program_options(const Scene& scene) {
  std::ostringstream opts;
  const bool wendland = scene.solver.kernel == KernelFunction::WendlandC2;
  opts << "-DKERNEL_W=" << (wendland ? "wendland_c2_w" : "cubic_spline_w")
       << " -DKERNEL_GRAD=" << (wendland ? "wendland_c2_grad_factor" : "cubic_spline_grad_factor");
  const bool dfsph = scene.solver.pressure == PressureSolver::Dfsph;
  // DFSPH solves for the pressure: the density pass writes none (sim/kernels/density.cl).
  if (dfsph) opts << " -DTHAW_DFSPH";
  // Air beside water: the number-density form in every pass that weighs neighbours (dfsph.cl).
  if (dfsph && scene.multiphase())
    opts << " -DTHAW_MULTIPHASE -DTHAW_MP_SPLIT=" << std::to_string(scene.rest_density_split()) << "f";
  if (dfsph && scene.multiphase() && scene.solver.multiphase == Multiphase::DomaradzkiMartyn)
    opts << " -DTHAW_MP_SYMMETRIC -DTHAW_VISC_ARITHMETIC_MEAN";
  if (scene.solver.eos == Eos::Tait && !dfsph) opts << " -DTHAW_EOS_TAIT";
  if (scene.solver.eos == Eos::Tait && scene.solver.gamma == 7.0) opts << " -DTHAW_GAMMA_7";
  if (wendland) opts << " -DTHAW_WENDLAND";
  // Flush subnormal floats: viscosity spreads velocities of 1e-30 m/s and less through a resting
  // lattice, and arithmetic on subnormals made the forces pass 2-4x slower for tens of steps after a
  // start (measured: docs/BENCHMARKS.md). Nothing physical lives below 1e-38.
  opts << " -cl-denorms-are-zero";
  opts << " -DTHAW_REACH=" << kGridReach << " -DTHAW_VW=" << kLanes;
  // Periodic y and z axes wrap the neighbour rows of every pass (grid_common.h); x wraps in the heat-only
  // mode alone, where the heat pass walks cell by cell (heat.cl).
  if (scene.solver.periodic[1]) opts << " -DTHAW_ROW_WRAP_Y";
  if (scene.solver.periodic[2]) opts << " -DTHAW_ROW_WRAP_Z";
  return opts.str();
}

// The domain and every particle (walls lie outside the domain).
std::pair<Eigen::Vector3f, Eigen::Vector3f> particle_bounds(const Scene& scene, const HostParticles& p) {
  Eigen::Vector3f lo = scene.domain.min.cast<float>(), hi = scene.domain.max.cast<float>();
  for (const auto& x : p.position) {
    lo = lo.cwiseMin(Eigen::Vector3f(x[0], x[1], x[2]));
    hi = hi.cwiseMax(Eigen::Vector3f(x[0], x[1], x[2]));
  }
  return {lo, hi};
}

// Boundary particles sampled by sample_scene() carry no mass yet: their Psi = rho0 V_b comes from the
// solver's rest density. Walls here sit on the fluid lattice and fill the kernel support, so the lattice
// cell dx^3 is their exact volume; Akinci's 1 / sum_k W_bk suits single-layer or irregular samplings but
// overestimates the fluid-facing layer of a lattice wall (docs/ARCHITECTURE.md, Numerics). Returns whether
// any boundary mass was missing.
bool give_boundaries_lattice_mass(HostParticles& p, const Scene& scene, float rest_density) {
  bool missing = false;
  const float lattice_psi = static_cast<float>(rest_density * std::pow(scene.spacing, 3));
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.phase[i] == static_cast<std::uint8_t>(Phase::Solid) && p.position[i][3] == 0.0f) {
      missing = true;
      p.position[i][3] = lattice_psi;
    }
  return missing;
}

// Rigid ice for scenes with free ice and flow; null otherwise.
std::unique_ptr<RigidIce> make_rigid_ice(ClRuntime& cl, ParticleStore& store, const std::string& opts,
                                         const Scene& scene, const SolverConstants& k, const HostParticles& p,
                                         std::size_t capacity, std::uint32_t ids) {
  const bool free_ice = std::any_of(scene.ice.begin(), scene.ice.end(),
                                    [](const IceBlock& b) { return b.motion == IceBlock::Motion::Free; });
  if (!free_ice || !scene.solver.flow) return nullptr;
  std::vector<std::uint8_t> anchored_by_id(ids, 0);
  for (std::size_t i = 0; i < p.size() && i < p.anchored.size(); ++i)
    if (p.id[i] < ids) anchored_by_id[p.id[i]] = p.anchored[i];
  // With tension the ice takes the reaction of the water's adhesion to it (rigid.cl, tension.cl).
  std::string options = opts;
  if (scene.tension.enabled())
    // brackbill1992 holds water to ice by akinci2013's adhesion
    options += scene.tension.model == TensionModel::Iwasaki2010
                   ? " -DTHAW_TENSION_REACTION -DTHAW_TENSION_IWASAKI2010"
                   : " -DTHAW_TENSION_REACTION -DTHAW_TENSION_AKINCI2013";
  auto rigid =
      std::make_unique<RigidIce>(cl, store, options, capacity, rigid_settings(scene, k),
                                 std::move(anchored_by_id), rigid_mass_scales(scene, k.rest_density));
  if (scene.tension.enabled()) rigid->use_tension(tension_coefficients(scene, k).adhesion);
  return rigid;
}

// Room for the emitters' first second, and a layer of room air, beside the particles there are; the solver
// grows it later.
std::size_t first_capacity(const Scene& scene, std::size_t n, const EmitterStage* emitters) {
  if (!emitters) return n;
  double per_second = 0;
  for (const Emitter& e : scene.emitters) per_second += EmitterStage::particles_per_second(e, scene.spacing);
  for (const Dryer& d : scene.dryers)
    if (d.model == DryerModel::Air) per_second += EmitterStage::particles_per_second(d, scene.spacing);
  // A second of pouring, but never past the particles the machine has room for (particle_limit), which is
  // checked before anything is allocated. Filling it later grows the run, or stops it with a message once
  // that limit is reached (emit).
  const double wanted =
      double(n) + std::max(1024.0, std::ceil(per_second)) + double(emitters->room_sites().size());
  return static_cast<std::size_t>(std::max(double(n), std::min(wanted, particle_limit())));
}

}  // namespace

Solver::Solver(ClRuntime& cl, const Scene& scene, const SimState& st)
    : cl_(cl), scene_(scene), k_(derive_constants(scene)), store_(cl) {
  if (EmitterStage::needed(scene_)) emitters_ = std::make_unique<EmitterStage>(scene_);
  if ((digest_ = RunDigest::active())) digest_number_ = digest_->solver_made();
  build(st, 0);
}

void Solver::build(const SimState& st, std::size_t capacity) {
  const HostParticles& p = st.particles;
  n_ = p.size();
  time_ = st.time;
  dt_ = st.dt;
  steps_ = st.step;
  clamped_base_ = st.clamped;
  const EmitterStage::Saved saved = emitters_ ? emitters_->restore(st.inflow) : EmitterStage::Saved{};
  std::uint64_t ids = n_ ? std::uint64_t(*std::max_element(p.id.begin(), p.id.end())) + 1 : 0;
  ids = std::max(ids, saved.next_id);
  if (ids > 0xffffffffull) throw Error("state: particle ids past 32 bits");
  next_id_ = static_cast<std::uint32_t>(ids);
  if (capacity == 0) capacity = saved.capacity ? saved.capacity : first_capacity(scene_, n_, emitters_.get());
  layout_ = layout_for(n_, capacity, cl_.layout_tiles());
  const auto [lo, hi] = particle_bounds(scene_, p);
  const std::string opts = program_options(scene_);
  const HeatPlan plan = plan_heat(scene_, p);
  heat_reason_ = plan.reason;

  // The stages this scene needs, each declaring its fields; then the fields are allocated and filled.
  rigid_.reset();
  substances_.reset();
  tension_.reset();
  surface_.reset();
  surface_done_ = false;
  heat_.reset();
  dfsph_.reset();
  fluid_.reset();
  grid_.reset();
  store_.clear();
  grid_built_ = false;
  f_ = add_core_fields(store_);
  const StageContext ctx{cl_, store_, f_, scene_, k_, opts, layout_};
  grid_ = std::make_unique<NeighbourGrid>(cl_, scene_, k_.support, kGridReach, opts, layout_, lo, hi);
  if (emitters_) grid_->set_room_sites(emitters_->room_sites());
  if (scene_.solver.flow) fluid_ = std::make_unique<FluidStage>(ctx, plan.build);
  if (fluid_ && scene_.solver.pressure == PressureSolver::Dfsph)
    dfsph_ = std::make_unique<DfsphStage>(ctx, fluid_->flow(), plan.build);
  if (dfsph_) fluid_->compute_dfsph_alpha(dfsph_->columns(), dfsph_->min_neighbours());
  if (fluid_ && scene_.tension.enabled()) tension_ = std::make_unique<TensionStage>(ctx);
  rigid_ = make_rigid_ice(cl_, store_, opts, scene_, k_, p, layout_.capacity, next_id_);
  if (rigid_ && fluid_ && dfsph_ && scene_.multiphase())
    rigid_->use_multiphase(fluid_->flow(), dfsph_->columns(), layout_.stride);
  forces_velocity_ = rigid_ && dfsph_
                         ? cl::Buffer(cl_.context(), CL_MEM_READ_WRITE, layout_.capacity * sizeof(cl_float4))
                         : cl::Buffer();
  if (plan.build) heat_ = std::make_unique<HeatStage>(ctx, plan, lo, hi);
  // The surface's areas where heat exchanges through them or surface-active substances sit on them.
  if ((heat_ && heat_->uses_surface()) || substances_need_surface(scene_))
    surface_ = std::make_unique<SurfaceStage>(ctx);
  if (heat_ && heat_->uses_surface()) heat_->surface_from(surface_->area());
  if (!scene_.substances.empty()) {
    const ParticleStore::Field enthalpy = heat_ ? heat_->enthalpy() : 0;
    const SurfaceFields surface =
        surface_ ? SurfaceFields{surface_->area(), surface_->normal()} : SurfaceFields{};
    substances_ =
        std::make_unique<SubstanceStage>(ctx, heat_ ? &enthalpy : nullptr, surface_ ? &surface : nullptr);
  }
  if (substances_ && substances_->lowers_melting()) heat_->melt_shift_from(substances_->melt_shift());
  if (tension_ && substances_ && substances_lower_tension(scene_))
    tension_->ratio_from(substances_->tension_ratio());
  plan_ = step_plan({.flow = fluid_ != nullptr,
                     .dfsph = dfsph_ != nullptr,
                     .tension = tension_ != nullptr,
                     .rigid = rigid_ != nullptr,
                     .heat = heat_ != nullptr,
                     .photons = heat_ && !scene_.lamps.empty(),
                     .surface = surface_ != nullptr,
                     .substances = substances_ != nullptr,
                     .emitters = emitters_ != nullptr});
  if (fluid_ && heat_) fluid_->buoyancy_from(heat_->enthalpy());
  if (dfsph_ && heat_) dfsph_->rest_density_from(heat_->enthalpy());
  store_.allocate(layout_.capacity);
  store_.resize(n_);

  clamped_ = cl::Buffer(cl_.context(), CL_MEM_READ_WRITE, 4);
  table_ = material_thermal_table(scene_, k_.rest_density);

  HostParticles init = p;
  const bool psi_missing = give_boundaries_lattice_mass(init, scene_, k_.rest_density);
  upload(init);
  // Areas a state (or the solver's own growth) brings are the ones its run had: they serve until the next
  // update (heat.area_interval), as they would have.
  surface_done_ = surface_ && init.column("surface_area") != nullptr;
  if (psi_missing && scene_.solver.boundary_volume == BoundaryVolume::Akinci2012) compute_boundary_psi(opts);
  if (rigid_ && !st.rigid_bodies.empty()) {
    if (!p.column("body") || !p.column("body_offset"))
      throw Error("state: rigid ice bodies without each particle's body and body_offset");
    rigid_->restore({st.rigid_bodies, st.rigid_labelling});
  }
  budget_ = st.energy_budget.empty() ? EnergyBudget{} : EnergyBudget::from_vector(st.energy_budget);
  outflow_ = OutflowBooks::from_vector(st.outflow);
  if (st.energy_budget.empty()) budget_.initial = total_enthalpy();
  if (substances_ && !st.substances.empty()) {
    substance_books_ = SubstanceBooks::from_vector(st.substances, scene_.substances.size());
  } else if (substances_) {
    substance_books_.initial = substances_->totals();
    substance_books_.outflow.assign(scene_.substances.size(), 0.0);
    substance_books_.inflow.assign(scene_.substances.size(), 0.0);
  }
}

Solver::~Solver() {
  // Its last state, for a RunDigest that compares runs by their ends. A device that fails here has already
  // failed the run: nothing is recorded then.
  RunDigest* d = listening();
  if (!d) return;
  try {
    d->record(digest_number_, "end", state());
  } catch (const std::exception&) {
  }
}

ParticleBuffers Solver::buffers() const {
  return {store_[f_.position],
          store_[f_.velocity],
          fluid_->state(),
          store_[f_.phase],
          store_[f_.material],
          store_[f_.id],
          grid_->cell_start(),
          cl_grid(grid_->info()),
          static_cast<std::uint32_t>(n_),
          next_id_};
}

void Solver::upload(const HostParticles& p) {
  auto& q = cl_.queue();
  if (n_ == 0) return;
  store_.upload(p);
  if (!heat_) {
    std::vector<Float2> enthalpy = p.enthalpy;
    enthalpy.resize(n_, Float2{0.f, 0.f});
    // Without heat a particle's enthalpy never changes: the host keeps it by id, unsorted.
    fixed_enthalpy_.assign(next_id_, Float2{0.f, 0.f});
    for (std::size_t i = 0; i < n_; ++i) fixed_enthalpy_[p.id[i]] = enthalpy[i];
  }
  const cl_uint zero = 0;
  q.enqueueWriteBuffer(clamped_, CL_TRUE, 0, 4, &zero);
}

template <class F>
void Solver::timed(Stage s, F&& f) {
  const auto t0 = Clock::now();
  f();
  cl_.queue().finish();
  timers_.add(s, seconds_since(t0));
  RunDigest* d = listening();
  if (d && d->detail() == RunDigest::Detail::Stages) d->record(digest_number_, kStageNames[int(s)], state());
}

RunDigest* Solver::listening() const { return digest_ && RunDigest::active() == digest_ ? digest_ : nullptr; }

void Solver::report(const char* stage) {
  RunDigest* d = listening();
  if (!d) return;
  if (d->detail() != RunDigest::Detail::Ends) d->record(digest_number_, stage, state());
  if (d->stop_after() && steps_ >= d->stop_after()) throw RunDigest::Stopped{};
}

void Solver::build_grid(bool intake) {
  const std::size_t kept =
      grid_->build(store_, f_, clamped_, intake && emitters_ ? &emitters_->owed() : nullptr);
  if (kept < n_) remove_particles_from(kept);
  grid_built_ = true;
}

void Solver::remove_particles_from(std::size_t kept) {
  // The sort put the particles that left through an open side behind the others: book them, then use
  // only the ones before them. Neighbour ranges already end before them (no cell holds them).
  const std::size_t gone = n_ - kept;
  auto& q = cl_.queue();
  std::vector<Float4> x(gone), v(gone);
  std::vector<std::uint8_t> material(gone);
  std::vector<std::uint32_t> id(gone);
  std::vector<Float2> h(gone);
  q.enqueueReadBuffer(store_[f_.position], CL_FALSE, kept * 16, gone * 16, x.data());
  q.enqueueReadBuffer(store_[f_.velocity], CL_FALSE, kept * 16, gone * 16, v.data());
  q.enqueueReadBuffer(store_[f_.material], CL_FALSE, kept, gone, material.data());
  if (heat_) q.enqueueReadBuffer(store_[heat_->enthalpy()], CL_FALSE, kept * 8, gone * 8, h.data());
  q.enqueueReadBuffer(store_[f_.id], CL_TRUE, kept * 4, gone * 4, id.data());
  // Substances that left with the water, booked before the particles go.
  if (substances_) {
    std::vector<Float2> amount(gone);
    for (std::size_t s = 0; s < substances_->fields().size(); ++s)
      for (const ParticleStore::Field f : substances_->amount_fields(s)) {
        q.enqueueReadBuffer(store_[f], CL_TRUE, kept * sizeof(Float2), gone * sizeof(Float2), amount.data());
        for (const Float2& a : amount) substance_books_.outflow[s] += double(a[0]) + double(a[1]);
      }
  }
  for (std::size_t k = 0; k < gone; ++k) {
    if (!heat_) h[k] = fixed_enthalpy_[id[k]];
    const double mass = double(x[k][3]) * table_[material[k]].thermal_mass_scale;
    outflow_.mass += mass;
    outflow_.momentum += mass * Eigen::Vector3d(v[k][0], v[k][1], v[k][2]);
    budget_.outflow += mass * (double(h[k][0]) + double(h[k][1]));
  }
  outflow_.particles += gone;
  n_ = kept;
  layout_.use(kept);
  store_.resize(kept);
}

void Solver::emit(double dt) {
  // What the emitters and the ids were before this step's particles, should they not fit.
  const std::vector<double> before = emitters_->save({next_id_, layout_.capacity});
  const std::uint32_t first_id = next_id_;
  HostParticles in = emitters_->emit(time_ - dt, dt, next_id_);
  // The room's air into the open sides' empty sites, on this step's grid (built at its start).
  if (grid_built_ && !emitters_->room_sites().empty()) {
    const NeighbourGrid::EmptySites empty =
        grid_->empty_sites(store_, f_, EmitterStage::room_air_gap * scene_.spacing);
    emitters_->admit_room_air(empty.site, empty.velocity, in, next_id_);
    in.resize(in.size());  // the room's air carries no substance: its columns' rows are zeros
  }
  if (in.size() == 0) return;
  if (n_ + in.size() > layout_.capacity) {
    // Out of room: rebuild every stage for half as many again (at least what is needed) from the state,
    // as a resumed run would; a run resumed from a state file written before this point grows here too.
    const std::size_t least = n_ + in.size();
    const std::size_t grown = static_cast<std::size_t>(
        std::max(double(least), std::min(double(layout_.capacity + layout_.capacity / 2), particle_limit())));
    const double needed = estimated_memory_bytes(double(grown)), limit = memory_limit_bytes();
    if (needed > limit || double(grown) > particle_limit()) {
      // Nothing came in: the books and ids stay with the particles there are.
      emitters_->restore(before);
      next_id_ = first_id;
      std::ostringstream os;
      os << "step " << steps_ << " (t = " << time_ << " s): the emitters have filled the run to " << n_
         << " particles, and " << grown << " would need about " << needed / 1e9 << " GB, more than the "
         << particle_limit() << " particles a run may hold (" << limit / 1e9
         << " GB available, THAW_MEMORY_LIMIT; 20 million at most); close the tap (emitters[].open), set "
         << "emitters[].stop, or open a side of the domain (domain.open)";
      throw BlowUpError(os.str());
    }
    build(state(), grown);
  }
  for (std::size_t i = 0; i < in.size(); ++i) {
    const double mass = double(in.position[i][3]) * table_[in.material[i]].thermal_mass_scale;
    budget_.inflow += mass * (double(in.enthalpy[i][0]) + double(in.enthalpy[i][1]));
  }
  for (std::size_t s = 0; substances_ && s < scene_.substances.size(); ++s)
    if (const HostColumn* c = in.column(substance_field(scene_.substances[s].name).name))
      for (std::size_t i = 0; i < in.size(); ++i)
        substance_books_.inflow[s] += double(c->as<Float2>()[i][0]) + double(c->as<Float2>()[i][1]);
  if (!heat_) {
    fixed_enthalpy_.resize(next_id_, Float2{0.f, 0.f});
    for (std::size_t i = 0; i < in.size(); ++i) fixed_enthalpy_[in.id[i]] = in.enthalpy[i];
  }
  store_.append(in);
  n_ = store_.size();
  layout_.use(n_);
  grid_built_ = false;
}

void Solver::compute_boundary_psi(const std::string& opts) {
  // Once, at the start, and only for scenes that ask for Akinci's volumes: built here, not kept.
  const auto boundary = cl_.build(neighbour_program({"boundary.cl"}), opts);
  cl::Kernel psi(boundary, "boundary_psi"), set_mass(boundary, "set_mass");
  cl::Buffer scratch(cl_.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(n_, 1) * 4);
  build_grid(false);
  auto& q = cl_.queue();
  const auto n = static_cast<cl_uint>(n_);
  const ClGrid g = cl_grid(grid_->info());
  set_args(psi, store_[f_.position], store_[f_.phase], grid_->cell_start(), g, k_.support, k_.rest_density,
           scratch, n);
  launch(q, psi, n_);
  set_args(set_mass, store_[f_.position], scratch, n);
  launch(q, set_mass, n_);
  q.finish();
}

void Solver::compute_density() {
  if (dfsph_) dfsph_->mark_fluid();  // the density pass reads it for DFSPH's alpha
  if (fluid_) fluid_->density(neighbours());
}

void Solver::compute_forces() {
  if (fluid_) fluid_->forces(neighbours());
}

double Solver::heat_time_step() const {
  return heat_ ? heat_->max_dt() : std::numeric_limits<double>::infinity();
}

double Solver::choose_time_step() {
  const auto& s = scene_.solver;
  if (!s.flow) {
    // Nothing moves: only heat and the substances' diffusion limit the step.
    double dt = std::min(s.max_dt, heat_time_step());
    if (substances_) dt = std::min(dt, substances_->max_dt());
    dt = static_cast<float>(dt);
    if (dt < s.min_dt) {
      std::ostringstream os;
      os << "step " << steps_ + 1 << " (t = " << time_ << " s): the heat time step " << dt
         << " s is below solver.min_dt = " << s.min_dt << " s; lower heat.time_scale or coarsen the spacing";
      throw BlowUpError(os.str());
    }
    return dt;
  }
  const FlowLimits lim = fluid_->limits();
  const double vmax2 = lim.vmax2, amax2 = lim.amax2;
  const std::uint32_t fastest = lim.fastest, bad = lim.bad;
  auto particle_at = [&](std::uint32_t i) {
    Float4 x, v;
    std::uint32_t id = 0;
    cl_.queue().enqueueReadBuffer(store_[f_.position], CL_TRUE, i * 16, 16, x.data());
    cl_.queue().enqueueReadBuffer(store_[f_.velocity], CL_TRUE, i * 16, 16, v.data());
    cl_.queue().enqueueReadBuffer(store_[f_.id], CL_TRUE, i * 4, 4, &id);
    std::ostringstream os;
    os << "particle " << id << " at (" << x[0] << ", " << x[1] << ", " << x[2] << ") m with velocity ("
       << v[0] << ", " << v[1] << ", " << v[2] << ") m/s";
    return os.str();
  };
  auto where = [&] {
    std::ostringstream os;
    os << "step " << steps_ + 1 << " (t = " << time_ << " s): ";
    return os.str();
  };
  // DFSPH has no sound speed: its step follows the flow.
  const char* advice = dfsph_ ? "; lower solver.max_dt or solver.cfl, or tighten solver.density_tolerance"
                              : "; lower solver.max_dt or solver.cfl, or raise solver.sound_speed_factor";
  if (bad != 0xffffffffu) {
    const bool accel_only = (bad & 0x80000000u) != 0;
    throw BlowUpError(
        where() + particle_at(bad & 0x7fffffffu) +
        (accel_only ? " has a non-finite acceleration" : " has a non-finite position or velocity") + advice);
  }
  const double body_speed = rigid_ ? rigid_->max_point_speed() : 0.0;
  if (body_speed > k_.max_speed) {
    std::ostringstream os;
    os << where() << "an ice body moves at " << body_speed << " m/s, above the limit " << k_.max_speed
       << " m/s (solver.max_speed)" << advice;
    throw BlowUpError(os.str());
  }
  const double vmax = std::max(std::sqrt(vmax2), body_speed);
  if (vmax > k_.max_speed) {
    std::ostringstream os;
    os << where() << particle_at(fastest) << " moves at " << vmax << " m/s, above the limit " << k_.max_speed
       << " m/s (solver.max_speed)" << advice;
    throw BlowUpError(os.str());
  }
  const double h = k_.smoothing;
  double dt = s.max_dt;
  if (dfsph_) {
    // Incompressible: the CFL condition on the flow's speed alone (Bender & Koschier 2017, sec. 4.1).
    if (vmax > 0) dt = std::min(dt, s.cfl * h / vmax);
  } else {
    dt = std::min(dt, s.cfl * h / (k_.sound_speed + vmax));  // CFL (acoustic + advective)
  }
  if (amax2 > 0) dt = std::min(dt, s.force_number * std::sqrt(h / std::sqrt(amax2)));
  // The viscous pair sum's stiffness grows with the neighbours a particle has per spacing, not with the
  // kernel's width: the limit takes the smaller of h and the spacing (Wendland C2 over 3 spacings has
  // h = 1.5 dx, and no-slip walls' ghost velocities, which double a wall pair's velocity difference, blew
  // a plane Poiseuille flow up in 160 steps at 0.125 h^2 / nu; 0.05 h^2 / nu ran).
  const double hv = std::min(double(h), scene_.spacing);
  if (k_.kinematic_viscosity > 0) dt = std::min(dt, s.viscous_number * hv * hv / k_.kinematic_viscosity);
  if (tension_) dt = std::min(dt, k_.capillary_dt);
  if (substances_) dt = std::min(dt, substances_->max_dt());
  // Conduction's limit, or as many of it as heat.max_substeps lets one flow step hold (compute_heat).
  const double dt_heat = heat_time_step() * scene_.heat.max_substeps;
  dt = std::min(dt, dt_heat);
  dt = static_cast<float>(dt);  // the kernels see a float: keep host time consistent with them
  if (dt < s.min_dt) {
    std::ostringstream os;
    os << where() << "the adaptive time step fell to " << dt << " s, below solver.min_dt = " << s.min_dt
       << " s (max acceleration " << std::sqrt(amax2) << " m/s^2, max speed " << vmax << " m/s, heat limit "
       << dt_heat << " s)" << advice;
    throw BlowUpError(os.str());
  }
  return dt;
}

void Solver::trace_photons(double dt) {
  if (heat_) heat_->trace_photons(dt, steps_, budget_);
}

NeighbourView Solver::neighbours() const { return grid_->view(); }

// Without flow the particles never move: the first pass's areas serve the whole run. With flow they are
// updated every heat.area_interval steps (counted from step 0, so a resumed run updates when the straight one
// did).
bool Solver::surface_due() const {
  const auto interval = static_cast<std::uint64_t>(scene_.heat.area_interval);
  return !surface_done_ || (scene_.solver.flow && steps_ % interval == 0);
}

void Solver::compute_heat(double dt) {
  if (!heat_) return;
  // Sub-steps (heat.max_substeps): equal parts of the flow step, each within conduction's limit, with the
  // particles where they are; the books add up over them.
  const double limit = heat_->max_dt();
  const int parts =
      dt > limit ? std::min(scene_.heat.max_substeps, static_cast<int>(std::ceil(dt / limit - 1e-9))) : 1;
  bool changed = false;
  for (int k = 0; k < parts; ++k)
    changed |=
        heat_->run(dt / parts, neighbours(), budget_, steps_, time_ + k * (dt / parts), rigid_ != nullptr);
  if (changed) rigid_->note_phase_change();
}

void Solver::label_ice() {
  if (rigid_) rigid_->relabel_if_due(buffers(), steps_, true);
}

void Solver::compute_ice_forces() {
  if (rigid_) rigid_->compute_forces(buffers());
}

std::vector<Float4> Solver::ice_forces() const {
  return rigid_ ? rigid_->forces(n_) : std::vector<Float4>(n_, Float4{0.f, 0.f, 0.f, 0.f});
}

void Solver::integrate(double dt) {
  if (fluid_) fluid_->integrate(dt, 1.0 / (1.0 + damping_ * dt));
}

// Walks the step's passes (sim/step_plan.h), each timed on its stage's timer.
void Solver::step() {
  double dt = 0;
  for (const Pass p : plan_) run_pass(p, dt);
  report("step");
}

void Solver::run_pass(Pass p, double& dt) {
  Stage timer = Stage::Count;
  pass_timer(p, timer);
  switch (p) {
    case Pass::Grid:
      // Without flow nothing moves: one sort serves the whole run.
      if (scene_.solver.flow || !grid_built_) timed(timer, [&] { build_grid(); });
      break;
    case Pass::Labels:
      timed(timer, [&] { rigid_->relabel_if_due(buffers(), steps_); });
      break;
    case Pass::Density:  // with DFSPH's alpha for both solves
      timed(timer, [&] { compute_density(); });
      break;
    case Pass::DivergenceSolve:
      timed(timer, [&] { dfsph_->divergence_solve(neighbours(), dt_); });
      break;
    case Pass::Forces:
      timed(timer, [&] {
        compute_forces();
        // Rigid ice's reaction to the viscous pair terms must see the velocities the water's side was
        // computed from, or momentum is not exchanged exactly (RigidIceTest.IceAndWaterKeepTheirTotalMomentum
        // UnderDfsph); DFSPH's solves change them before the ice takes its forces.
        if (dfsph_ && rigid_ && n_ > 0)
          cl_.queue().enqueueCopyBuffer(store_[f_.velocity], forces_velocity_, 0, 0, n_ * sizeof(cl_float4));
      });
      break;
    case Pass::Tension:
      timed(timer, [&] { tension_->run(neighbours(), fluid_->accel()); });
      break;
    case Pass::IceForces:
      timed(timer, [&] {
        const ParticleBuffers b = buffers();
        if (!dfsph_) {
          rigid_->compute_forces(b);
        } else {
          // After DFSPH's solves: their pressure impulses, and the forces pass's viscosity from the
          // velocities that pass saw (rigid.cl).
          rigid_->compute_forces({b.position, forces_velocity_, b.state, b.phase, b.material, b.id,
                                  b.cell_start, b.grid, b.n, b.ids});
        }
      });
      break;
    case Pass::TimeStep:
      timed(timer, [&] { dt = choose_time_step(); });
      break;
    case Pass::Surface:
      if (surface_due()) timed(timer, [&] { surface_->run(neighbours()); });
      surface_done_ = true;
      break;
    case Pass::SubstanceState:
      timed(timer, [&] { substances_->prepare(neighbours()); });
      break;
    case Pass::Photons:
      timed(timer, [&] { trace_photons(dt); });
      break;
    case Pass::Heat:
      timed(timer, [&] { compute_heat(dt); });
      break;
    case Pass::SubstanceDiffusion:
      timed(timer, [&] { substances_->diffuse(dt, neighbours()); });
      break;
    case Pass::DensitySolve:
      timed(timer, [&] {
        dfsph_->predict(fluid_->accel(), neighbours(), dt, 1.0 / (1.0 + damping_ * dt));
        dfsph_->density_solve(neighbours(), dt);
        dfsph_->write_pressure(fluid_->state(), dt);
      });
      break;
    case Pass::Bodies:
      timed(timer, [&] { rigid_->advance(buffers(), dt); });
      break;
    case Pass::Integrate:
      timed(timer, [&] {
        grid_->drive_pipes(store_, f_);  // (WCSPH's v += a dt then moves the pipes' air a little off)
        if (dfsph_)
          dfsph_->drift(dt);
        else
          integrate(dt);
      });
      break;
    case Pass::Advance:
      time_ += dt;
      dt_ = dt;
      ++steps_;
      break;
    case Pass::Emit:
      timed(timer, [&] { emit(dt); });
      break;
  }
}

void Solver::hold_ice(bool held) {
  if (rigid_) rigid_->hold(held);
}

// The step's passes that change no state, at dt = 0: a sort of sorted keys is the identity, and dt = 0 leaves
// x, v and the enthalpy unchanged (the air dryers take nothing in; the solves, diffusion and bodies wait for
// a step).
void Solver::warm_up() {
  for (const Pass p : plan_) {
    switch (p) {
      case Pass::Grid:
        build_grid(false);
        break;
      case Pass::Labels:  // the first labelling is due before the first step anyway, at these positions
        rigid_->relabel_if_due(buffers(), steps_);
        break;
      case Pass::Density:
        compute_density();
        break;
      case Pass::Forces:
        compute_forces();
        break;
      case Pass::Tension:
        tension_->run(neighbours(), fluid_->accel());
        break;
      case Pass::IceForces:
        rigid_->compute_forces(buffers());
        break;
      case Pass::TimeStep:
        choose_time_step();
        break;
      case Pass::Surface:
        if (!surface_done_) surface_->run(neighbours());
        surface_done_ = true;
        break;
      case Pass::SubstanceState:
        substances_->prepare(neighbours());
        break;
      case Pass::Heat:
        heat_->warm_up(neighbours(), budget_);  // its sums of zero leave the budget unchanged
        break;
      case Pass::Integrate:
        integrate(0.0);
        break;
      case Pass::DivergenceSolve:
      case Pass::Photons:
      case Pass::SubstanceDiffusion:
      case Pass::DensitySolve:
      case Pass::Bodies:
      case Pass::Advance:
      case Pass::Emit:
        break;
    }
  }
  cl_.queue().finish();
}

void Solver::set_dryer(std::size_t index, const Dryer& d) {
  if (index >= scene_.dryers.size())
    throw Error("dryer " + std::to_string(index) + " does not exist; the scene has " +
                std::to_string(scene_.dryers.size()));
  const std::string path = "dryers[" + std::to_string(index) + "]";
  Json j = to_json(d);
  validate(j, *find_field(scene_schema(), "dryers[0]"), path);
  Dryer checked = dryer_from_json(j, path);
  check_dryer(checked, scene_, path);
  if (checked.model != scene_.dryers[index].model)
    throw Error(path + ".model: a dryer's model is fixed while the scene runs (it decides the stages built)");
  scene_.dryers[index] = checked;
  if (heat_) heat_->dryers_changed();
}

void Solver::set_lamp(std::size_t index, const Lamp& l) {
  if (index >= scene_.lamps.size())
    throw Error("lamp " + std::to_string(index) + " does not exist; the scene has " +
                std::to_string(scene_.lamps.size()));
  const std::string path = "lamps[" + std::to_string(index) + "]";
  Json j = to_json(l);
  validate(j, *find_field(scene_schema(), "lamps[0]"), path);
  scene_.lamps[index] = lamp_from_json(j, path);
  if (heat_) heat_->lamps_changed();
}

bool Solver::set_emitter(std::size_t index, const Emitter& e) {
  if (index >= scene_.emitters.size())
    throw Error("emitter " + std::to_string(index) + " does not exist; the scene has " +
                std::to_string(scene_.emitters.size()));
  const std::string path = "emitters[" + std::to_string(index) + "]";
  Json j = to_json(e, scene_.materials);
  validate(j, *find_field(scene_schema(), "emitters[0]"), path);
  Emitter checked = emitter_from_json(j, path, scene_.materials);
  checked.substances = scene_.emitters[index].substances;  // fixed while the scene runs
  check_emitter(checked, scene_, path);
  if (checked.material != scene_.emitters[index].material) return false;
  if (!heat_ && checked.temperature != scene_.emitters[index].temperature) return false;
  // The sound speed was chosen for the fastest water the scene could make (derive_constants): a faster
  // or higher jet needs a stiffer fluid, so a new solver.
  Scene next = scene_;
  next.emitters[index] = checked;
  if (derive_constants(next).sound_speed > k_.sound_speed) return false;
  scene_.emitters[index] = checked;
  return true;
}

std::vector<std::string> Solver::stages() const {
  std::vector<std::string> out;
  std::vector<std::string> named;
  for (const Pass p : plan_) {
    const std::string stage = pass_stage(p);
    if (stage.empty() || std::find(named.begin(), named.end(), stage) != named.end()) continue;
    named.push_back(stage);
    // What a newcomer needs beside the name: the model, the form that holds air beside water, why heat was
    // built.
    if (p == Pass::Tension) {
      out.push_back(stage + " (" + name(scene_.tension.model) + ")");
    } else if (p == Pass::DivergenceSolve) {
      out.push_back(scene_.multiphase()
                        ? "pressure (dfsph, multiphase " + std::string(name(scene_.solver.multiphase)) +
                              (scene_.air.buoyancy == Buoyancy::IdealGas ? ", eq 7's ideal-gas air)" : ")")
                        : "pressure (dfsph)");
    } else if (p == Pass::Photons) {
      out.push_back(heat_->tracing_photons() ? stage : "photons (when a lamp is on)");
    } else if (p == Pass::Surface) {
      out.push_back(stage + " (" + name(surface_->model()) + ")");
    } else if (p == Pass::Heat) {
      out.push_back("heat (" + heat_reason_ + ")");
    } else if (p == Pass::SubstanceState) {
      out.push_back("substances (" + std::to_string(scene_.substances.size()) + ")");
    } else if (p == Pass::Emit) {
      // A scene without taps or dryers has this stage for its open sides: say so.
      out.push_back(EmitterStage::admits_room_air(scene_) ? "emit (room air through open sides)" : "emit");
    } else {
      out.push_back(stage);
    }
  }
  return out;
}

std::vector<Stage> Solver::timed_stages() const {
  std::vector<Stage> out;
  for (const Pass p : plan_) {
    Stage t = Stage::Count;
    if (pass_timer(p, t) && std::find(out.begin(), out.end(), t) == out.end()) out.push_back(t);
  }
  return out;
}

std::vector<double> Solver::held_power() const {
  std::vector<double> out;
  if (heat_) out = heat_->held_power(store_[f_.material], scene_.materials.size());
  return out;
}

Solver::ThermalInputs Solver::thermal_inputs() const {
  ThermalInputs t;
  if (heat_) heat_->thermal_inputs(t.temperature, t.conductivity, t.volume);
  return t;
}

double Solver::total_enthalpy() const {
  if (n_ == 0) return 0.0;
  const HostParticles p = particles();
  double sum = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    const double mass = double(p.position[i][3]) * table_[p.material[i]].thermal_mass_scale;
    sum += mass * (double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]));
  }
  return sum;
}

std::vector<float> Solver::surface_areas() const {
  std::vector<float> a;
  if (!surface_ || n_ == 0) return a;
  a.resize(n_);
  cl_.queue().enqueueReadBuffer(store_[surface_->area()], CL_TRUE, 0, n_ * 4, a.data());
  return a;
}

std::vector<float> Solver::temperatures() const {
  std::vector<float> t = temperatures_of(particles(), scene_);
  t.resize(n_, 0.0f);
  return t;
}

std::uint64_t Solver::clamped() const {
  cl_uint c = 0;
  cl_.queue().enqueueReadBuffer(clamped_, CL_TRUE, 0, 4, &c);
  return clamped_base_ + c + (rigid_ ? rigid_->clamped() : 0);
}

HostParticles Solver::particles() const {
  HostParticles p;
  store_.download(p);
  if (!heat_)
    for (std::size_t i = 0; i < n_; ++i) p.enthalpy[i] = fixed_enthalpy_[p.id[i]];
  return p;
}

SimState Solver::state() const {
  SimState s;
  s.particles = particles();
  s.step = steps_;
  s.time = time_;
  s.dt = dt_;
  s.clamped = clamped();
  s.scene_json = scene_.source.dump();
  s.energy_budget = budget_.to_vector();
  if (outflow_.particles) s.outflow = outflow_.to_vector();
  if (emitters_) s.inflow = emitters_->save({next_id_, layout_.capacity});
  if (substances_) s.substances = substance_books_.to_vector();
  if (rigid_) {
    RigidIce::Saved r = rigid_->save();
    s.rigid_bodies = std::move(r.bodies);
    s.rigid_labelling = std::move(r.labelling);
  }
  return s;
}

std::size_t Solver::drop_substance(std::size_t s, double amount, const Eigen::Vector3d& at) {
  if (!substances_ || s >= scene_.substances.size())
    throw Error("substance.drop: the scene has no substance " + std::to_string(s));
  if (!(amount > 0) || !std::isfinite(amount))
    throw Error("substance.drop: amount " + std::to_string(amount) + " kg must be positive");
  if (!at.allFinite()) throw Error("substance.drop: the point is not finite");
  std::vector<Float4> x(n_);
  std::vector<std::uint8_t> phase(n_);
  auto& q = cl_.queue();
  if (n_ > 0) {
    q.enqueueReadBuffer(store_[f_.position], CL_FALSE, 0, n_ * sizeof(Float4), x.data());
    q.enqueueReadBuffer(store_[f_.phase], CL_TRUE, 0, n_, phase.data());
  }
  // Shares by the kernel's weight among the water and ice within its support of the point. No particle may
  // hold more of it than its own mass (as a state file may not): where those particles cannot hold the dose
  // together (the point lies on a thin film, or the dose is a large pinch), it spreads over the water and ice
  // within twice and then three times the support, by the kernel stretched to that reach; past what even
  // those hold it is refused whole, saying the most they take. What a particle's melt cannot dissolve stays
  // undissolved with it (sim/kernels/liquidus.h).
  const double H = k_.support;
  const bool wendland = scene_.solver.kernel == KernelFunction::WendlandC2;
  const cl::Buffer& field = store_[substances_->fields()[s]];
  std::vector<Float2> amounts(n_);
  std::vector<std::uint8_t> material(n_);
  if (n_ > 0) {
    q.enqueueReadBuffer(field, CL_FALSE, 0, n_ * sizeof(Float2), amounts.data());
    q.enqueueReadBuffer(store_[f_.material], CL_TRUE, 0, n_, material.data());
  }
  std::vector<std::pair<std::size_t, double>> share;
  std::vector<double> room;
  double most = 0;
  bool any = false;
  for (int reach = 1; reach <= 3; ++reach) {
    const double R = reach * H;
    share.clear();
    room.clear();
    double held_room = 0;
    for (std::size_t i = 0; i < n_; ++i) {
      const auto ph = static_cast<Phase>(phase[i]);
      if ((ph != Phase::Water && ph != Phase::Ice) || !(x[i][3] > 0)) continue;
      const double r2 = (Eigen::Vector3d(x[i][0], x[i][1], x[i][2]) - at).squaredNorm();
      if (r2 >= R * R) continue;
      const float r = static_cast<float>(std::sqrt(r2));
      const double w = wendland ? sph::wendland_c2_w(r, float(R)) : sph::cubic_spline_w(r, float(R));
      if (!(w > 0)) continue;
      const double mass = double(x[i][3]) * table_.at(material[i]).thermal_mass_scale;
      share.push_back({i, w});
      room.push_back(std::max(mass - (double(amounts[i][0]) + double(amounts[i][1])), 0.0));
      held_room += room.back();
    }
    any = any || !share.empty();
    most = std::max(most, held_room);
    if (!share.empty() && amount <= held_room) break;
  }
  if (!any) {
    std::ostringstream os;
    os << "substance.drop: no water or ice within " << 3 * H << " m of the point (" << at.x() << ", "
       << at.y() << ", " << at.z() << ")";
    throw Error(os.str());
  }
  if (amount > most) {
    std::ostringstream os;
    os << "substance.drop: " << amount << " kg of " << scene_.substances[s].name << " is more than the water "
       << "and ice within " << 3 * H << " m of the point can hold (at most " << most
       << " kg: no particle holds more than its own mass of it)";
    throw Error(os.str());
  }
  std::vector<Float2> held(share.size());
  for (std::size_t k = 0; k < share.size(); ++k) held[k] = amounts[share[k].first];
  std::vector<double> give(share.size(), 0.0);
  // Shares by weight among the particles with room; those that fill drop out and the rest is shared again.
  double left = amount;
  for (std::size_t round = 0; round < share.size() && left > 0; ++round) {
    double weight = 0;
    for (std::size_t k = 0; k < share.size(); ++k)
      if (give[k] < room[k]) weight += share[k].second;
    if (!(weight > 0)) break;
    double given = 0;
    for (std::size_t k = 0; k < share.size(); ++k) {
      if (!(give[k] < room[k])) continue;
      const double d = std::min(left * share[k].second / weight, room[k] - give[k]);
      give[k] += d;
      given += d;
    }
    left -= given;
    if (left <= 1e-12 * amount) break;
  }
  double added = 0;
  for (std::size_t k = 0; k < share.size(); ++k) {
    const std::size_t i = share[k].first;
    Float2 v = held[k];
    const double before = double(v[0]) + double(v[1]);
    const double now = before + give[k];
    v[0] = static_cast<float>(now);
    v[1] = static_cast<float>(now - double(v[0]));
    added += (double(v[0]) + double(v[1])) - before;
    q.enqueueWriteBuffer(field, CL_TRUE, i * sizeof(Float2), sizeof(Float2), &v);
  }
  substance_books_.inflow[s] += added;
  return share.size();
}

std::vector<double> Solver::substance_totals() const {
  return substances_ ? substances_->totals() : std::vector<double>{};
}

std::vector<SubstanceStage::Parts> Solver::substance_parts() const {
  return substances_ ? substances_->parts() : std::vector<SubstanceStage::Parts>{};
}

std::vector<float> Solver::melt_shifts() const {
  return substances_ ? substances_->melt_shifts() : std::vector<float>{};
}

std::vector<std::uint32_t> Solver::cell_starts() const { return grid_->cell_starts(); }

std::vector<float> Solver::densities() const {
  std::vector<float> out(n_);
  if (n_) cl_.queue().enqueueReadBuffer(store_[f_.density], CL_TRUE, 0, n_ * 4, out.data());
  return out;
}

std::vector<Float4> Solver::pressure_state() const {
  std::vector<Float4> out(n_);
  if (n_ && fluid_) cl_.queue().enqueueReadBuffer(fluid_->state(), CL_TRUE, 0, n_ * 16, out.data());
  return out;
}

}  // namespace thaw
