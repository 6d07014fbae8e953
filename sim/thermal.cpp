#include "sim/thermal.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "sim/emitters.h"
#include "sim/solver_constants.h"
#include "sim/substance_stage.h"

namespace thaw {

namespace {

// The thermal law of one material: specific heats on each side of the melting point, latent heat and
// melting point. An ice and the fluid it melts into share L and T_m, and each side's c is the c of the
// material that is on that side; materials without a phase change have L = 0 and T_m = 0.
struct Law {
  double c_solid, c_liquid, latent = 0, melt = 0;
  bool ice = false;
};

Law law_of(const Scene& scene, int material) {
  const Material& m = scene.materials[static_cast<std::size_t>(material)];
  Law law{m.specific_heat, m.specific_heat};
  if (m.partner >= 0) {
    const Material& other = scene.materials[static_cast<std::size_t>(m.partner)];
    law.ice = m.kind == MaterialKind::Ice;
    law.c_solid = law.ice ? m.specific_heat : other.specific_heat;
    law.c_liquid = law.ice ? other.specific_heat : m.specific_heat;
    law.latent = m.latent_heat;
    law.melt = m.melting_point;
  }
  return law;
}

}  // namespace

double mass_scale(const Material& m, double rest_density) {
  return flows(m.kind) ? 1.0 : m.density / rest_density;
}

std::vector<MaterialThermal> material_thermal_table(const Scene& scene, double rest_density) {
  std::vector<MaterialThermal> table;
  const double dx = scene.spacing;
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    const Law law = law_of(scene, static_cast<int>(i));
    MaterialThermal t{};
    t.k_solid = t.k_liquid = static_cast<float>(m.conductivity);
    t.c_solid = static_cast<float>(law.c_solid);
    t.c_liquid = static_cast<float>(law.c_liquid);
    t.latent = static_cast<float>(law.latent);
    t.melt = static_cast<float>(law.melt);
    t.partner = m.partner;
    if (m.partner >= 0) {
      const Material& other = scene.materials[static_cast<std::size_t>(m.partner)];
      t.k_solid = static_cast<float>(law.ice ? m.conductivity : other.conductivity);
      t.k_liquid = static_cast<float>(law.ice ? other.conductivity : m.conductivity);
      t.flags |= law.ice ? THAW_MAT_MELTS : THAW_MAT_FREEZES;
    }
    t.thermal_mass_scale = static_cast<float>(mass_scale(m, rest_density));
    // The ambient model stands for air that is not there as particles (plan_heat: off where it is).
    if (m.kind == MaterialKind::Fluid || m.kind == MaterialKind::Ice) t.flags |= THAW_MAT_AIR_EXCHANGE;
    if (m.adiabatic) {
      // Its T and k are those of what is around it (heat.cl, adiabatic_state); it keeps its own enthalpy,
      // the heat its mirrored temperature exchanges booked as `held`.
      t.flags |= THAW_MAT_ADIABATIC;
    }
    if (m.held) {
      t.flags |= THAW_MAT_HELD;
      t.held_enthalpy = static_cast<float>(enthalpy_at(scene, static_cast<int>(i), m.held_temperature));
    }
    if (m.wall_heat) {
      // U A (T_out - T) through the outer face, shared by the layers of wall behind each dx^2 of it.
      t.flags |= THAW_MAT_WALL_HEAT;
      t.wall_coefficient =
          static_cast<float>(scene.heat.wall_coefficient * dx * dx / std::max(wall_layer_count(scene), 1));
      t.wall_temperature = static_cast<float>(scene.heat.wall_temperature);
    }
    table.push_back(t);
  }
  return table;
}

double enthalpy_at(const Scene& scene, int material, double temperature) {
  const Law law = law_of(scene, material);
  // Ice is on its solid side at its melting point; everything else on its liquid side.
  return thermal::thermal_enthalpy(temperature, law.ice ? 0 : 1, law.latent, law.melt, law.c_solid,
                                   law.c_liquid);
}

double temperature_at(const MaterialThermal& m, double h, double shift) {
  if (shift > 0 && m.latent > 0)
    return thermal::thermal_temperature_lowered(h, m.latent, m.melt, m.c_solid, m.c_liquid, shift);
  return thermal::thermal_temperature(h, m.latent, m.melt, m.c_solid, m.c_liquid);
}

double liquid_fraction_at(const MaterialThermal& m, double h, double shift) {
  if (shift > 0 && m.latent > 0)
    return thermal::thermal_liquid_fraction_lowered(h, m.latent, m.c_solid, m.c_liquid, shift);
  return thermal::thermal_liquid_fraction(h, m.latent);
}

std::vector<double> melt_shifts_of(const HostParticles& p, const Scene& scene) {
  std::vector<double> out;
  const HostColumn* c = p.column(kMeltShiftField);
  if (!substances_lower_melting(scene) || !c || c->size() != p.size()) return out;
  out.assign(c->as<float>(), c->as<float>() + p.size());
  return out;
}

std::vector<float> temperatures_of(const HostParticles& p, const Scene& scene) {
  std::vector<float> out;
  if (!scene.heat.enabled || p.enthalpy.size() != p.size()) return out;
  const auto table = material_thermal_table(scene, derive_constants(scene).rest_density);
  const std::vector<double> shift = melt_shifts_of(p, scene);
  out.reserve(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    out.push_back(static_cast<float>(temperature_at(table[p.material[i]],
                                                    double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]),
                                                    shift.empty() ? 0.0 : shift[i])));
  return out;
}

namespace {

// The lowest melting point of the scene's ice materials [°C] (infinity without ice).
double scene_min_melting_point(const Scene& scene) {
  double t = std::numeric_limits<double>::infinity();
  for (const Material& m : scene.materials)
    if (m.kind == MaterialKind::Ice) t = std::min(t, m.melting_point);
  return t;
}

}  // namespace

HeatPlan plan_heat(const Scene& scene, const HostParticles& p) {
  HeatPlan plan;
  if (!scene.heat.enabled) {
    plan.reason = "heat.enabled is false";
    return plan;
  }
  // Cone dryers only: an air dryer's heat comes in with the air it blows (booked as inflow).
  plan.dryers = std::any_of(scene.dryers.begin(), scene.dryers.end(),
                            [](const Dryer& d) { return d.model == DryerModel::Cone; });
  plan.lamps = !scene.lamps.empty();
  const bool wall_heat = std::any_of(scene.materials.begin(), scene.materials.end(),
                                     [](const Material& m) { return m.wall_heat; });
  plan.walls = wall_heat && scene.heat.wall_coefficient > 0;
  // Air particles carry the air's heat themselves: the ambient model, which stands for the air, is off.
  plan.ambient = scene.heat.ambient_coefficient > 0 && !scene.has_air();
  plan.air_faces = scene.has_air() && scene.air.face_time > 0;
  // The adiabatic pass only where a solid or the walls are of such a material (not merely declared).
  auto adiabatic = [&](int m) { return m >= 0 && scene.materials[static_cast<std::size_t>(m)].adiabatic; };
  plan.adiabatic =
      adiabatic(scene.wall_material) || std::any_of(scene.solids.begin(), scene.solids.end(),
                                                    [&](const Solid& s) { return adiabatic(s.material); });

  // Temperatures differ by round-off only when each came from the same temperature through a float
  // enthalpy pair: a thousandth of a millikelvin is no difference.
  constexpr double kSame = 1e-6;
  // What emitters pour counts as though it were there already (a closed tap may open).
  std::vector<float> T = temperatures_of(p, scene);
  for (const Emitter& e : scene.emitters) T.push_back(static_cast<float>(e.temperature));
  for (const Dryer& d : scene.dryers)
    if (d.model == DryerModel::Air) T.push_back(static_cast<float>(d.temperature));
  // So does the room's air that open sides let in, at the ambient temperature (sim/emitters.h). Left out,
  // air at 25 °C beside a 20 °C room built no heat, and the room's air came in at 20 °C's mass
  // (rest_density_at) into a flow table that holds 25 °C's rest density for every air particle.
  if (EmitterStage::admits_room_air(scene)) T.push_back(static_cast<float>(scene.heat.ambient_temperature));
  const auto [lo, hi] = std::minmax_element(T.begin(), T.end());
  const bool spread = !T.empty() && double(*hi) - double(*lo) > kSame;
  auto differs = [&](double outside) {
    return !T.empty() && (std::abs(double(*lo) - outside) > kSame || std::abs(double(*hi) - outside) > kSame);
  };
  std::ostringstream why;
  if (plan.dryers) {
    why << "the scene has dryers";
  } else if (scene.air_dryer_count() > 0) {
    why << "the scene has an air dryer (its temperature can be set live)";
  } else if (plan.lamps) {
    why << "the scene has lamps";
  } else if (spread) {
    why << "temperatures range from " << *lo << " to " << *hi << " °C";
  } else if (substances_lower_melting(scene) && !T.empty() && double(*lo) < scene_min_melting_point(scene)) {
    // Brine below the ice's melting point melts it, and cools as it does.
    why << "dissolved substances lower the melting point below the " << *lo << " °C the scene starts at";
  } else if (plan.ambient && differs(scene.heat.ambient_temperature)) {
    why << "the ambient air is at " << scene.heat.ambient_temperature << " °C";
  } else if (plan.air_faces && differs(scene.heat.ambient_temperature)) {
    why << "the air exchanges heat with the ambient at " << scene.heat.ambient_temperature
        << " °C near the sides";
  } else if (plan.walls && differs(scene.heat.wall_temperature)) {
    why << "the tank walls' outside is at " << scene.heat.wall_temperature << " °C";
  } else {
    why << "no heat: every particle is at " << (T.empty() ? 0.0 : double(*lo))
        << " °C and nothing heats or cools it";
    plan.reason = why.str();
    plan.ambient = plan.walls = plan.air_faces = false;
    return plan;
  }
  plan.build = true;
  plan.reason = why.str();
  return plan;
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
  for (const auto& e : scene.emitters) use(e.material);
  if (scene.has_air()) use(scene.air.material);
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
