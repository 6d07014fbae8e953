#include "sim/heat_stage.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "sim/books.h"
#include "sim/cl_launch.h"
#include "sim/error.h"
#include "sim/kernels/dryer_model.h"
#include "sim/kernels/heat_params.h"
#include "sim/solver_constants.h"
#include "sim/substance_stage.h"

namespace thaw {

HeatStage::HeatStage(const StageContext& c, const HeatPlan& plan, const Eigen::Vector3f& lo,
                     const Eigen::Vector3f& hi)
    : cl_(c.cl),
      store_(c.store),
      core_(c.core),
      scene_(c.scene),
      plan_(plan),
      diffusion_dt_(c.k.diffusion_dt),
      wall_dt_(c.k.wall_dt),
      exposed_capacity_(c.k.exposed_capacity),
      support_(c.k.support),
      smoothing_(c.k.smoothing),
      rest_density_(c.k.rest_density),
      layout_(c.layout) {
  enthalpy_ = c.store.add({"enthalpy", FieldType::Float32, 2});

  std::string opts = c.options;
  if (uses_surface()) opts += " -DTHAW_SURFACE_AREA";
  if (substances_lower_melting(c.scene)) opts += " -DTHAW_MELT_SHIFT";
  if (plan.ambient) opts += " -DTHAW_AMBIENT";
  if (plan.dryers) opts += " -DTHAW_DRYERS";
  if (plan.walls) opts += " -DTHAW_WALL_HEAT";
  if (plan.lamps) opts += " -DTHAW_LAMPS";
  if (plan.adiabatic) opts += " -DTHAW_ADIABATIC";
  if (plan.air_faces) opts += " -DTHAW_AIR_FACES";
  for (int a = 0; a < 3; ++a)
    if (c.scene.solver.periodic[static_cast<std::size_t>(a)])
      opts += std::string(" -DTHAW_PERIODIC_") + "XYZ"[a];
  const auto program = c.cl.build(
      neighbour_program({"thermal_law.h", "dryer_model.h", "heat_params.h", "wrapped_walk.h", "heat.cl"}),
      opts);
  k_thermal_state_ = cl::Kernel(program, "thermal_state");
  k_heat_ = cl::Kernel(program, "heat");
  k_absorb_ = cl::Kernel(program, "absorb_photons");
  k_budget_ = cl::Kernel(program, "heat_budget");
  if (plan.adiabatic) k_adiabatic_ = cl::Kernel(program, "adiabatic_state");

  auto& ctx = c.cl.context();
  auto& q = c.cl.queue();
  const std::size_t n = std::max<std::size_t>(c.layout.capacity, 1);
  const std::size_t tiles = std::max<cl_uint>(c.layout.max_tiles, 1);
  auto buf = [&](std::size_t bytes) {
    return cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, 4));
  };
  const std::vector<MaterialThermal> table = material_thermal_table(c.scene, c.k.rest_density);
  materials_ = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                          table.size() * sizeof(MaterialThermal), const_cast<MaterialThermal*>(table.data()));
  thermal_ = buf(std::size_t(c.layout.stride) * 3 * 4);
  q.enqueueFillBuffer(thermal_, 0.0f, 0, std::size_t(c.layout.stride) * 3 * 4);
  if (plan.lamps) {
    lamp_energy_ = buf(n * 4);
    q.enqueueFillBuffer(lamp_energy_, 0.0f, 0, n * 4);
  }
  budget_parts_ = buf(std::size_t(c.layout.stride) * 5 * 4);
  budget_tiles_ = buf(tiles * 5 * 4);
  budget_bad_ = buf(tiles * 4);
  phase_changed_ = buf(4);
  q.enqueueFillBuffer(phase_changed_, cl_uint(0), 0, 4);
  dryers_ = buf(std::max<std::size_t>(c.scene.dryers.size(), 1) * sizeof(dryer::DryerJet));

  // Voxels of one spacing over every particle: a lattice of that spacing puts one particle in each, at
  // the centre for the lattice through the lowest particle (not on a face, where rounding could put two
  // in one voxel and leave a hole next to it). Built once a lamp is on.
  photon_grid_.cell = static_cast<float>(c.scene.spacing);
  photon_grid_.origin = lo - Eigen::Vector3f::Constant(1.5f * photon_grid_.cell);
  const Eigen::Vector3f span = hi + Eigen::Vector3f::Constant(photon_grid_.cell) - photon_grid_.origin;
  photon_grid_.nx = static_cast<int>(std::ceil(span.x() / photon_grid_.cell)) + 1;
  photon_grid_.ny = static_cast<int>(std::ceil(span.y() / photon_grid_.cell)) + 1;
  photon_grid_.nz = static_cast<int>(std::ceil(span.z() / photon_grid_.cell)) + 1;
  lamps_changed();
}

HeatStage::~HeatStage() = default;

bool HeatStage::uses_surface() const {
  return scene_.heat.exposed_area != ExposedArea::Iwasaki2010 && (plan_.ambient || plan_.dryers);
}

double HeatStage::max_dt() const {
  double dt = std::min(diffusion_dt_, wall_dt_);
  double h_air = plan_.ambient ? scene_.heat.ambient_coefficient : 0.0;
  for (const Dryer& d : scene_.dryers)
    if (d.model == DryerModel::Cone && d.on && d.speed > 0)
      h_air += dryer::dryer_coefficient(static_cast<float>(d.nozzle_diameter)) * std::sqrt(d.speed);
  if (h_air > 0) dt = std::min(dt, 0.5 * exposed_capacity_ / (scene_.heat.time_scale * h_air));
  return dt;
}

void HeatStage::lamps_changed() {
  if (photons_) return;
  if (std::none_of(scene_.lamps.begin(), scene_.lamps.end(), [](const Lamp& l) { return l.on; })) return;
  const std::size_t n = std::max<std::size_t>(layout_.capacity, 1);
  hits_ = cl::Buffer(cl_.context(), CL_MEM_READ_WRITE, n * 4);
  cl_.queue().enqueueFillBuffer(hits_, cl_uint(0), 0, n * 4);
  photons_ = std::make_unique<PhotonTracer>(cl_, photon_grid_);
}

void HeatStage::trace_photons(double dt, std::uint64_t step, EnergyBudget& budget) {
  if (!photons_ || layout_.n == 0) return;
  const auto n = static_cast<cl_uint>(layout_.n);
  photons_->build_occupancy(store_[core_.position], store_[core_.phase], n);
  for (std::size_t l = 0; l < scene_.lamps.size(); ++l) {
    const Lamp& lamp = scene_.lamps[l];
    if (!lamp.on) continue;
    // The rectangle's width runs horizontally (across the normal and z) where it can.
    const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d u = lamp.normal.cross(z);
    u = u.norm() > 1e-6 ? u.normalized() : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d v = lamp.normal.cross(u);
    LampGeometry geo;
    geo.centre = lamp.centre.cast<float>();
    geo.normal = lamp.normal.cast<float>();
    geo.half_u = (0.5 * lamp.width * u).cast<float>();
    geo.half_v = (0.5 * lamp.height * v).cast<float>();
    const auto photons = static_cast<std::uint32_t>(lamp.photons);
    const double energy = photon_energy(lamp.emissivity, lamp.temperature, lamp.width * lamp.height,
                                        scene_.heat.time_scale * dt, photons);
    const PhotonTally tally = photons_->trace(geo, photons, step, static_cast<std::uint32_t>(l), hits_);
    const float e = static_cast<float>(energy);
    set_args(k_absorb_, hits_, lamp_energy_, e, n);
    launch(cl_.queue(), k_absorb_, layout_.n);
    budget.lamp_emitted += double(e) * double(tally.emitted);
    budget.lamp_escaped += double(e) * double(tally.escaped());
  }
}

void HeatStage::upload_dryers() {
  std::vector<dryer::DryerJet> jets;
  for (const Dryer& d : scene_.dryers) {
    dryer::DryerJet j{};
    j.px = float(d.position.x());
    j.py = float(d.position.y());
    j.pz = float(d.position.z());
    j.dx = float(d.direction.x());
    j.dy = float(d.direction.y());
    j.dz = float(d.direction.z());
    j.half_angle = float(d.half_angle * M_PI / 180.0);
    j.reach = float(d.reach);
    j.temperature = float(d.temperature);
    j.speed = d.on ? float(d.speed) : 0.0f;
    j.diameter = float(d.nozzle_diameter);
    j.coefficient = dryer::dryer_coefficient(j.diameter);
    jets.push_back(j);
  }
  if (!jets.empty())
    cl_.queue().enqueueWriteBuffer(dryers_, CL_TRUE, 0, jets.size() * sizeof(dryer::DryerJet), jets.data());
  dryers_dirty_ = false;
}

bool HeatStage::run(double dt, const NeighbourView& nv, EnergyBudget& budget, std::uint64_t step, double time,
                    bool want_phase_change) {
  if (layout_.n == 0) return false;
  auto& q = cl_.queue();
  const auto n = static_cast<cl_uint>(layout_.n);
  if (dryers_dirty_) upload_dryers();

  heat::HeatParams P{};
  P.support = support_;
  P.eta2 = 0.01f * smoothing_ * smoothing_;
  float* period[3] = {&P.period_x, &P.period_y, &P.period_z};
  for (int a = 0; a < 3; ++a)
    if (scene_.solver.periodic[static_cast<std::size_t>(a)])
      *period[a] = static_cast<float>(scene_.domain.max[a] - scene_.domain.min[a]);
  const float dx = static_cast<float>(scene_.spacing);
  // Iwasaki's voxel faces: a neighbour within 1.2 spacings covers one (lattice face neighbours sit at 1,
  // edge neighbours at 1.41 spacings).
  P.exposed_r2 = 1.44f * dx * dx;
  P.face_area = dx * dx;
  P.ambient_temperature = static_cast<float>(scene_.heat.ambient_temperature);
  P.ambient_coefficient = static_cast<float>(scene_.heat.ambient_coefficient);
  P.dt_heat = static_cast<float>(scene_.heat.time_scale * dt);
  last_dt_heat_ = double(P.dt_heat);
  P.ndryers = static_cast<cl_uint>(scene_.dryers.size());
  P.stride = layout_.stride;
  P.n = n;
  P.rest_density = rest_density_;
  P.flow = scene_.solver.flow ? 1u : 0u;
  if (plan_.air_faces) {
    const AirFill& air = scene_.air;
    P.face_material = static_cast<cl_uint>(air.material);
    float* lo[3] = {&P.face_min_x, &P.face_min_y, &P.face_min_z};
    float* hi[3] = {&P.face_max_x, &P.face_max_y, &P.face_max_z};
    for (int a = 0; a < 3; ++a) {
      const bool wraps = scene_.solver.periodic[static_cast<std::size_t>(a)];
      *lo[a] = wraps ? -1e30f : static_cast<float>(scene_.domain.min[a]);
      *hi[a] = wraps ? 1e30f : static_cast<float>(scene_.domain.max[a]);
    }
    P.face_depth = static_cast<float>(air.face_depth);
    P.face_fraction = static_cast<float>(-std::expm1(-double(P.dt_heat) / air.face_time));
    P.face_enthalpy = static_cast<float>(enthalpy_at(scene_, air.material, scene_.heat.ambient_temperature));
  }
  // Without a melt shift the kernels never touch its argument; any buffer fills it.
  const cl::Buffer& shift = has_melt_shift_ ? store_[melt_shift_] : dryers_;
  set_args(k_thermal_state_, store_[core_.position], store_[core_.density], store_[enthalpy_],
           store_[core_.phase], store_[core_.material], materials_, thermal_, P, shift);
  launch(q, k_thermal_state_, layout_.n);
  if (plan_.adiabatic) {
    set_args(k_adiabatic_, store_[core_.position], store_[core_.phase], store_[core_.material], materials_,
             nv.soa, thermal_, nv.cell_start, nv.grid, P);
    launch(q, k_adiabatic_, layout_.n);
  }

  // Without lamps the kernel never touches lamp_energy; any buffer fills the argument.
  const cl::Buffer& lamp_energy = plan_.lamps ? lamp_energy_ : dryers_;
  set_args(k_heat_, store_[core_.position], store_[core_.velocity], store_[enthalpy_], store_[core_.phase],
           store_[core_.material], materials_, nv.soa, thermal_, nv.cell_start, nv.grid, P, dryers_,
           lamp_energy, budget_parts_, phase_changed_, uses_surface() ? store_[surface_area_] : dryers_,
           shift);
  launch(q, k_heat_, layout_.n);
  set_args(k_budget_, budget_parts_, store_[enthalpy_], layout_.stride, budget_tiles_, budget_bad_, n,
           layout_.tile);
  launch(q, k_budget_, layout_.ntiles);
  std::vector<float> sums(std::size_t(layout_.ntiles) * 5);
  std::vector<cl_uint> bad(layout_.ntiles);
  cl_uint changed = 0;
  q.enqueueReadBuffer(budget_tiles_, CL_FALSE, 0, sums.size() * 4, sums.data());
  // Rigid ice relabels after a phase change; the flag comes back with the budget (one wait, not two).
  if (want_phase_change) q.enqueueReadBuffer(phase_changed_, CL_FALSE, 0, 4, &changed);
  q.enqueueReadBuffer(budget_bad_, CL_TRUE, 0, bad.size() * 4, bad.data());
  for (cl_uint t = 0; t < layout_.ntiles; ++t) {
    if (bad[t] != 0xffffffffu) {
      Float4 x;
      std::uint32_t id = 0;
      q.enqueueReadBuffer(store_[core_.position], CL_TRUE, bad[t] * 16, 16, x.data());
      q.enqueueReadBuffer(store_[core_.id], CL_TRUE, bad[t] * 4, 4, &id);
      std::ostringstream os;
      os << "step " << step + 1 << " (t = " << time << " s): particle " << id << " at (" << x[0] << ", "
         << x[1] << ", " << x[2]
         << ") m has a non-finite enthalpy; lower solver.max_dt or heat.time_scale, or tame the heat sources";
      throw BlowUpError(os.str());
    }
    const float* t5 = &sums[std::size_t(t) * 5];
    budget.ambient += t5[0];
    budget.lamps += t5[1];
    budget.dryers += t5[2];
    budget.walls += t5[3];
    budget.held += t5[4];
  }
  if (changed) q.enqueueFillBuffer(phase_changed_, cl_uint(0), 0, 4);
  return changed != 0;
}

void HeatStage::warm_up(const NeighbourView& nv, EnergyBudget& budget) {
  if (photons_) photons_->warm_up();
  run(0.0, nv, budget, 0, 0.0, false);
}

std::vector<double> HeatStage::held_power(const cl::Buffer& material, std::size_t materials) const {
  std::vector<double> out(materials, 0.0);
  const std::size_t n = layout_.n;
  if (n == 0 || last_dt_heat_ <= 0) return out;
  std::vector<float> e(n);
  std::vector<std::uint8_t> m(n);
  auto& q = cl_.queue();
  // The budget's held block: what the thermostat put back into each particle, i.e. what it gave the rest.
  q.enqueueReadBuffer(budget_parts_, CL_FALSE, std::size_t(layout_.stride) * 4 * 4, n * 4, e.data());
  q.enqueueReadBuffer(material, CL_TRUE, 0, n, m.data());
  for (std::size_t i = 0; i < n; ++i)
    if (m[i] < materials) out[m[i]] += double(e[i]);
  for (double& p : out) p /= last_dt_heat_;
  return out;
}

void HeatStage::thermal_inputs(std::vector<float>& T, std::vector<float>& k, std::vector<float>& V) const {
  const std::size_t n = layout_.n, stride = layout_.stride;
  if (n == 0) return;
  std::vector<float> all(stride * 3);
  cl_.queue().enqueueReadBuffer(thermal_, CL_TRUE, 0, all.size() * 4, all.data());
  T.assign(all.begin(), all.begin() + long(n));
  k.assign(all.begin() + long(stride), all.begin() + long(stride + n));
  V.assign(all.begin() + 2 * long(stride), all.begin() + long(2 * stride + n));
}

}  // namespace thaw
