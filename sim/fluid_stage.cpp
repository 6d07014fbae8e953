#include "sim/fluid_stage.h"

#include <algorithm>

#include "sim/cl_launch.h"
#include "sim/error.h"
#include "sim/solver_constants.h"

namespace thaw {

fluid::MaterialFlow flow_row(const SolverSettings& s, float rest_density, float kinematic_viscosity,
                             float sound_speed, float smoothing) {
  const double rho0 = rest_density, c = sound_speed, c2 = c * c;
  fluid::MaterialFlow f{};
  f.rest_density = rest_density;
  f.stiffness = static_cast<float>(s.eos == Eos::Tait ? rho0 * c2 / s.gamma : rho0 * c2);
  // Monaghan 2005 eq. 4.8: 2 (d + 2) nu = 10 nu in 3-D, plus the artificial part alpha c h.
  f.viscosity =
      static_cast<float>(s.artificial_viscosity * c * double(smoothing) + 10.0 * double(kinematic_viscosity));
  f.sound_speed = sound_speed;
  f.gravity = 1.0f;
  f.push = 1.0f;
  return f;
}

std::vector<fluid::MaterialFlow> material_flow_table(const Scene& scene, const SolverConstants& k,
                                                     bool with_heat) {
  check_multiphase(scene);  // a scene built in code has not been through the loader's check
  std::vector<fluid::MaterialFlow> table;
  for (const Material& m : scene.materials) {
    // A boundary material carries rho0 V of the fluid it bounds: the fluid's row (Akinci 2012).
    const bool fluid = flows(m.kind);
    table.push_back(
        fluid ? flow_row(scene.solver, static_cast<float>(m.density),
                         static_cast<float>(m.viscosity / m.density), k.sound_speed, k.smoothing)
              : flow_row(scene.solver, k.rest_density, k.kinematic_viscosity, k.sound_speed, k.smoothing));
    if (m.kind == MaterialKind::Air) {
      const AirFill& air = scene.air;
      fluid::MaterialFlow& f = table.back();
      f.gravity = 0.0f;
      // Air is never a lone drop: its pressure holds it off the walls, and the push's dashpot, acting on
      // neighbours at an angle, was a drag along the wall: the cavity's mid-line speeds at Ra 1e3 (res 20)
      // 10 % below de Vahl Davis's with it, within 2 % without. An air dryer's jet is another matter: at
      // 2 m/s against the far wall of a closed box (0.5 % density tolerance) 12 particles a step got
      // past the walls' pressure to the domain's face (clamped, 9,238 in 768 steps); with the push, none.
      f.push = scene.air_dryer_count() > 0 ? 1.0f : 0.0f;
      f.artificial_buoyancy = static_cast<float>(air.artificial_buoyancy);
      f.max_temperature = static_cast<float>(air.max_temperature);
      f.inv_specific_heat = static_cast<float>(1.0 / m.specific_heat);
      if (air.buoyancy == Buoyancy::IdealGas) {
        // Eq 7's rest density follows the temperature in the pressure solve (dfsph_columns); without heat
        // every air particle keeps its starting one.
        if (with_heat)
          f.theta = static_cast<float>(air.theta);
        else
          f.rest_density = static_cast<float>(ideal_gas_rest_density(m.density, air, air.temperature));
      }
      if (air.buoyancy != Buoyancy::None) {
        // The weight: g - grad p / rho0(T). The air's hydrostatic pressure at its reference density rho_r
        // (the material's, at T0) is left out of p, as Boussinesq's rho0 g is (sim/scene.h): what stays is
        // g (1 - rho_r / rho0(T)), and with eq 7 that is exactly -theta (T - T0) / (1 + theta T0) g, a
        // Boussinesq force of expansion theta / (1 + theta T0) (1 / (T0 + 273.15 K) for the ideal gas).
        // Kept in p, the air's weight made a pressure about 30 times the buoyancy's, whose symmetric pair
        // terms held the cavity's circulation at half de Vahl Davis's speed (u_max 1.76 alpha/L
        // against 3.65).
        f.expansion = static_cast<float>(air.buoyancy == Buoyancy::IdealGas
                                             ? air.theta / (1.0 + air.theta * air.reference_temperature)
                                             : air.expansion);
        f.reference_temperature = static_cast<float>(air.reference_temperature);
        // Without heat every air particle stays at its starting temperature: its buoyancy is a constant.
        if (!with_heat)
          f.gravity =
              static_cast<float>(-double(f.expansion) * (air.temperature - air.reference_temperature));
      }
      // Eq 8 at the starting temperature, as a share of gravity (against it), likewise.
      if (!with_heat && air.artificial_buoyancy > 0 && scene.gravity.norm() > 0)
        f.gravity -=
            static_cast<float>(air.artificial_buoyancy /
                               std::max(air.max_temperature - air.temperature, 1.0) / scene.gravity.norm());
    }
  }
  return table;
}

bool rest_density_reads_temperature(const Scene& scene, bool with_heat) {
  return with_heat && scene.solver.flow && scene.solver.pressure == PressureSolver::Dfsph &&
         scene.has_air() && scene.air.buoyancy == Buoyancy::IdealGas;
}

bool buoyancy_reads_temperature(const Scene& scene, bool with_heat) {
  return with_heat && scene.has_air() &&
         ((scene.air.buoyancy == Buoyancy::Boussinesq && scene.air.expansion > 0) ||
          scene.air.buoyancy == Buoyancy::IdealGas || scene.air.artificial_buoyancy > 0);
}

FluidStage::FluidStage(const StageContext& c, bool with_heat)
    : cl_(c.cl),
      store_(c.store),
      f_(c.core),
      layout_(c.layout),
      buoyancy_(buoyancy_reads_temperature(c.scene, with_heat)) {
  no_slip_ = c.scene.solver.no_slip == NoSlip::Adami2012;
  const std::string slip = no_slip_ ? " -DTHAW_NO_SLIP" : "";
  k_density_ = cl::Kernel(
      c.cl.build(neighbour_program({"fluid_params.h", "dfsph_columns.h", "density.cl"}), c.options + slip),
      "density");
  k_forces_ = cl::Kernel(c.cl.build(neighbour_program({"fluid_params.h", "forces.cl"}),
                                    c.options + slip + (buoyancy_ ? " -DTHAW_BUOYANCY" : "")),
                         "forces");
  const auto integrate =
      c.cl.build(neighbour_program({"fluid_params.h", "integrate.cl", "step_limits.cl"}), c.options);
  k_limits_ = cl::Kernel(integrate, "step_limits");
  k_integrate_ = cl::Kernel(integrate, "integrate");

  const std::vector<fluid::MaterialFlow> table = material_flow_table(c.scene, c.k, with_heat);
  auto& ctx = c.cl.context();
  flow_ = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, table.size() * sizeof(fluid::MaterialFlow),
                     const_cast<fluid::MaterialFlow*>(table.data()));
  const std::size_t n = std::max<std::size_t>(c.layout.capacity, 1);
  const std::size_t tiles = std::max<cl_uint>(c.layout.max_tiles, 1);
  auto buf = [&](std::size_t bytes) {
    return cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, 4));
  };
  state_ = buf(n * 16);
  accel_ = buf(n * 16);
  derived_ = buf(std::size_t(c.layout.stride) * 3 * 4);
  // The padding past the last particle is read by masked lanes only; keep it finite anyway.
  c.cl.queue().enqueueFillBuffer(derived_, 0.0f, 0, std::size_t(c.layout.stride) * 3 * 4);
  if (no_slip_) {
    ghost_ = buf(std::size_t(c.layout.stride) * 3 * 4);
    c.cl.queue().enqueueFillBuffer(ghost_, 0.0f, 0, std::size_t(c.layout.stride) * 3 * 4);
  }
  limits_f_ = buf(tiles * 8);
  limits_i_ = buf(tiles * 8);

  density_params_.support = c.k.support;
  density_params_.gamma = static_cast<float>(c.scene.solver.gamma);
  density_params_.visc_boundary = c.k.visc_boundary;
  density_params_.stride = c.layout.stride;
  density_params_.n = static_cast<cl_uint>(c.layout.n);
  forces_params_.support = c.k.support;
  forces_params_.eps2 = 0.01f * c.k.smoothing * c.k.smoothing;
  forces_params_.gravity_x = float(c.scene.gravity.x());
  forces_params_.gravity_y = float(c.scene.gravity.y());
  forces_params_.gravity_z = float(c.scene.gravity.z());
  forces_params_.rep_k = c.k.repulsion;
  forces_params_.rep_r0 = c.k.repulsion_range;
  forces_params_.rep_d = c.k.repulsion_damping;
  forces_params_.stride = c.layout.stride;
  forces_params_.n = static_cast<cl_uint>(c.layout.n);
}

void FluidStage::density(const NeighbourView& nv) {
  if (layout_.n == 0) return;
  density_params_.n = static_cast<cl_uint>(layout_.n);
  set_args(k_density_, store_[f_.position], nv.soa, store_[f_.phase], store_[f_.material], flow_,
           nv.cell_start, nv.grid, density_params_, store_[f_.density], state_, derived_);
  cl_uint arg = 11;
  if (dfsph_columns_) {  // built with THAW_DFSPH: the pass also computes alpha (density.cl)
    k_density_.setArg(arg++, *dfsph_columns_);
    k_density_.setArg(arg++, dfsph_min_neighbours_);
  }
  if (no_slip_) k_density_.setArg(arg, ghost_);
  launch(cl_.queue(), k_density_, layout_.n);
}

void FluidStage::forces(const NeighbourView& nv) {
  if (layout_.n == 0) return;
  forces_params_.n = static_cast<cl_uint>(layout_.n);
  set_args(k_forces_, store_[f_.position], store_[f_.velocity], nv.soa, derived_, state_, store_[f_.phase],
           store_[f_.material], flow_, nv.cell_start, nv.grid, forces_params_, accel_);
  cl_uint arg = 12;
  if (buoyancy_) k_forces_.setArg(arg++, store_[enthalpy_]);
  if (no_slip_) k_forces_.setArg(arg, ghost_);
  launch(cl_.queue(), k_forces_, layout_.n);
}

FlowLimits FluidStage::limits() {
  FlowLimits out;
  if (layout_.n == 0) return out;
  auto& q = cl_.queue();
  set_args(k_limits_, store_[f_.position], store_[f_.velocity], accel_, store_[f_.phase], limits_f_,
           limits_i_, static_cast<cl_uint>(layout_.n), layout_.tile);
  launch(q, k_limits_, layout_.ntiles);
  std::vector<cl_float2> f(layout_.ntiles);
  std::vector<cl_uint2> ix(layout_.ntiles);
  q.enqueueReadBuffer(limits_f_, CL_FALSE, 0, layout_.ntiles * 8, f.data());
  q.enqueueReadBuffer(limits_i_, CL_TRUE, 0, layout_.ntiles * 8, ix.data());
  for (cl_uint t = 0; t < layout_.ntiles; ++t) {
    if (f[t].s[0] > out.vmax2) {
      out.vmax2 = f[t].s[0];
      out.fastest = ix[t].s[0];
    }
    out.amax2 = std::max(out.amax2, double(f[t].s[1]));
    out.bad = std::min(out.bad, ix[t].s[1]);
  }
  return out;
}

void FluidStage::integrate(double dt, double damping_factor) {
  if (layout_.n == 0) return;
  set_args(k_integrate_, store_[f_.position], store_[f_.velocity], accel_, store_[f_.phase],
           static_cast<float>(dt), static_cast<float>(damping_factor), static_cast<cl_uint>(layout_.n));
  launch(cl_.queue(), k_integrate_, layout_.n);
}

}  // namespace thaw
