#pragma once
// The host side of the heat model: each material's thermal law for the device (sim/kernels/thermal_law.h),
// and conversions between temperature and the enthalpy a particle carries.
#include <string>
#include <vector>

#include "sim/kernels/thermal_law.h"
#include "sim/particles.h"
#include "sim/scene.h"

namespace thaw {

using thermal::MaterialThermal;

// One entry per Scene::materials, in order; rest_density is the fluid's rho0, which sets the SPH mass
// of static particles (solids and ice carry rho0 V, their physical mass is rho V).
std::vector<MaterialThermal> material_thermal_table(const Scene& scene, double rest_density);

// A particle's physical mass over its SPH mass, per material: fluid particles carry their physical mass;
// static ones (solids, ice) the rest-density mass rho0 V that the fluid solver needs from a boundary
// particle. The thermal table's and the rigid bodies' masses both come from this.
double mass_scale(const Material& m, double rest_density);

// Specific enthalpy [J/kg] of a particle of `material` at temperature T [°C] (ice below or at its melting
// point is solid, everything else is on its liquid side).
double enthalpy_at(const Scene& scene, int material, double temperature);

// Temperature [°C] and liquid fraction from a particle's enthalpy (thermal_law.h, in double); `shift` [K]
// lowers the melting point of a material that changes phase (dissolved substances: thermal_law.h's
// thermal_temperature_lowered).
double temperature_at(const MaterialThermal& m, double enthalpy, double shift = 0.0);
double liquid_fraction_at(const MaterialThermal& m, double enthalpy, double shift = 0.0);

// How far below its material's melting point each particle melts [K] where the scene's substances lower it
// (docs/SUBSTANCES.md): the particles' "melt_shift" column, which sampled scenes, solvers and state files
// carry; empty where nothing lowers it or the particles carry no such column.
std::vector<double> melt_shifts_of(const HostParticles& p, const Scene& scene);

// Temperatures [°C] of a particle set (e.g. read from a state file), one per particle, with their melt
// shifts; empty when the scene has no heat or the particles carry no enthalpy.
std::vector<float> temperatures_of(const HostParticles& p, const Scene& scene);

// Thermal diffusivity k / (rho c) of the most diffusive material [m^2/s] that some particle has or can
// turn into (held solids excepted): it sets the diffusion time-step limit.
double max_diffusivity(const Scene& scene);

// Which parts of the heat stage a run builds. Heat is built only when something can make temperatures
// differ or change: particles at different temperatures, air or tank walls at another temperature than
// the particles they touch, or a heat source a user may switch on during the run (a dryer or a lamp, on
// or off). Each source is compiled into the heat pass only when the scene has it. An isothermal scene
// (a dam break at 20 °C in 20 °C air) builds no heat at all: no enthalpy sort, no heat pass, no read-back.
struct HeatPlan {
  bool build = false;      // the heat stage at all
  bool ambient = false;    // exchange with the ambient air (heat.ambient_coefficient > 0)
  bool dryers = false;     // the scene has dryers
  bool walls = false;      // tank walls exchange heat with the outside (heat.wall_coefficient > 0)
  bool lamps = false;      // the scene has lamps (the photon grid is built once one is on)
  bool adiabatic = false;  // the scene has adiabatic solids (their mirrored temperatures: heat.cl)
  bool air_faces = false;  // air relaxes toward the ambient near the sides (air.face_exchange_time > 0)
  std::string reason;      // why heat is built or not, in words, for `thaw run`'s list of stages
};
HeatPlan plan_heat(const Scene& scene, const HostParticles& particles);

// Kelvin offset of the Celsius scale, for radiation.
inline constexpr double kKelvin = 273.15;

}  // namespace thaw
