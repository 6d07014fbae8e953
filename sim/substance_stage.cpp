#include "sim/substance_stage.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/cl_launch.h"
#include "sim/solver_constants.h"
#include "sim/thermal.h"

namespace thaw {

FieldSpec substance_field(const std::string& name) {
  return {kSubstancePrefix + name, FieldType::Float32, 2, true, false};
}

FieldSpec melt_shift_field() { return {kMeltShiftField, FieldType::Float32, 1, true, true}; }

FieldSpec adsorbed_field(const std::string& name) {
  return {kAdsorbedPrefix + name, FieldType::Float32, 2, true, false};
}

FieldSpec deposited_field(const std::string& name) {
  return {kDepositedPrefix + name, FieldType::Float32, 2, true, false};
}

bool substances_lower_tension(const Scene& scene) {
  return scene.solver.flow && scene.tension.enabled() &&
         std::any_of(scene.substances.begin(), scene.substances.end(),
                     [](const Substance& s) { return s.lowers_tension(); });
}

// Saved: the tension pass of a resumed run's first step reads the ratios the straight run's last step left.
// 1 (0x3f800000) where a state has none.
FieldSpec tension_ratio_field() {
  return {kTensionRatioField, FieldType::Float32, 1, true, true, 0x3f800000u};
}

bool substances_coat(const Scene& scene) {
  return std::any_of(scene.substances.begin(), scene.substances.end(),
                     [](const Substance& s) { return s.coating(); });
}

void add_deposit_columns(HostParticles& p, const Scene& scene,
                         const std::vector<std::pair<std::size_t, std::size_t>>& outer) {
  const double face = scene.spacing * scene.spacing;
  for (std::size_t s = 0; s < scene.substances.size(); ++s) {
    if (!scene.substances[s].coating()) continue;
    HostColumn c{deposited_field(scene.substances[s].name), {}};
    c.bytes.assign(p.size() * c.spec.bytes(), 0);
    Float2* d = c.as<Float2>();
    for (const auto& [i, solid] : outer) {
      const std::vector<double>& deposits = scene.solids[solid].deposits;
      const double amount = s < deposits.size() ? deposits[s] * face : 0.0;
      const float hi = static_cast<float>(amount);
      d[i] = {hi, static_cast<float>(amount - double(hi))};
    }
    p.columns.push_back(std::move(c));
  }
}

bool substances_need_surface(const Scene& scene) {
  return std::any_of(scene.substances.begin(), scene.substances.end(),
                     [](const Substance& s) { return s.surface_active(); });
}

void add_substance_columns(HostParticles& p, const Scene& scene, const std::vector<std::size_t>& first_of,
                           const std::vector<std::vector<double>>& concentrations) {
  for (std::size_t s = 0; s < scene.substances.size(); ++s) {
    HostColumn c{substance_field(scene.substances[s].name), {}};
    c.bytes.assign(p.size() * c.spec.bytes(), 0);
    Float2* q = c.as<Float2>();
    for (std::size_t b = 0; b + 1 < first_of.size() && b < concentrations.size(); ++b) {
      const double concentration = s < concentrations[b].size() ? concentrations[b][s] : 0.0;
      if (concentration == 0.0) continue;
      for (std::size_t i = first_of[b]; i < first_of[b + 1]; ++i) {
        const double rho0 = scene.materials[p.material[i]].density;
        const double amount = concentration * double(p.position[i][3]) / rho0;
        const float hi = static_cast<float>(amount);
        q[i] = {hi, static_cast<float>(amount - double(hi))};
      }
    }
    p.columns.push_back(std::move(c));
  }
  // Where substances lower the melting point, the shift the solution starts with (wholly liquid: the scene
  // loader keeps fluids above their lowered melting point), which the first step's partly frozen check reads.
  if (substances_lower_melting(scene)) {
    HostColumn c{melt_shift_field(), {}};
    c.bytes.assign(p.size() * 4, 0);
    for (std::size_t b = 0; b + 1 < first_of.size() && b < concentrations.size(); ++b)
      for (std::size_t i = first_of[b]; i < first_of[b + 1]; ++i)
        c.as<float>()[i] = static_cast<float>(melting_point_drop(scene, p.material[i], concentrations[b]));
    p.columns.push_back(std::move(c));
  }
}

namespace {

bool has_ice_pair(const Scene& scene) {
  return std::any_of(scene.materials.begin(), scene.materials.end(),
                     [](const Material& m) { return m.kind == MaterialKind::Ice && m.partner >= 0; });
}

}  // namespace

bool substances_lower_melting(const Scene& scene) {
  return scene.heat.enabled && has_ice_pair(scene) &&
         std::any_of(scene.substances.begin(), scene.substances.end(),
                     [](const Substance& s) { return s.lowers_melting_point(); });
}

bool substances_rejected_by_ice(const Scene& scene) {
  return scene.heat.enabled && has_ice_pair(scene) &&
         std::any_of(scene.substances.begin(), scene.substances.end(),
                     [](const Substance& s) { return !s.enters_ice; });
}

SubstanceStage::SubstanceStage(const StageContext& c, const ParticleStore::Field* enthalpy,
                               const SurfaceFields* surface)
    : cl_(c.cl), store_(c.store), core_(c.core), scene_(c.scene), layout_(c.layout) {
  for (const Substance& s : c.scene.substances) {
    fields_.push_back(c.store.add(substance_field(s.name)));
    diffusivity_.push_back(s.diffusivity);
    adsorbed_.push_back(-1);
    if (s.surface_active() && surface) {
      adsorbed_.back() = static_cast<int>(adsorbed_fields_.size());
      adsorbed_fields_.push_back(c.store.add(adsorbed_field(s.name)));
    }
    deposited_.push_back(-1);
    if (s.coating()) {
      deposited_.back() = static_cast<int>(deposited_fields_.size());
      deposited_fields_.push_back(c.store.add(deposited_field(s.name)));
    }
  }
  surface_ = !adsorbed_fields_.empty();
  deposit_ = !deposited_fields_.empty();
  if (surface_) surface_fields_ = *surface;
  // The shift is a field wherever the scene's substances lower the melting point (a state file keeps it for
  // the temperatures it shows), and renewed here only where heat reads it.
  has_shift_ = substances_lower_melting(c.scene);
  if (has_shift_) shift_ = c.store.add(melt_shift_field());
  lowers_ = enthalpy && has_shift_;
  const bool rejects = enthalpy && substances_rejected_by_ice(c.scene);
  std::string opts = c.options + " -DTHAW_NSUB=" + std::to_string(c.scene.substances.size());
  if (lowers_) opts += " -DTHAW_MELT_SHIFT";
  if (rejects) opts += " -DTHAW_REJECT";
  if (surface_) opts += " -DTHAW_SURFACE";
  if (deposit_) opts += " -DTHAW_DEPOSIT";
  lowers_tension_ = surface_ && substances_lower_tension(c.scene);
  if (lowers_tension_) {
    opts += " -DTHAW_TENSION_LAW";
    ratio_ = c.store.add(tension_ratio_field());
    for (std::size_t s = 0; s < c.scene.substances.size(); ++s) {
      const Substance& sub = c.scene.substances[s];
      if (!sub.lowers_tension()) continue;
      params_.tension_law |= (sub.tension_law == TensionLaw::Szyszkowski ? 1u : 2u) << (2 * s);
      float* e[4] = {&params_.tension0, &params_.tension1, &params_.tension2, &params_.tension3};
      *e[s] = static_cast<float>(sub.tension_scale / c.scene.tension.coefficient);
    }
  }
  ice_pass_ = lowers_ || rejects;
  if (enthalpy) enthalpy_ = *enthalpy;
  for (int a = 0; a < 3; ++a)
    if (c.scene.solver.periodic[static_cast<std::size_t>(a)])
      opts += std::string(" -DTHAW_PERIODIC_") + "XYZ"[a];
  const auto program = c.cl.build(neighbour_program({"wrapped_walk.h", "thermal_law.h", "liquidus.h",
                                                     "substance_params.h", "substance.cl"}),
                                  opts);
  k_state_ = cl::Kernel(program, "substance_state");
  if (ice_pass_) k_ice_ = cl::Kernel(program, "substance_ice");
  k_diffuse_ = cl::Kernel(program, "substance_diffuse");
  if (surface_) k_norm_ = cl::Kernel(program, "substance_norm");
  if (deposit_) {
    k_wet_ = cl::Kernel(program, "substance_wet");
    k_cells_ = cl::Kernel(program, "substance_cells");
    k_around_ = cl::Kernel(program, "substance_cells_around");
  }

  // Zeros past the particles too: the walk's lanes read a few floats beyond each cell's last one. The
  // blocks: M, A, W per substance; with surface-active ones AS, NRM, MOM, PX, PY, PZ, NX, NY, NZ, G per
  // substance; with coatings F, R per substance.
  const std::size_t count = c.scene.substances.size();
  const std::size_t bytes = std::size_t(c.layout.stride) *
                            (2 + count + (surface_ ? 9 + count : 0) + (deposit_ ? 1 + count : 0)) * 4;
  sub_ = cl::Buffer(c.cl.context(), CL_MEM_READ_WRITE, bytes);
  c.cl.queue().enqueueFillBuffer(sub_, 0.0f, 0, bytes);
  // Each material's rest density and cryoscopic constant (ice: that of the water it melts into).
  std::vector<float> fluid;
  for (const Material& m : c.scene.materials) {
    const Material* solvent = m.kind == MaterialKind::Fluid ? &m
                              : m.kind == MaterialKind::Ice && m.partner >= 0
                                  ? &c.scene.materials[static_cast<std::size_t>(m.partner)]
                                  : nullptr;
    fluid.push_back(static_cast<float>(m.density));
    fluid.push_back(static_cast<float>(solvent ? solvent->cryoscopic_constant : 0.0));
  }
  fluid_ =
      cl::Buffer(c.cl.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, fluid.size() * 4, fluid.data());
  std::vector<float> law;  // each material's L, c_solid, c_liquid and physical over SPH mass
  for (const thermal::MaterialThermal& m : material_thermal_table(c.scene, c.k.rest_density))
    law.insert(law.end(), {m.latent, m.c_solid, m.c_liquid, m.thermal_mass_scale});
  law_ = cl::Buffer(c.cl.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, law.size() * 4, law.data());
  liquidus_table_ = liquidus_table(c.scene);  // each substance's phase diagram
  liquidus_ = cl::Buffer(c.cl.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                         liquidus_table_.size() * sizeof(thermal::Liquidus), liquidus_table_.data());

  params_.support = c.k.support;
  params_.eta2 = 0.01f * c.k.smoothing * c.k.smoothing;
  float* period[3] = {&params_.period_x, &params_.period_y, &params_.period_z};
  for (int a = 0; a < 3; ++a)
    if (c.scene.solver.periodic[static_cast<std::size_t>(a)])
      *period[a] = static_cast<float>(c.scene.domain.max[a] - c.scene.domain.min[a]);
  params_.flow = c.scene.solver.flow ? 1u : 0u;
  for (std::size_t s = 0; s < c.scene.substances.size(); ++s)
    if (!c.scene.substances[s].enters_ice) params_.reject |= 1u << s;

  // Explicit diffusion is stable for D dt / h^2 below about 1/6 in 3-D; heat keeps the same margin.
  const double D = diffusivity_.empty() ? 0.0 : *std::max_element(diffusivity_.begin(), diffusivity_.end());
  const double h = c.k.smoothing;
  max_dt_ = D > 0 ? c.scene.solver.diffusion_number * h * h / D : std::numeric_limits<double>::infinity();
  rest_density_ = c.k.rest_density;

  if (deposit_) {
    const double dx = c.scene.spacing, H = c.k.support;
    params_.face = static_cast<float>(dx * dx);
    // The water weight sum_j M_j w(r / H) of a kernel volume kWetFraction full of water: rho0 kWetFraction
    // over the kernel's normalisation sigma / H^3 (Wendland C2 21 / (2 pi), the cubic spline 8 / pi).
    const double sigma3 =
        c.scene.solver.kernel == KernelFunction::WendlandC2 ? 21.0 / (2.0 * M_PI) : 8.0 / M_PI;
    params_.wet_weight = static_cast<float>(kWetFraction * c.k.rest_density * H * H * H / sigma3);
    params_.cleanser = 0xffffu;
    for (std::size_t s = 0; s < count; ++s) {
      const Substance& sub = c.scene.substances[s];
      if (!sub.coating()) continue;
      params_.coating |= 1u << s;
      if (sub.cleanser >= 0) {
        params_.cleanser &= ~(15u << (4 * s));
        params_.cleanser |= static_cast<unsigned>(sub.cleanser) << (4 * s);
      }
      // A step may move at most diffusion_number of a carrier's coating to the boundary (k_c dt / dx: a
      // carrier of volume dx^3 over a face dx^2), of a boundary's coating saturating (k_c c_max dt /
      // Gamma_R,max) or of a deposit back (k_r c_D,max dt), c_max the largest concentration the scene starts
      // with or pours.
      auto most = [&](std::size_t of) {
        double top = 0;
        for (const FluidBlock& f : c.scene.fluids)
          top = std::max(top, of < f.substances.size() ? f.substances[of] : 0.0);
        for (const Emitter& e : c.scene.emitters)
          top = std::max(top, of < e.substances.size() ? e.substances[of] : 0.0);
        return top;
      };
      double rate = sub.coating_rate / dx;
      if (sub.coating_capacity > 0) rate += sub.coating_rate * most(s) / sub.coating_capacity;
      if (sub.cleanser >= 0) rate += sub.cleansing_rate * most(static_cast<std::size_t>(sub.cleanser));
      if (rate > 0) max_dt_ = std::min(max_dt_, c.scene.solver.diffusion_number / rate);
    }
  }

  if (!surface_) return;
  // Surface particles: more than a twentieth of a lattice face of area (kSurfaceMinArea; brackbill1992 gates
  // the area to the outer layer, where a flat face's particles carry 0.6 of theirs). The surface point of
  // each lies surface_depth_spacings out along its normal (substance_stage.h says why a quarter).
  const double dx = c.scene.spacing;
  params_.min_area = static_cast<float>(kSurfaceMinArea * dx * dx);
  params_.surface_depth = static_cast<float>(surface_depth_spacings * dx);
  // The 2-D kernel's normalisation over the support H: Wendland C2 7 / (pi H^2), the cubic spline
  // 40 / (7 pi H^2) (the 3-D ones' shapes, sph_lanes.h).
  const double H = c.k.support;
  const double sigma2 =
      c.scene.solver.kernel == KernelFunction::WendlandC2 ? 7.0 / M_PI : 40.0 / (7.0 * M_PI);
  params_.sigma2 = static_cast<float>(sigma2);
  sigma2_over_h4_ = sigma2 / (H * H * H * H);
  for (std::size_t s = 0; s < count; ++s) {
    const Substance& sub = c.scene.substances[s];
    if (adsorbed_[s] < 0) continue;
    params_.surface |= 1u << s;
    // The most water a step may hand the surface or take back, as a fraction: k_d dt, k_a dt / dx (a
    // carrier of volume dx^3 under a face dx^2), and the Langmuir saturation rate k_a c / Gamma_max at the
    // largest concentration the scene starts with or pours, each at most diffusion_number.
    double c_max = 0;
    for (const FluidBlock& f : c.scene.fluids)
      c_max = std::max(c_max, s < f.substances.size() ? f.substances[s] : 0.0);
    for (const Emitter& e : c.scene.emitters)
      c_max = std::max(c_max, s < e.substances.size() ? e.substances[s] : 0.0);
    const double rate = sub.desorption_rate + sub.adsorption_rate / dx +
                        (sub.surface_capacity > 0 ? sub.adsorption_rate * c_max / sub.surface_capacity : 0.0);
    if (rate > 0) max_dt_ = std::min(max_dt_, c.scene.solver.diffusion_number / rate);
    if (sub.surface_diffusivity > 0)
      max_dt_ = std::min(max_dt_, c.scene.solver.diffusion_number * h * h / sub.surface_diffusivity);
  }
}

const cl::Buffer& SubstanceStage::amount(std::size_t s) const {
  return store_[fields_[std::min(s, fields_.size() - 1)]];
}

const cl::Buffer& SubstanceStage::on_surface(std::size_t s) const {
  if (s < adsorbed_.size() && adsorbed_[s] >= 0) return store_[adsorbed_fields_[std::size_t(adsorbed_[s])]];
  return adsorbed_fields_.empty() ? sub_ : store_[adsorbed_fields_.front()];
}

const cl::Buffer& SubstanceStage::on_solids(std::size_t s) const {
  if (s < deposited_.size() && deposited_[s] >= 0)
    return store_[deposited_fields_[std::size_t(deposited_[s])]];
  return deposited_fields_.empty() ? sub_ : store_[deposited_fields_.front()];
}

std::vector<ParticleStore::Field> SubstanceStage::amount_fields(std::size_t s) const {
  std::vector<ParticleStore::Field> out{fields_[s]};
  if (adsorbed_[s] >= 0) out.push_back(adsorbed_fields_[std::size_t(adsorbed_[s])]);
  if (deposited_[s] >= 0) out.push_back(deposited_fields_[std::size_t(deposited_[s])]);
  return out;
}

void SubstanceStage::prepare(const NeighbourView& nv) {
  if (layout_.n == 0) return;
  auto& q = cl_.queue();
  params_.stride = layout_.stride;
  params_.n = static_cast<cl_uint>(layout_.n);
  split_ = true;
  split_n_ = layout_.n;
  // Slots past the scene's substances take the first one's buffer: the kernels never touch them. Without
  // the ice pass the kernels never read the enthalpy, nor the shift without THAW_MELT_SHIFT; any buffer
  // fills those arguments.
  const cl::Buffer& enthalpy = ice_pass_ ? store_[enthalpy_] : sub_;
  const cl::Buffer& shift = has_shift_ ? store_[shift_] : sub_;
  const cl::Buffer& area = surface_ ? store_[surface_fields_.area] : sub_;
  const cl::Buffer& normal = surface_ ? store_[surface_fields_.normal] : sub_;
  set_args(k_state_, store_[core_.position], store_[core_.density], enthalpy, store_[core_.phase],
           store_[core_.material], fluid_, law_, liquidus_, sub_, shift, amount(0), amount(1), amount(2),
           amount(3), area, normal, on_surface(0), on_surface(1), on_surface(2), on_surface(3), on_solids(0),
           on_solids(1), on_solids(2), on_solids(3), params_);
  launch(q, k_state_, layout_.n);
  if (surface_) {
    set_args(k_norm_, store_[core_.position], nv.soa, sub_, nv.cell_start, nv.grid, params_);
    launch(q, k_norm_, layout_.n);
  }
  if (deposit_) {
    const std::size_t cells = std::size_t(nv.grid.nx) * std::size_t(nv.grid.ny) * std::size_t(nv.grid.nz);
    if (cells != cell_count_) {
      held_cells_ = cl::Buffer(cl_.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(cells, 1));
      around_cells_ = cl::Buffer(cl_.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(cells, 1));
      cell_count_ = cells;
    }
    set_args(k_cells_, sub_, store_[core_.phase], nv.cell_start, held_cells_, static_cast<cl_uint>(cells),
             params_);
    launch(q, k_cells_, cells);
    set_args(k_around_, held_cells_, around_cells_, nv.grid, static_cast<cl_uint>(cells));
    launch(q, k_around_, cells);
    set_args(k_wet_, store_[core_.position], store_[core_.phase], nv.soa, sub_, nv.cell_start, nv.grid,
             params_, around_cells_);
    launch(q, k_wet_, layout_.n);
  }
  if (ice_pass_) {
    set_args(k_ice_, store_[core_.position], store_[core_.phase], store_[core_.material], fluid_, law_,
             liquidus_, enthalpy, nv.soa, sub_, shift, nv.cell_start, nv.grid, amount(0), amount(1),
             amount(2), amount(3), params_);
    launch(q, k_ice_, layout_.n);
  }
}

void SubstanceStage::diffuse(double dt, const NeighbourView& nv) {
  if (layout_.n == 0 || dt <= 0) return;
  // 2 D dt of each substance: the pair term's constant for this step with the kernel's sigma / H^2
  // (substance.cl).
  float* step[4] = {&params_.step0, &params_.step1, &params_.step2, &params_.step3};
  for (std::size_t s = 0; s < 4; ++s)
    *step[s] = s < diffusivity_.size() ? static_cast<float>(2.0 * diffusivity_[s] * dt) : 0.0f;
  if (surface_) {
    float* adsorb[4] = {&params_.adsorb0, &params_.adsorb1, &params_.adsorb2, &params_.adsorb3};
    float* desorb[4] = {&params_.desorb0, &params_.desorb1, &params_.desorb2, &params_.desorb3};
    float* inv_capacity[4] = {&params_.inv_capacity0, &params_.inv_capacity1, &params_.inv_capacity2,
                              &params_.inv_capacity3};
    float* glide[4] = {&params_.glide0, &params_.glide1, &params_.glide2, &params_.glide3};
    for (std::size_t s = 0; s < adsorbed_.size(); ++s) {
      if (adsorbed_[s] < 0) continue;
      const Substance& sub = scene_.substances[s];
      *adsorb[s] = static_cast<float>(sub.adsorption_rate * rest_density_ * dt);
      *desorb[s] = static_cast<float>(sub.desorption_rate * dt);
      *inv_capacity[s] = sub.surface_capacity > 0 ? static_cast<float>(1.0 / sub.surface_capacity) : 0.0f;
      *glide[s] = static_cast<float>(2.0 * sub.surface_diffusivity * dt * sigma2_over_h4_);
    }
  }
  if (deposit_) {
    float* coat[4] = {&params_.coat0, &params_.coat1, &params_.coat2, &params_.coat3};
    float* cleanse[4] = {&params_.cleanse0, &params_.cleanse1, &params_.cleanse2, &params_.cleanse3};
    float* inv_capacity[4] = {&params_.inv_coat_capacity0, &params_.inv_coat_capacity1,
                              &params_.inv_coat_capacity2, &params_.inv_coat_capacity3};
    for (std::size_t s = 0; s < deposited_.size(); ++s) {
      if (deposited_[s] < 0) continue;
      const Substance& sub = scene_.substances[s];
      *coat[s] = static_cast<float>(sub.coating_rate * rest_density_ * dt);
      *cleanse[s] = sub.cleanser >= 0 ? static_cast<float>(sub.cleansing_rate * rest_density_ * dt) : 0.0f;
      *inv_capacity[s] = sub.coating_capacity > 0 ? static_cast<float>(1.0 / sub.coating_capacity) : 0.0f;
    }
  }
  set_args(k_diffuse_, store_[core_.position], nv.soa, sub_, nv.cell_start, nv.grid, params_, amount(0),
           amount(1), amount(2), amount(3), on_surface(0), on_surface(1), on_surface(2), on_surface(3),
           on_solids(0), on_solids(1), on_solids(2), on_solids(3), lowers_tension_ ? store_[ratio_] : sub_,
           deposit_ ? around_cells_ : sub_);
  launch(cl_.queue(), k_diffuse_, layout_.n);
}

std::vector<float> SubstanceStage::melt_shifts() const {
  std::vector<float> out(lowers_ ? layout_.n : 0);
  if (!out.empty()) cl_.queue().enqueueReadBuffer(store_[shift_], CL_TRUE, 0, out.size() * 4, out.data());
  return out;
}

std::vector<double> SubstanceStage::totals() const {
  std::vector<double> out;
  for (const Parts& p : parts()) out.push_back(p.dissolved + p.on_surface + p.on_solids);
  return out;
}

std::vector<SubstanceStage::Parts> SubstanceStage::parts() const {
  std::vector<Parts> out(fields_.size());
  const std::size_t n = layout_.n;
  if (n == 0) return out;
  std::vector<Float2> a(n);
  auto sum = [&](ParticleStore::Field f) {
    cl_.queue().enqueueReadBuffer(store_[f], CL_TRUE, 0, n * sizeof(Float2), a.data());
    double total = 0;
    for (const Float2& v : a) total += double(v[0]) + double(v[1]);
    return total;
  };
  for (std::size_t s = 0; s < fields_.size(); ++s) {
    out[s].dissolved = sum(fields_[s]);
    if (adsorbed_[s] >= 0) out[s].on_surface = sum(adsorbed_fields_[std::size_t(adsorbed_[s])]);
    if (deposited_[s] >= 0) out[s].on_solids = sum(deposited_fields_[std::size_t(deposited_[s])]);
  }
  if (!split_) return out;
  // Each particle's melt (the M block, the first of sub_: its liquid part's mass; -1 for ice handing its
  // amount out, which has none) from the last prepare, and the amounts now: what the melt does not dissolve
  // is undissolved. Particles an emitter added since (past split_n_) hold the solution it pours, which the
  // scene keeps within solubility.
  std::vector<float> melt(std::min(n, split_n_));
  if (!melt.empty()) cl_.queue().enqueueReadBuffer(sub_, CL_TRUE, 0, melt.size() * 4, melt.data());
  for (std::size_t s = 0; s < fields_.size(); ++s) {
    cl_.queue().enqueueReadBuffer(store_[fields_[s]], CL_TRUE, 0, n * sizeof(Float2), a.data());
    Parts& p = out[s];
    p.split = true;
    for (std::size_t i = 0; i < melt.size(); ++i) {
      const double q = double(a[i][0]) + double(a[i][1]), m = std::max(double(melt[i]), 0.0);
      if (!(q > 0)) continue;
      const double held = thermal::liquidus_dissolved(&liquidus_table_[s], q, m);
      p.undissolved += q - held;
      if (m > 0) p.most_fraction = std::max(p.most_fraction, held / m);
    }
  }
  return out;
}

}  // namespace thaw
