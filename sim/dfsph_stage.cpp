#include "sim/dfsph_stage.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include "sim/cl_launch.h"
#include "sim/fluid_stage.h"
#include "sim/kernels/sph_kernel.h"
#include "sim/solver_constants.h"

namespace thaw {

namespace {
// FM, KR, AD, AV, ERR (sim/kernels/dfsph_columns.h), and VOL in multiphase builds only.
constexpr int kColumns = 5;
// The share of last step's kappa a warm start applies. All of it ratchets: the solves only add (they
// correct compression, never expansion), so a warm start that overshoots is never taken back, and the
// hydrostatic tank's kinetic energy grew tenfold every 10 ms until it blew up. Half, as SPlisHSPlasH's
// implementation does, decays what is no longer needed geometrically.
constexpr float kWarmShare = 0.5f;
}  // namespace

double dfsph_rest_ratio(const Scene& scene) {
  const auto w = scene.solver.kernel == KernelFunction::WendlandC2 ? sph::wendland_c2_w : sph::cubic_spline_w;
  // The support as the solver computes it (SolverConstants::support, a float).
  return sph::lattice_sum(w, scene.spacing, static_cast<float>(scene.solver.support_ratio * scene.spacing));
}

DfsphStage::DfsphStage(const StageContext& c, const cl::Buffer& flow, bool with_heat)
    : cl_(c.cl),
      store_(c.store),
      f_(c.core),
      layout_(c.layout),
      flow_(flow),
      ideal_gas_(rest_density_reads_temperature(c.scene, with_heat)) {
  // The accumulated (sum kappa dt^2, sum kappa dt) of the step's two solves: the next step's warm start,
  // saved so that a resumed run continues bitwise.
  kappa_ = c.store.add({"dfsph_kappa", FieldType::Float32, 2});
  std::ostringstream relaxation;
  relaxation.precision(9);
  relaxation << std::showpoint;  // 1 as "1.00000000f": OpenCL C has no "1f"
  relaxation << c.options << " -DTHAW_OMEGA=" << c.scene.solver.pressure_relaxation << "f";
  divergence_warm_start_ = c.scene.solver.divergence_warm_start;
  extrapolate_ = c.scene.solver.boundary_pressure == DfsphBoundary::Adami2012;
  if (extrapolate_) relaxation << " -DTHAW_DFSPH_EXTRAPOLATE";
  // The density solve's target: the density a resting lattice sums to (dfsph.cl, dfsph_error).
  relaxation << " -DTHAW_DFSPH_LATTICE=" << dfsph_rest_ratio(c.scene) << "f";
  if (ideal_gas_) relaxation << " -DTHAW_IDEAL_GAS";
  const auto program =
      c.cl.build(neighbour_program({"fluid_params.h", "dfsph_columns.h", "dfsph.cl"}), relaxation.str());
  k_columns_ = cl::Kernel(program, "dfsph_columns");
  // A closed domain's air cannot leave as it warms: the domain's pressure rises instead, so that eq 7's
  // density at that pressure, P / (R T), keeps the air's volume (the thermodynamic pressure of a closed
  // low-Mach flow, Paolucci 1982). Without it the warming air's rest volumes outgrew the box, which the
  // solve cannot relieve: warm-plate-air blew up after 2.1 s. Air that fills only part of the domain
  // (air.region) has room to expand into and stays at the room's pressure.
  const bool fills =
      c.scene.air.region.min == c.scene.domain.min && c.scene.air.region.max == c.scene.domain.max;
  closed_gas_ = ideal_gas_ && c.scene.open_faces == 0 && fills;
  lattice_volume_ = std::pow(c.scene.spacing, 3);
  if (closed_gas_) k_gas_volume_ = cl::Kernel(program, "dfsph_gas_volume");
  k_error_ = cl::Kernel(program, "dfsph_error");
  k_warm_ = cl::Kernel(program, "dfsph_warm");
  k_correct_ = cl::Kernel(program, "dfsph_correct");
  k_sum_ = cl::Kernel(program, "dfsph_error_sum");
  k_predict_ = cl::Kernel(program, "dfsph_predict");
  k_drift_ = cl::Kernel(program, "dfsph_drift");
  k_pressure_ = cl::Kernel(program, "dfsph_pressure");
  k_extrapolate_ = cl::Kernel(program, "dfsph_extrapolate");
  support_ = c.k.support;
  // The hydrostatic term of the walls' extrapolated pressure. Air feels no gravity but its buoyancy
  // (sim/scene.h, Buoyancy), a few per cent of g that is left out here: the walls of a scene of air alone
  // take the pressure of the air next to them.
  const bool air_alone =
      c.scene.has_air() && c.scene.fluids.empty() && c.scene.emitters.empty() && c.scene.ice.empty();
  const Eigen::Vector3d g = air_alone ? Eigen::Vector3d::Zero() : c.scene.gravity;
  gravity_ = {{static_cast<float>(g.x()), static_cast<float>(g.y()), static_cast<float>(g.z()), 0.0f}};
  // A full neighbourhood holds about (4/3) pi (H / dx)^3 particles; below 60 % of it a particle is at a
  // surface, where the divergence solve leaves it (20 of 33 at H = 2 dx, SPlisHSPlasH's threshold).
  min_neighbours_ =
      static_cast<cl_uint>(std::lround(0.6 * sph::full_neighbourhood(c.scene.spacing, c.k.support)));
  rest_density_ = c.k.rest_density;
  // Multiphase builds measure the errors as fractions of each particle's own rest density (dfsph.cl).
  error_scale_ = c.scene.multiphase() ? 1.0 : c.k.rest_density;
  density_tolerance_ = c.scene.solver.density_tolerance;
  divergence_tolerance_ = c.scene.solver.divergence_tolerance;
  max_iterations_ = c.scene.solver.max_pressure_iterations;
  const int columns = kColumns + (c.scene.multiphase() ? 2 : 0);  // VOL and RHO
  col_ = cl::Buffer(c.cl.context(), CL_MEM_READ_WRITE, std::size_t(c.layout.stride) * columns * 4);
  // Lanes read up to 15 floats past the last particle: keep the padding finite.
  c.cl.queue().enqueueFillBuffer(col_, 0.0f, 0, std::size_t(c.layout.stride) * columns * 4);
  sums_ = cl::Buffer(c.cl.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(c.layout.max_tiles, 1) * 8);
}

void DfsphStage::mark_fluid() {
  if (layout_.n == 0) return;
  if (closed_gas_) gas_volume_factor_ = closed_gas_volume_factor();
  set_args(k_columns_, store_[f_.position], store_[f_.phase], store_[f_.material], flow_, col_,
           layout_.stride, static_cast<cl_uint>(layout_.n));
  if (ideal_gas_) {
    k_columns_.setArg(7, store_[enthalpy_]);
    k_columns_.setArg(8, static_cast<float>(gas_volume_factor_));
  }
  launch(cl_.queue(), k_columns_, layout_.n);
}

std::pair<double, double> DfsphStage::tile_sums(cl::Kernel& k) {
  auto& q = cl_.queue();
  const cl_uint tiles = layout_.ntiles;
  launch(q, k, tiles);
  std::vector<cl_float2> s(tiles);
  q.enqueueReadBuffer(sums_, CL_TRUE, 0, tiles * 8, s.data());
  double sum = 0, count = 0;
  for (const auto& t : s) {
    sum += t.s[0];
    count += t.s[1];
  }
  return {sum, count};
}

double DfsphStage::closed_gas_volume_factor() {
  if (layout_.ntiles == 0) return 1.0;
  set_args(k_gas_volume_, store_[f_.position], store_[f_.material], flow_, store_[enthalpy_], sums_,
           static_cast<cl_uint>(layout_.n), layout_.tile);
  const auto [volume, count] = tile_sums(k_gas_volume_);
  // Each particle of air was laid on the lattice at its rest density (rest_density_at): one lattice
  // volume each, whatever has come and gone since.
  return volume > 0 ? count * lattice_volume_ / volume : 1.0;
}

double DfsphStage::mean_error(double rest_density) {
  if (layout_.ntiles == 0) return 0.0;
  set_args(k_sum_, col_, store_[f_.phase], sums_, layout_.stride, static_cast<cl_uint>(layout_.n),
           layout_.tile);
  const auto [sum, count] = tile_sums(k_sum_);
  return count > 0 ? sum / count / rest_density : 0.0;
}

PressureSolve DfsphStage::solve(const NeighbourView& nv, double dt, bool density_mode) {
  PressureSolve out;
  if (layout_.n == 0 || !(dt > 0)) return out;
  auto& q = cl_.queue();
  const auto n = static_cast<cl_uint>(layout_.n);
  const float fdt = static_cast<float>(dt);
  const cl_int mode = density_mode ? 1 : 0;
  // Warm start: apply a share of last step's accumulated kappa, which stays in the accumulator (the
  // density solve always; the divergence solve with solver.divergence_warm_start). A divergence solve
  // started from zero took the dam break's whole step 14 % less wall time: its two corrections bring the
  // error 20x below tolerance either way, and the warm start's sweep and the walls' extrapolation for it
  // were the cost; the front, the floating prism's draft and the hydrostatic tank stayed within their
  // gates (docs/BENCHMARKS.md). Unwarmed, the kernel only resets the accumulator.
  const bool warm = density_mode || divergence_warm_start_;
  set_args(k_warm_, store_[f_.density], store_[f_.phase], col_, store_[kappa_], fdt, mode,
           cl_float(warm ? kWarmShare : 0.0f), layout_.stride, n);
  launch(q, k_warm_, layout_.n);
  // The boundary's pressure (solver.boundary_pressure adami2012): from the warm-started fluid, with
  // gravity's share in the density solve; then after every sweep's error pass, from the fluid's increments
  // alone.
  auto extrapolate = [&](bool hydrostatic) {
    if (!extrapolate_) return;
    set_args(k_extrapolate_, store_[f_.position], nv.soa, store_[f_.density], store_[f_.phase], col_,
             nv.cell_start, nv.grid, support_, gravity_, cl_int(hydrostatic ? 1 : 0),
             static_cast<float>(rest_density_), layout_.stride, n);
    launch(q, k_extrapolate_, layout_.n);
  };
  set_args(k_correct_, store_[f_.velocity], nv.soa, store_[f_.phase], col_, store_[f_.position],
           store_[f_.density], store_[kappa_], nv.cell_start, nv.grid, support_, fdt, mode, layout_.stride,
           n);
  if (warm) {
    extrapolate(density_mode);
    launch(q, k_correct_, layout_.n);
  }
  set_args(k_error_, store_[f_.position], nv.soa, store_[f_.density], store_[f_.phase], store_[f_.material],
           flow_, col_, nv.cell_start, nv.grid, support_, fdt, mode, layout_.stride, n);
  // The density error is (rho* - rho0), the divergence error D rho / Dt; both as fractions of rho0, the
  // second over one step.
  const double scale = density_mode ? 1.0 : dt;
  const double tolerance = density_mode ? density_tolerance_ : divergence_tolerance_;
  for (;;) {
    launch(q, k_error_, layout_.n);
    extrapolate(false);
    out.error = mean_error(error_scale_) * scale;
    // At least two corrections each (Bender & Koschier 2017, Algorithms 2 and 3), then until the
    // tolerance. One for the divergence saved 12 % of the step in the dam break but slowed its front (dZ/dT*
    // 1.100 against the data's 1.156) past the position gate at T* = 1.219 (6.1 %).
    if (out.iterations >= 2 && out.error <= tolerance) break;
    if (out.iterations >= max_iterations_) {
      out.converged = false;
      break;
    }
    launch(q, k_correct_, layout_.n);
    ++out.iterations;
    // Bender & Koschier's loop stops on the error it measured before its last correction (2017, Algorithms
    // 2 and 3): when the two corrections it always makes follow a measurement already within tolerance,
    // no sweep is spent measuring again. Measured in the dam break: the same steps and state, one error
    // sweep a step fewer in the divergence solve (docs/BENCHMARKS.md).
    if (out.iterations >= 2 && out.error <= tolerance) break;
  }
  return out;
}

PressureSolve DfsphStage::divergence_solve(const NeighbourView& nv, double dt) {
  last_divergence_ = solve(nv, dt, false);
  totals_.divergence_iterations += std::uint64_t(last_divergence_.iterations);
  if (!last_divergence_.converged) ++totals_.divergence_unconverged;
  return last_divergence_;
}

void DfsphStage::predict(const cl::Buffer& accel, const NeighbourView& nv, double dt, double damping_factor) {
  if (layout_.n == 0) return;
  set_args(k_predict_, store_[f_.velocity], nv.soa, accel, store_[f_.phase], static_cast<float>(dt),
           static_cast<float>(damping_factor), layout_.stride, static_cast<cl_uint>(layout_.n));
  launch(cl_.queue(), k_predict_, layout_.n);
}

PressureSolve DfsphStage::density_solve(const NeighbourView& nv, double dt) {
  last_density_ = solve(nv, dt, true);
  ++totals_.steps;
  totals_.density_iterations += std::uint64_t(last_density_.iterations);
  if (!last_density_.converged) {
    ++totals_.density_unconverged;
    totals_.worst_density_error = std::max(totals_.worst_density_error, last_density_.error);
  }
  return last_density_;
}

void DfsphStage::write_pressure(const cl::Buffer& state, double dt) {
  if (layout_.n == 0) return;
  set_args(k_pressure_, store_[f_.density], store_[f_.phase], store_[kappa_], state, static_cast<float>(dt),
           static_cast<cl_uint>(layout_.n));
  launch(cl_.queue(), k_pressure_, layout_.n);
}

void DfsphStage::drift(double dt) {
  if (layout_.n == 0) return;
  set_args(k_drift_, store_[f_.position], store_[f_.velocity], store_[f_.phase], static_cast<float>(dt),
           static_cast<cl_uint>(layout_.n));
  launch(cl_.queue(), k_drift_, layout_.n);
}

}  // namespace thaw
