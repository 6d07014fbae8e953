#include "sim/solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "sim/error.h"

namespace thaw {
namespace {

static_assert(static_cast<int>(Phase::Solid) == 2, "THAW_PHASE_SOLID in sim/kernels/grid_common.h");

// Must match `Grid` in sim/kernels/grid_common.h.
struct ClGrid {
  cl_float4 origin;
  cl_float inv_cell;
  cl_int nx, ny, nz;
};

// Cells of H / kGridReach. A finer grid visits fewer candidates per neighbour but walks more, shorter
// rows; with the neighbour loops on SIMD lanes, cells of H (9 rows of about 24 candidates) were the
// fastest of H, H/2 and H/3 (`thaw bench throughput`: see docs/BENCHMARKS.md).
constexpr int kGridReach = 1;

// SIMD lanes of the neighbour loops (sim/kernels/grid_common.h): candidates read at a time. 8 (AVX2
// width) beat 4 and 16 on the AVX-512 machine of docs/BENCHMARKS.md.
constexpr int kLanes = 8;

// Work-group size of the one-work-item-per-particle kernels. Left to itself pocl picks a divisor of
// the global size (15 for 135645 particles), which made the simple kernels a third slower.
constexpr std::size_t kGroup = 64;

const std::vector<std::string> kPrelude = {"sph_kernel.h", "grid_common.h"};

std::vector<std::string> with_prelude(std::initializer_list<std::string> files) {
  std::vector<std::string> all = kPrelude;
  all.insert(all.end(), files);
  return all;
}

// Sets a kernel's arguments in order: buffers, scalars and argument structs alike.
template <class... Args>
void set_args(cl::Kernel& k, const Args&... args) {
  cl_uint i = 0;
  (k.setArg(i++, args), ...);
}

cl::NDRange global_for(std::size_t n) { return cl::NDRange(std::max<std::size_t>(n, 1)); }

// One work-item per particle (n of them), in groups of kGroup; the kernels ignore ids >= n.
void launch(cl::CommandQueue& q, cl::Kernel& k, std::size_t n) {
  const std::size_t global = (std::max<std::size_t>(n, 1) + kGroup - 1) / kGroup * kGroup;
  q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(kGroup));
}

ClGrid cl_grid(const Solver::GridInfo& gi) {
  return {{{gi.origin.x(), gi.origin.y(), gi.origin.z(), 0.f}}, 1.0f / gi.cell, gi.nx, gi.ny, gi.nz};
}

}  // namespace

SolverConstants derive_constants(const Scene& scene) {
  const auto& s = scene.solver;
  SolverConstants k;
  k.support = static_cast<float>(s.support_ratio * scene.spacing);
  k.smoothing = 0.5f * k.support;

  int fluid_material = -1;
  for (std::size_t b = 0; b < scene.fluids.size(); ++b) {
    const int m = scene.fluids[b].material;
    if (fluid_material >= 0 && scene.materials[m].density != scene.materials[fluid_material].density)
      throw SceneError("fluids[" + std::to_string(b) + "].material",
                       "every fluid block must have the same rest density in this solver ('" +
                           scene.materials[m].name + "' differs from '" +
                           scene.materials[fluid_material].name + "')");
    if (fluid_material < 0) fluid_material = m;
  }
  const Material* fluid = fluid_material >= 0 ? &scene.materials[fluid_material] : nullptr;
  k.rest_density = static_cast<float>(fluid ? fluid->density : 1000.0);
  k.kinematic_viscosity = static_cast<float>(fluid ? fluid->viscosity / fluid->density : 0.0);

  // Reference speed: free fall from the highest fluid to the bottom of the domain, or the fastest
  // initial velocity, whichever is larger.
  double v_ref = s.reference_speed;
  if (v_ref <= 0) {
    const double g = scene.gravity.norm();
    if (g > 0) {
      const Eigen::Vector3d up = -scene.gravity / g;
      double top = -std::numeric_limits<double>::infinity();
      for (const auto& f : scene.fluids) top = std::max(top, f.box.max_along(up));
      const double bottom = -scene.domain.max_along(-up);
      if (!scene.fluids.empty()) v_ref = std::sqrt(2.0 * g * std::max(0.0, top - bottom));
    }
    for (const auto& f : scene.fluids) v_ref = std::max(v_ref, f.velocity.norm());
    v_ref = std::max(v_ref, 0.1);  // a still fluid in zero gravity still needs a finite stiffness
  }
  k.sound_speed = static_cast<float>(s.speed_of_sound > 0 ? s.speed_of_sound : s.sound_speed_factor * v_ref);
  const double c2 = double(k.sound_speed) * k.sound_speed;
  k.stiffness = static_cast<float>(s.eos == "tait" ? k.rest_density * c2 / s.gamma : k.rest_density * c2);
  k.max_speed = static_cast<float>(s.max_speed > 0 ? s.max_speed : 5.0 * k.sound_speed);
  const float h = k.smoothing;
  k.visc_fluid =
      static_cast<float>(s.artificial_viscosity * k.sound_speed * h + 10.0 * k.kinematic_viscosity);
  k.visc_boundary = static_cast<float>(s.boundary_viscosity * k.sound_speed * h);
  return k;
}

Solver::Solver(ClRuntime& cl, const Scene& scene, const SimState& st)
    : cl_(cl), scene_(scene), k_(derive_constants(scene)) {
  const HostParticles& p = st.particles;
  n_ = p.size();
  time_ = st.time;
  dt_ = st.dt;
  steps_ = st.step;
  clamped_base_ = st.clamped;

  // Grid bounds: the domain and every particle (walls lie outside the domain), plus one cell.
  Eigen::Vector3f lo = scene.domain.min.cast<float>(), hi = scene.domain.max.cast<float>();
  for (const auto& x : p.position) {
    lo = lo.cwiseMin(Eigen::Vector3f(x[0], x[1], x[2]));
    hi = hi.cwiseMax(Eigen::Vector3f(x[0], x[1], x[2]));
  }
  // A few ulps above H / reach, so float rounding in grid_cell() never puts a neighbour just inside
  // the support more than `reach` cells away.
  grid_.cell = k_.support / float(kGridReach) * (1.0f + 8.0f * std::numeric_limits<float>::epsilon());
  grid_.reach = kGridReach;
  grid_.origin = lo - Eigen::Vector3f::Constant(grid_.cell);
  const Eigen::Vector3f ext = hi + Eigen::Vector3f::Constant(grid_.cell) - grid_.origin;
  grid_.nx = static_cast<int>(std::ceil(ext.x() / grid_.cell)) + 1;
  grid_.ny = static_cast<int>(std::ceil(ext.y() / grid_.cell)) + 1;
  grid_.nz = static_cast<int>(std::ceil(ext.z() / grid_.cell)) + 1;
  const double cells = double(grid_.nx) * grid_.ny * grid_.nz;
  if (cells > double(1u << 28))
    throw SceneError("spacing", "the neighbour grid would need " + std::to_string(cells) +
                                    " cells; use a smaller domain or a larger spacing");
  ncells_ = static_cast<std::uint32_t>(cells);
  int bits = 1;
  while (bits < 32 && (ncells_ - 1) >> bits) ++bits;
  // The fewest radix passes of at most 11 bits, the key's bits spread evenly over them (17 bits: two
  // passes of 9 rather than three of 8).
  sort_passes_ = static_cast<std::uint32_t>((bits + 10) / 11);
  radix_bits_ = static_cast<std::uint32_t>((bits + int(sort_passes_) - 1) / int(sort_passes_));
  // About 32 tiles (whole multiples of 256 particles): enough work-items to keep the cores busy, few
  // enough that each tile's per-digit bookkeeping is small beside its particles.
  tile_ = static_cast<std::uint32_t>(std::max<std::size_t>(256, (n_ / 32 + 255) / 256 * 256));
  ntiles_ = static_cast<std::uint32_t>((n_ + tile_ - 1) / tile_);
  // Lane loads (SIMD lanes, sim/kernels/grid_common.h) read up to 15 floats past the last particle.
  stride_ = static_cast<std::uint32_t>((n_ + 16 + 15) / 16 * 16);

  // Only the kernel and EOS this scene uses are compiled in.
  std::ostringstream opts;
  const bool wendland = scene.solver.kernel == "wendland_c2";
  opts << "-DKERNEL_W=" << (wendland ? "wendland_c2_w" : "cubic_spline_w")
       << " -DKERNEL_GRAD=" << (wendland ? "wendland_c2_grad_factor" : "cubic_spline_grad_factor");
  if (scene.solver.eos == "tait") opts << " -DTHAW_EOS_TAIT";
  if (scene.solver.eos == "tait" && scene.solver.gamma == 7.0) opts << " -DTHAW_GAMMA_7";
  if (wendland) opts << " -DTHAW_WENDLAND";
  // Flush subnormal floats: viscosity spreads velocities of 1e-30 m/s and less through a resting
  // lattice, and arithmetic on subnormals made the forces pass 2-4x slower for tens of steps after a
  // start (measured: docs/BENCHMARKS.md). Nothing physical lives below 1e-38.
  opts << " -cl-denorms-are-zero";
  opts << " -DTHAW_REACH=" << kGridReach << " -DTHAW_VW=" << kLanes;
  const auto grid =
      cl.build(with_prelude({"grid.cl"}), opts.str() + " -DTHAW_RADIX_BITS=" + std::to_string(radix_bits_));
  const auto boundary = cl.build(with_prelude({"boundary.cl"}), opts.str());
  const auto density = cl.build(with_prelude({"density.cl"}), opts.str());
  const auto forces = cl.build(with_prelude({"forces.cl"}), opts.str());
  const auto integrate = cl.build(with_prelude({"integrate.cl", "step_limits.cl"}), opts.str());
  k_cell_keys_ = cl::Kernel(grid, "cell_keys");
  k_hist_ = cl::Kernel(grid, "radix_histogram");
  k_scan_ = cl::Kernel(grid, "radix_scan_rows");
  k_scatter_ = cl::Kernel(grid, "radix_scatter");
  k_starts_ = cl::Kernel(grid, "cell_starts");
  k_reorder_ = cl::Kernel(grid, "reorder");
  k_psi_ = cl::Kernel(boundary, "boundary_psi");
  k_set_mass_ = cl::Kernel(boundary, "set_mass");
  k_density_ = cl::Kernel(density, "density");
  k_forces_ = cl::Kernel(forces, "forces");
  k_limits_ = cl::Kernel(integrate, "step_limits");
  k_integrate_ = cl::Kernel(integrate, "integrate");

  auto& ctx = cl.context();
  const std::size_t n = std::max<std::size_t>(n_, 1);
  auto buf = [&](std::size_t bytes) {
    return cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, 4));
  };
  position_ = buf(n * 16);
  velocity_ = buf(n * 16);
  density_ = buf(n * 4);
  phase_ = buf(n);
  material_ = buf(n);
  id_ = buf(n * 4);
  state_ = buf(n * 16);
  accel_ = buf(n * 16);
  for (int i = 0; i < 2; ++i) {
    keys_[i] = buf(n * 4);
    order_[i] = buf(n * 4);
  }
  hist_ = buf((std::size_t(1) << radix_bits_) * std::max<std::uint32_t>(ntiles_, 1) * 4);
  totals_ = buf((std::size_t(1) << radix_bits_) * 4);
  spare_pos_ = buf(n * 16);
  spare_vel_ = buf(n * 16);
  spare1f_ = buf(n * 4);
  spare_phase_ = buf(n);
  spare_mat_ = buf(n);
  spare_id_ = buf(n * 4);
  soa_ = buf(std::size_t(stride_) * 7 * 4);
  derived_ = buf(std::size_t(stride_) * 2 * 4);
  // The padding past the last particle is read by masked lanes only; keep it finite anyway.
  cl.queue().enqueueFillBuffer(soa_, 0.0f, 0, std::size_t(stride_) * 7 * 4);
  cl.queue().enqueueFillBuffer(derived_, 0.0f, 0, std::size_t(stride_) * 2 * 4);
  cell_start_ = buf((std::size_t(ncells_) + 1) * 4);
  clamped_ = buf(4);
  limits_f_ = buf(std::size_t(std::max<std::uint32_t>(ntiles_, 1)) * 8);
  limits_i_ = buf(std::size_t(std::max<std::uint32_t>(ntiles_, 1)) * 8);

  // Boundary particles sampled by sample_scene() carry no mass yet: their Psi = rho0 V_b comes from
  // the solver's rest density. Walls here sit on the fluid lattice and fill the kernel support, so the
  // lattice cell dx^3 is their exact volume; Akinci's 1 / sum_k W_bk suits single-layer or irregular
  // samplings but overestimates the fluid-facing layer of a lattice wall (by 18 % at H = 2 dx, which
  // raised the wall-adjacent density by 2.6 %: measured with configs/hydrostatic-tank.json).
  HostParticles init = p;
  bool psi_unknown = false;
  const float lattice_psi = static_cast<float>(k_.rest_density * std::pow(scene.spacing, 3));
  for (std::size_t i = 0; i < n_; ++i)
    if (init.phase[i] == static_cast<std::uint8_t>(Phase::Solid) && init.position[i][3] == 0.0f) {
      psi_unknown = true;
      init.position[i][3] = lattice_psi;
    }
  upload(init);
  if (psi_unknown && scene.solver.boundary_volume == "akinci") compute_boundary_psi();
}

void Solver::upload(const HostParticles& p) {
  auto& q = cl_.queue();
  if (n_ == 0) return;
  q.enqueueWriteBuffer(position_, CL_TRUE, 0, n_ * 16, p.position.data());
  q.enqueueWriteBuffer(velocity_, CL_TRUE, 0, n_ * 16, p.velocity.data());
  q.enqueueWriteBuffer(density_, CL_TRUE, 0, n_ * 4, p.density.data());
  q.enqueueWriteBuffer(phase_, CL_TRUE, 0, n_, p.phase.data());
  q.enqueueWriteBuffer(material_, CL_TRUE, 0, n_, p.material.data());
  q.enqueueWriteBuffer(id_, CL_TRUE, 0, n_ * 4, p.id.data());
  const cl_uint zero = 0;
  q.enqueueWriteBuffer(clamped_, CL_TRUE, 0, 4, &zero);
}

template <class F>
void Solver::timed(Stage s, F&& f) {
  const auto t0 = Clock::now();
  f();
  cl_.queue().finish();
  timers_.add(s, seconds_since(t0));
}

void Solver::build_grid() {
  if (n_ == 0) return;
  auto& q = cl_.queue();
  const auto n = static_cast<cl_uint>(n_);
  const ClGrid g = cl_grid(grid_);
  const auto& d = scene_.domain;
  const cl_float4 dmin{{float(d.min.x()), float(d.min.y()), float(d.min.z()), 0.f}};
  const cl_float4 dmax{{float(d.max.x()), float(d.max.y()), float(d.max.z()), 0.f}};
  set_args(k_cell_keys_, position_, velocity_, phase_, keys_[0], order_[0], clamped_, g, dmin, dmax, n);
  launch(q, k_cell_keys_, n_);

  for (std::uint32_t pass = 0; pass < sort_passes_; ++pass) {
    const int src = pass % 2, dst = 1 - src;
    const cl_uint shift = radix_bits_ * pass;
    set_args(k_hist_, keys_[src], hist_, shift, n, tile_, ntiles_);
    q.enqueueNDRangeKernel(k_hist_, cl::NullRange, global_for(ntiles_));
    set_args(k_scan_, hist_, totals_, ntiles_);
    q.enqueueNDRangeKernel(k_scan_, cl::NullRange, cl::NDRange(std::size_t(1) << radix_bits_));
    set_args(k_scatter_, keys_[src], order_[src], keys_[dst], order_[dst], hist_, totals_, shift, n, tile_,
             ntiles_);
    q.enqueueNDRangeKernel(k_scatter_, cl::NullRange, global_for(ntiles_));
  }
  const cl::Buffer& keys = keys_[sort_passes_ % 2];
  const cl::Buffer& order = order_[sort_passes_ % 2];

  // Every per-particle state buffer follows the sort (a new buffer must be added here and to the
  // reorder kernel), in one pass.
  set_args(k_reorder_, order, n, position_, spare_pos_, velocity_, spare_vel_, density_, spare1f_, phase_,
           spare_phase_, material_, spare_mat_, id_, spare_id_, soa_, stride_);
  launch(q, k_reorder_, n_);
  std::swap(position_, spare_pos_);
  std::swap(velocity_, spare_vel_);
  std::swap(density_, spare1f_);
  std::swap(phase_, spare_phase_);
  std::swap(material_, spare_mat_);
  std::swap(id_, spare_id_);

  set_args(k_starts_, keys, cell_start_, n, ncells_);
  launch(q, k_starts_, n_ + 1);
}

void Solver::compute_boundary_psi() {
  build_grid();
  auto& q = cl_.queue();
  const auto n = static_cast<cl_uint>(n_);
  const ClGrid g = cl_grid(grid_);
  set_args(k_psi_, position_, phase_, cell_start_, g, k_.support, k_.rest_density, spare1f_, n);
  launch(q, k_psi_, n_);
  set_args(k_set_mass_, position_, spare1f_, n);
  launch(q, k_set_mass_, n_);
  q.finish();
}

void Solver::compute_density() {
  if (n_ == 0) return;
  const ClGrid g = cl_grid(grid_);
  const auto& s = scene_.solver;
  set_args(k_density_, position_, soa_, stride_, phase_, cell_start_, g, k_.support, k_.rest_density,
           k_.stiffness, static_cast<float>(s.gamma), k_.visc_fluid, k_.visc_boundary, density_, state_,
           derived_, static_cast<cl_uint>(n_));
  launch(cl_.queue(), k_density_, n_);
}

void Solver::compute_forces() {
  if (n_ == 0) return;
  const ClGrid g = cl_grid(grid_);
  const float h = k_.smoothing;
  const cl_float4 gravity{
      {float(scene_.gravity.x()), float(scene_.gravity.y()), float(scene_.gravity.z()), 0.f}};
  set_args(k_forces_, position_, velocity_, soa_, derived_, stride_, state_, phase_, cell_start_, g,
           k_.support, gravity, 0.01f * h * h, accel_, static_cast<cl_uint>(n_));
  launch(cl_.queue(), k_forces_, n_);
}

double Solver::choose_time_step() {
  const auto& s = scene_.solver;
  double vmax2 = 0, amax2 = 0;
  std::uint32_t fastest = 0, bad = 0xffffffffu;
  if (n_ > 0) {
    set_args(k_limits_, position_, velocity_, accel_, phase_, limits_f_, limits_i_, static_cast<cl_uint>(n_),
             tile_);
    cl_.queue().enqueueNDRangeKernel(k_limits_, cl::NullRange, global_for(ntiles_));
    std::vector<cl_float2> f(ntiles_);
    std::vector<cl_uint2> ix(ntiles_);
    cl_.queue().enqueueReadBuffer(limits_f_, CL_FALSE, 0, ntiles_ * 8, f.data());
    cl_.queue().enqueueReadBuffer(limits_i_, CL_TRUE, 0, ntiles_ * 8, ix.data());
    for (std::uint32_t t = 0; t < ntiles_; ++t) {
      if (f[t].s[0] > vmax2) {
        vmax2 = f[t].s[0];
        fastest = ix[t].s[0];
      }
      amax2 = std::max(amax2, double(f[t].s[1]));
      bad = std::min(bad, ix[t].s[1]);
    }
  }
  auto particle_at = [&](std::uint32_t i) {
    Float4 x, v;
    std::uint32_t id = 0;
    cl_.queue().enqueueReadBuffer(position_, CL_TRUE, i * 16, 16, x.data());
    cl_.queue().enqueueReadBuffer(velocity_, CL_TRUE, i * 16, 16, v.data());
    cl_.queue().enqueueReadBuffer(id_, CL_TRUE, i * 4, 4, &id);
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
  const char* advice = "; lower solver.max_dt or solver.cfl, or raise solver.sound_speed_factor";
  if (bad != 0xffffffffu) {
    const bool accel_only = (bad & 0x80000000u) != 0;
    throw BlowUpError(
        where() + particle_at(bad & 0x7fffffffu) +
        (accel_only ? " has a non-finite acceleration" : " has a non-finite position or velocity") + advice);
  }
  const double vmax = std::sqrt(vmax2);
  if (vmax > k_.max_speed) {
    std::ostringstream os;
    os << where() << particle_at(fastest) << " moves at " << vmax << " m/s, above the limit " << k_.max_speed
       << " m/s (solver.max_speed)" << advice;
    throw BlowUpError(os.str());
  }
  const double h = k_.smoothing;
  double dt = s.max_dt;
  dt = std::min(dt, s.cfl * h / (k_.sound_speed + vmax));  // CFL (acoustic + advective)
  if (amax2 > 0) dt = std::min(dt, s.force_number * std::sqrt(h / std::sqrt(amax2)));
  if (k_.kinematic_viscosity > 0) dt = std::min(dt, s.viscous_number * h * h / k_.kinematic_viscosity);
  dt = static_cast<float>(dt);  // the kernels see a float: keep host time consistent with them
  if (dt < s.min_dt) {
    std::ostringstream os;
    os << where() << "the adaptive time step fell to " << dt << " s, below solver.min_dt = " << s.min_dt
       << " s (max acceleration " << std::sqrt(amax2) << " m/s^2, max speed " << vmax << " m/s)" << advice;
    throw BlowUpError(os.str());
  }
  return dt;
}

void Solver::integrate(double dt) {
  if (n_ == 0) return;
  set_args(k_integrate_, position_, velocity_, accel_, phase_, static_cast<float>(dt),
           static_cast<float>(1.0 / (1.0 + damping_ * dt)), static_cast<cl_uint>(n_));
  launch(cl_.queue(), k_integrate_, n_);
}

void Solver::step() {
  timed(Stage::Grid, [&] { build_grid(); });
  timed(Stage::Density, [&] { compute_density(); });
  timed(Stage::Forces, [&] { compute_forces(); });
  double dt = 0;
  timed(Stage::TimeStep, [&] { dt = choose_time_step(); });
  timed(Stage::Integrate, [&] { integrate(dt); });
  time_ += dt;
  dt_ = dt;
  ++steps_;
}

void Solver::warm_up() {
  // A sort of sorted keys is the identity and dt = 0 leaves x and v unchanged, so this changes no state.
  build_grid();
  compute_density();
  compute_forces();
  choose_time_step();
  integrate(0.0);
  cl_.queue().finish();
}

std::uint64_t Solver::clamped() const {
  cl_uint c = 0;
  cl_.queue().enqueueReadBuffer(clamped_, CL_TRUE, 0, 4, &c);
  return clamped_base_ + c;
}

HostParticles Solver::particles() const {
  HostParticles p;
  p.resize(n_);
  if (n_ == 0) return p;
  auto& q = cl_.queue();
  q.enqueueReadBuffer(position_, CL_FALSE, 0, n_ * 16, p.position.data());
  q.enqueueReadBuffer(velocity_, CL_FALSE, 0, n_ * 16, p.velocity.data());
  q.enqueueReadBuffer(density_, CL_FALSE, 0, n_ * 4, p.density.data());
  q.enqueueReadBuffer(phase_, CL_FALSE, 0, n_, p.phase.data());
  q.enqueueReadBuffer(material_, CL_FALSE, 0, n_, p.material.data());
  q.enqueueReadBuffer(id_, CL_TRUE, 0, n_ * 4, p.id.data());
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
  return s;
}

std::vector<std::uint32_t> Solver::cell_starts() const {
  std::vector<std::uint32_t> out(std::size_t(ncells_) + 1);
  cl_.queue().enqueueReadBuffer(cell_start_, CL_TRUE, 0, out.size() * 4, out.data());
  return out;
}

std::vector<float> Solver::densities() const {
  std::vector<float> out(n_);
  if (n_) cl_.queue().enqueueReadBuffer(density_, CL_TRUE, 0, n_ * 4, out.data());
  return out;
}

std::vector<Float4> Solver::pressure_state() const {
  std::vector<Float4> out(n_);
  if (n_) cl_.queue().enqueueReadBuffer(state_, CL_TRUE, 0, n_ * 16, out.data());
  return out;
}

}  // namespace thaw
