#include "sim/thermal.h"

#include "sim/solver.h"

#include <algorithm>
#include <cmath>

namespace thaw {

std::vector<MaterialThermal> material_thermal_table(const Scene& scene, double rest_density, int wall_layers) {
  std::vector<MaterialThermal> table;
  const double dx = scene.spacing;
  for (const Material& m : scene.materials) {
    MaterialThermal t{};
    t.k_solid = t.k_liquid = static_cast<float>(m.conductivity);
    t.c_solid = t.c_liquid = static_cast<float>(m.specific_heat);
    t.partner = m.partner;
    if (m.partner >= 0) {
      const Material& other = scene.materials[static_cast<std::size_t>(m.partner)];
      const bool ice = m.kind == "ice";
      t.c_solid = static_cast<float>(ice ? m.specific_heat : other.specific_heat);
      t.c_liquid = static_cast<float>(ice ? other.specific_heat : m.specific_heat);
      t.k_solid = static_cast<float>(ice ? m.conductivity : other.conductivity);
      t.k_liquid = static_cast<float>(ice ? other.conductivity : m.conductivity);
      t.latent = static_cast<float>(m.latent_heat);
      t.melt = static_cast<float>(m.melting_point);
      t.flags |= ice ? THAW_MAT_MELTS : THAW_MAT_FREEZES;
    }
    // Fluid particles carry their physical mass; static ones (solids, ice) the rest-density mass rho0 V
    // that the fluid solver needs from a boundary particle.
    t.thermal_mass_scale = static_cast<float>(m.kind == "fluid" ? 1.0 : m.density / rest_density);
    if (m.kind != "solid") t.flags |= THAW_MAT_AIR_EXCHANGE;
    if (m.held) {
      t.flags |= THAW_MAT_HELD;
      t.held_enthalpy = static_cast<float>(m.specific_heat * (m.held_temperature - t.melt));
    }
    if (m.wall_heat) {
      // U A (T_out - T) through the outer face, shared by the layers of wall behind each dx^2 of it.
      t.flags |= THAW_MAT_WALL_HEAT;
      t.wall_coefficient = static_cast<float>(scene.heat.wall_coefficient * dx * dx / std::max(wall_layers, 1));
      t.wall_temperature = static_cast<float>(scene.heat.wall_temperature);
    }
    table.push_back(t);
  }
  return table;
}

double enthalpy_at(const Scene& scene, int material, double temperature) {
  const Material& m = scene.materials[static_cast<std::size_t>(material)];
  if (m.partner < 0) return m.specific_heat * temperature;  // T_m = 0 for materials without a phase change
  const Material& other = scene.materials[static_cast<std::size_t>(m.partner)];
  const bool ice = m.kind == "ice";
  const double c_solid = ice ? m.specific_heat : other.specific_heat;
  const double c_liquid = ice ? other.specific_heat : m.specific_heat;
  const double dT = temperature - m.melting_point;
  return ice ? c_solid * dT : m.latent_heat + c_liquid * dT;
}

double temperature_at(const MaterialThermal& m, double h) {
  return h < 0 ? m.melt + h / m.c_solid : (h > m.latent ? m.melt + (h - m.latent) / m.c_liquid : m.melt);
}

double liquid_fraction_at(const MaterialThermal& m, double h) {
  if (m.latent <= 0) return h > 0 ? 1.0 : 0.0;
  return std::clamp(h / m.latent, 0.0, 1.0);
}

std::vector<float> temperatures_of(const HostParticles& p, const Scene& scene) {
  std::vector<float> out;
  if (!scene.heat.enabled || p.enthalpy.size() != p.size()) return out;
  const int layers = scene.wall_layers > 0 ? scene.wall_layers
                                           : static_cast<int>(std::ceil(scene.solver.support_ratio - 1e-9));
  const auto table = material_thermal_table(scene, derive_constants(scene).rest_density, layers);
  out.reserve(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    out.push_back(static_cast<float>(
        temperature_at(table[p.material[i]], double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]))));
  return out;
}

double max_diffusivity(const Scene& scene) {
  // Materials some particle has or can turn into.
  std::vector<bool> used(scene.materials.size(), false);
  auto use = [&](int m) {
    if (m < 0) return;
    used[static_cast<std::size_t>(m)] = true;
    const int partner = scene.materials[static_cast<std::size_t>(m)].partner;
    if (partner >= 0) used[static_cast<std::size_t>(partner)] = true;
  };
  for (const auto& f : scene.fluids) use(f.material);
  for (const auto& c : scene.ice) use(c.material);
  for (const auto& s : scene.solids) use(s.material);
  if (!scene.walls.empty()) use(scene.wall_material);
  double alpha = 0;
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    // Held solids are reset every step: their own diffusion needs no limit.
    if (used[i] && !m.held) alpha = std::max(alpha, m.conductivity / (m.density * m.specific_heat));
  }
  return alpha;
}

}  // namespace thaw
