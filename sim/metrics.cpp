#include "sim/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/dfsph_stage.h"
#include "sim/rigid_ice.h"
#include "sim/solver.h"
#include "sim/thermal.h"

namespace thaw {

Metrics measure(const HostParticles& p, const Scene& scene, double rest_density) {
  Metrics m;
  double err_sum = 0;
  std::size_t fluid = 0;
  m.heat = scene.heat.enabled && p.enthalpy.size() == p.size();
  std::vector<MaterialThermal> table;
  if (m.heat) table = material_thermal_table(scene, rest_density);
  double t_sum = 0;
  std::size_t t_count = 0;
  // Compression is measured against the density the pressure solver holds water at rest at: WCSPH's
  // equation of state, rho0; DFSPH's density solve, the density a resting lattice sums to (dfsph.cl: 1.003
  // rho0 for Wendland C2 over 3 spacings), which against rho0 read as 0.3 % of compression in still water.
  const double reference =
      scene.solver.pressure == PressureSolver::Dfsph ? rest_density * dfsph_rest_ratio(scene) : rest_density;
  m.min_temperature = m.air_min_temperature = std::numeric_limits<double>::infinity();
  m.max_temperature = m.air_max_temperature = -std::numeric_limits<double>::infinity();
  double air_sum = 0;
  std::size_t air_count = 0;
  const std::vector<double> shift = m.heat ? melt_shifts_of(p, scene) : std::vector<double>{};
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto phase = static_cast<Phase>(p.phase[i]);
    ++m.count[static_cast<int>(phase)];
    if (m.heat) {
      const MaterialThermal& mt = table[p.material[i]];
      const double h = double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]);
      const double mass = double(p.position[i][3]) * mt.thermal_mass_scale;
      m.enthalpy += mass * h;
      m.enthalpy_scale += mass * std::abs(h);
      if (phase == Phase::Water || phase == Phase::Ice) {
        (phase == Phase::Ice ? m.ice_mass : m.water_mass) += mass;
        const double T = temperature_at(mt, h, shift.empty() ? 0.0 : shift[i]);
        m.min_temperature = std::min(m.min_temperature, T);
        m.max_temperature = std::max(m.max_temperature, T);
        t_sum += T;
        ++t_count;
      } else if (phase == Phase::Air) {
        m.air_mass += mass;
        const double T = temperature_at(mt, h);
        m.air_min_temperature = std::min(m.air_min_temperature, T);
        m.air_max_temperature = std::max(m.air_max_temperature, T);
        air_sum += T;
        ++air_count;
      }
    }
    if (phase == Phase::Solid || phase == Phase::Ice) continue;
    const auto& x = p.position[i];
    const auto& v = p.velocity[i];
    const double mass = x[3];
    const double v2 = double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2];
    m.max_speed = std::max(m.max_speed, std::sqrt(v2));
    m.fluid_mass += mass;
    m.kinetic += 0.5 * mass * v2;
    m.potential -= mass * (scene.gravity.x() * x[0] + scene.gravity.y() * x[1] + scene.gravity.z() * x[2]);
    // Compression only: a free-surface particle's summation density is low for lack of neighbours,
    // not because the fluid expanded.
    const double e = std::max(0.0, (p.density[i] - reference) / reference);
    m.max_density_error = std::max(m.max_density_error, e);
    err_sum += e;
    ++fluid;
  }
  m.mean_density_error = fluid ? err_sum / double(fluid) : 0.0;
  m.mean_temperature = t_count ? t_sum / double(t_count) : 0.0;
  if (!t_count) m.min_temperature = m.max_temperature = 0.0;
  m.air_mean_temperature = air_count ? air_sum / double(air_count) : 0.0;
  if (!air_count) m.air_min_temperature = m.air_max_temperature = 0.0;
  if (!m.heat) m.water_mass = m.fluid_mass;
  return m;
}

Metrics measure(const Solver& s) {
  Metrics m = measure(s.particles(), s.scene(), s.constants().rest_density);
  m.time = s.time();
  m.dt = s.dt();
  m.steps = s.steps();
  m.clamped = s.clamped();
  m.budget = s.energy_budget();
  m.outflow = s.outflow();
  m.inflow = s.inflow();
  m.bodies = bodies_json(s);
  m.pressure_solve = pressure_solve_json(s);
  m.substances = substances_json(s);
  return m;
}

Json substances_json(const Solver& s) {
  const std::vector<Substance>& list = s.scene().substances;
  if (list.empty()) return nullptr;
  const std::vector<SubstanceStage::Parts> parts = s.substance_parts();
  const SubstanceBooks& books = s.substance_books();
  Json out = Json::object();
  for (std::size_t k = 0; k < list.size(); ++k) {
    const SubstanceStage::Parts& p = parts[k];
    const double total = p.dissolved + p.on_surface + p.on_solids;
    const double closure = books.closure(k, total), scale = books.initial[k] + books.inflow[k];
    out[list[k].name] = {{"total", total},
                         {"dissolved", p.dissolved},
                         {"on_surface", p.on_surface},
                         {"on_solids", p.on_solids},
                         {"initial", books.initial[k]},
                         {"outflow", books.outflow[k]},
                         {"inflow", books.inflow[k]},
                         {"closure", closure},
                         {"closure_relative", scale > 0 ? closure / scale : 0.0}};
    // Past its solubility a melt leaves the rest undissolved (sim/kernels/liquidus.h); known once a step ran.
    if (p.split) {
      out[list[k].name]["undissolved"] = p.undissolved;
      out[list[k].name]["most_mass_fraction"] = p.most_fraction;
    }
  }
  return out;
}

Json pressure_solve_json(const Solver& s) {
  const DfsphStage* d = s.dfsph();
  if (!d) return nullptr;
  const PressureSolveTotals& t = d->totals();
  const double steps = double(std::max<std::uint64_t>(t.steps, 1));
  auto solve = [](const PressureSolve& p, double tolerance) {
    return Json{{"iterations", p.iterations},
                {"error", p.error},
                {"tolerance", tolerance},
                {"converged", p.converged}};
  };
  const SolverSettings& st = s.scene().solver;
  Json out = {{"density", solve(d->last_density(), st.density_tolerance)},
              {"divergence", solve(d->last_divergence(), st.divergence_tolerance)},
              {"mean_density_iterations", double(t.density_iterations) / steps},
              {"mean_divergence_iterations", double(t.divergence_iterations) / steps},
              {"unconverged_density_steps", t.density_unconverged},
              {"unconverged_divergence_steps", t.divergence_unconverged},
              {"worst_unconverged_density_error", t.worst_density_error}};
  // Ideal-gas air filling a closed domain: its pressure over the room's (Gay-Lussac's law).
  if (d->closed_gas()) out["closed_air_pressure_ratio"] = 1.0 / d->gas_volume_factor();
  return out;
}

Json bodies_json(const Solver& s) {
  const RigidIce* rigid = s.rigid_ice();
  if (!rigid) return nullptr;
  auto vec = [](const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); };
  Json list = Json::array();
  for (const IceBody& b : rigid->bodies()) {
    list.push_back({{"label", b.label},
                    {"particles", b.particles},
                    {"mass", b.body.mass},
                    {"fixed", b.body.fixed},
                    {"centre", vec(b.body.position)},
                    {"velocity", vec(b.body.velocity)},
                    {"angular_velocity", vec(b.body.angular_velocity())}});
  }
  return {{"list", list}, {"labellings", rigid->labellings()}, {"last_sweeps", rigid->last_iterations()}};
}

Json metrics_json(const Metrics& m, double wall_ms_per_step, const Json& stage_ms_per_step) {
  Json j;
  j["time"] = m.time;
  j["steps"] = m.steps;
  j["dt"] = m.dt;
  j["wall_ms_per_step"] = wall_ms_per_step;
  j["stage_ms_per_step"] = stage_ms_per_step;
  Json counts;
  for (int i = 0; i < kPhaseCount; ++i) counts[phase_name(static_cast<Phase>(i))] = m.count[i];
  j["particles"] = counts;
  j["clamped"] = m.clamped;
  j["max_speed"] = m.max_speed;
  j["max_density_error"] = m.max_density_error;
  j["mean_density_error"] = m.mean_density_error;
  j["total_mass"] = m.heat ? m.water_mass + m.ice_mass : m.fluid_mass;
  j["energy"] = {{"kinetic", m.kinetic}, {"potential", m.potential}, {"mechanical", m.kinetic + m.potential}};
  if (!m.bodies.is_null()) j["bodies"] = m.bodies;
  if (!m.pressure_solve.is_null()) j["dfsph"] = m.pressure_solve;
  if (!m.substances.is_null()) j["substances"] = m.substances;
  if (m.outflow.particles)
    j["outflow"] = {{"particles", m.outflow.particles},
                    {"mass", m.outflow.mass},
                    {"momentum", {m.outflow.momentum.x(), m.outflow.momentum.y(), m.outflow.momentum.z()}},
                    {"enthalpy", m.budget.outflow}};
  if (m.inflow.particles)
    j["inflow"] = {{"particles", m.inflow.particles},
                   {"mass", m.inflow.mass},
                   {"momentum", {m.inflow.momentum.x(), m.inflow.momentum.y(), m.inflow.momentum.z()}},
                   {"enthalpy", m.budget.inflow}};
  if (m.heat) {
    const EnergyBudget& b = m.budget;
    j["mass"] = {{"water", m.water_mass}, {"ice", m.ice_mass}};
    j["temperature"] = {{"min", m.min_temperature}, {"mean", m.mean_temperature}, {"max", m.max_temperature}};
    if (m.count[static_cast<int>(Phase::Air)]) {
      j["mass"]["air"] = m.air_mass;
      j["air_temperature"] = {
          {"min", m.air_min_temperature}, {"mean", m.air_mean_temperature}, {"max", m.air_max_temperature}};
    }
    const double gross =
        std::abs(b.ambient) + std::abs(b.lamps) + std::abs(b.dryers) + std::abs(b.walls) + std::abs(b.held);
    j["heat"] = {
        {"enthalpy", m.enthalpy},
        {"in",
         {{"ambient", b.ambient},
          {"lamps", b.lamps},
          {"dryers", b.dryers},
          {"walls", b.walls},
          {"held", b.held},
          {"outflow", -b.outflow},
          {"inflow", b.inflow},
          {"total", b.heat_in()}}},
        {"lamps", {{"emitted", b.lamp_emitted}, {"absorbed", b.lamps}, {"escaped", b.lamp_escaped}}},
        {"closure", m.closure()},
        {"closure_relative", m.closure() / std::max({m.enthalpy_scale, gross, 1e-300})},
    };
  }
  return j;
}

}  // namespace thaw
