#pragma once
// Scenes: JSON files in configs/ validated against one declared schema (sim/scene_schema.cpp).
// The schema — every field's name, type, unit, default, range and meaning — drives validation,
// error messages with JSON paths, `--set` overrides and docs/SCENES.md.
#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sim/geometry/shape.h"
#include "sim/kernels/liquidus.h"
#include "sim/schema.h"

namespace thaw {

struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();

  // The largest u . x over the box (at the corner u points to); -max_along(-u) is the smallest.
  double max_along(const Eigen::Vector3d& u) const {
    return u.dot(0.5 * (min + max)) + u.cwiseAbs().dot(0.5 * (max - min));
  }
};

// Choices of the scene file as enums at the host boundary. Each one's spellings are in one table below
// (Choices<E>), which the schema's choices, the scene loader and name() all read.
// Air: a fluid of its own phase (Domaradzki & Martyn sec. 6.1): it flows, conducts and carries heat, and
// never melts, freezes, exchanges heat with the ambient model or shows in the surface view.
enum class MaterialKind { Fluid, Solid, Ice, Air };
enum class KernelFunction { CubicSpline, WendlandC2 };
enum class Eos { Tait, Linear };
// The pressure solver: weakly compressible (an equation of state), or divergence-free SPH (Bender &
// Koschier 2015, 2017: sim/dfsph_stage.h).
enum class PressureSolver { Wcsph, Dfsph };
enum class BoundaryVolume { Lattice, Akinci2012 };
// DFSPH: the pressure boundary particles take in the solves (sim/kernels/dfsph.cl).
enum class DfsphBoundary { Adami2012, Akinci2012 };
// How fluids of several rest densities meet (dfsph, sim/kernels/dfsph.cl).
enum class Multiphase { HuAdams2006, DomaradzkiMartyn };
enum class SubstanceKind { Bulk, SurfaceActive, Coating };
// How a surface-active substance lowers the water's surface tension (sim/kernels/substance.cl): not at all,
// by Szyszkowski's law sigma0 + E ln(1 - Gamma / Gamma_max) (Langmuir's isotherm's own equation of state), or
// by its linear part sigma0 - E Gamma / Gamma_max.
enum class TensionLaw { None, Szyszkowski, Linear };
enum class ExposedArea { Iwasaki2010, Orthmann2013, Brackbill1992 };
// Interfacial tension (sim/tension_stage.h): none, Akinci et al. 2013's cohesion, curvature and adhesion, or
// Iwasaki et al. 2010's eq. 4.
enum class TensionModel { None, Akinci2013, Iwasaki2010, Brackbill1992 };
// How walls hold the fluid's tangential velocity: only through boundary_viscosity, or no-slip.
enum class NoSlip { None, Adami2012 };
// What a dryer is: an analytic cone of warm air that heats exposed ice and water (scenes without air
// particles), or a nozzle that blows air particles (scenes with `air`; sim/emitters.h).
enum class DryerModel { Cone, Air };
// Whether particles of this kind move with the fluid passes and carry their own mass (fluid and air).
inline bool flows(MaterialKind k) { return k == MaterialKind::Fluid || k == MaterialKind::Air; }
// A substance's liquidus with water (sim/kernels/liquidus.h): Blagden's dilute law, NaCl's measured table
// (CRC Handbook) to its eutectic, or the scene's own table.
enum class LiquidusLaw { Blagden, CrcNaCl, Table };

// How air's density follows its temperature. Boussinesq: the momentum equation keeps the density rho0
// except in the body force, rho0 g (1 - beta (T - T0)) (de Vahl Davis 1983's problem); the uniform part
// rho0 g only makes the air's own hydrostatic pressure, a few pascals, and is left out, so the air feels
// -beta (T - T0) g alone. IdealGas: Domaradzki & Martyn's eq 7, each air particle's rest density
// rho0(T) = rho0(0 °C) / (1 + theta T) follows its temperature (with theta = 1/273.15 K, Charles's law:
// the ideal gas at constant pressure) in the pressure solve's rest volumes (dfsph.cl), so warm air
// expands, and it feels its weight less that of air at T0, g (1 - rho0(T0) / rho0(T)) (the reference
// air's hydrostatic pressure left out as Boussinesq's is). None: air feels no gravity at all.
enum class Buoyancy { None, Boussinesq, IdealGas };

// Each choice's spellings in the scene file, in the order the schema lists them (the first is not always the
// default: the schema says which is).
template <class E>
struct Choices;
template <class E>
concept Choice = requires {
  Choices<E>::names;
};

template <>
struct Choices<MaterialKind> {
  static constexpr std::pair<MaterialKind, const char*> names[] = {{MaterialKind::Fluid, "fluid"},
                                                                   {MaterialKind::Solid, "solid"},
                                                                   {MaterialKind::Ice, "ice"},
                                                                   {MaterialKind::Air, "air"}};
};
template <>
struct Choices<KernelFunction> {
  static constexpr std::pair<KernelFunction, const char*> names[] = {
      {KernelFunction::CubicSpline, "cubic_spline"}, {KernelFunction::WendlandC2, "wendland_c2"}};
};
template <>
struct Choices<Eos> {
  static constexpr std::pair<Eos, const char*> names[] = {{Eos::Tait, "tait"}, {Eos::Linear, "linear"}};
};
template <>
struct Choices<PressureSolver> {
  static constexpr std::pair<PressureSolver, const char*> names[] = {{PressureSolver::Wcsph, "wcsph"},
                                                                     {PressureSolver::Dfsph, "dfsph"}};
};
template <>
struct Choices<BoundaryVolume> {
  static constexpr std::pair<BoundaryVolume, const char*> names[] = {{BoundaryVolume::Lattice, "lattice"},
                                                                     {BoundaryVolume::Akinci2012, "akinci"}};
};
template <>
struct Choices<DfsphBoundary> {
  static constexpr std::pair<DfsphBoundary, const char*> names[] = {
      {DfsphBoundary::Adami2012, "adami2012"}, {DfsphBoundary::Akinci2012, "akinci2012"}};
};
template <>
struct Choices<Multiphase> {
  static constexpr std::pair<Multiphase, const char*> names[] = {
      {Multiphase::HuAdams2006, "hu_adams2006"}, {Multiphase::DomaradzkiMartyn, "domaradzki_martyn"}};
};
template <>
struct Choices<SubstanceKind> {
  static constexpr std::pair<SubstanceKind, const char*> names[] = {
      {SubstanceKind::Bulk, "bulk"},
      {SubstanceKind::SurfaceActive, "surface_active"},
      {SubstanceKind::Coating, "coating"}};
};
template <>
struct Choices<TensionLaw> {
  static constexpr std::pair<TensionLaw, const char*> names[] = {
      {TensionLaw::Szyszkowski, "szyszkowski"}, {TensionLaw::Linear, "linear"}, {TensionLaw::None, "none"}};
};
template <>
struct Choices<ExposedArea> {
  static constexpr std::pair<ExposedArea, const char*> names[] = {
      {ExposedArea::Iwasaki2010, "iwasaki2010"},
      {ExposedArea::Brackbill1992, "brackbill1992"},
      {ExposedArea::Orthmann2013, "orthmann2013"}};
};
template <>
struct Choices<TensionModel> {
  static constexpr std::pair<TensionModel, const char*> names[] = {
      {TensionModel::None, "none"},
      {TensionModel::Akinci2013, "akinci2013"},
      {TensionModel::Iwasaki2010, "iwasaki2010"},
      {TensionModel::Brackbill1992, "brackbill1992"}};
};
template <>
struct Choices<NoSlip> {
  static constexpr std::pair<NoSlip, const char*> names[] = {{NoSlip::None, "none"},
                                                             {NoSlip::Adami2012, "adami2012"}};
};
template <>
struct Choices<DryerModel> {
  static constexpr std::pair<DryerModel, const char*> names[] = {{DryerModel::Cone, "cone"},
                                                                 {DryerModel::Air, "air"}};
};
template <>
struct Choices<LiquidusLaw> {
  static constexpr std::pair<LiquidusLaw, const char*> names[] = {
      {LiquidusLaw::Blagden, "blagden"}, {LiquidusLaw::CrcNaCl, "crc_nacl"}, {LiquidusLaw::Table, "table"}};
};
template <>
struct Choices<Buoyancy> {
  static constexpr std::pair<Buoyancy, const char*> names[] = {
      {Buoyancy::Boussinesq, "boussinesq"}, {Buoyancy::IdealGas, "ideal_gas"}, {Buoyancy::None, "none"}};
};

// A choice's spelling ("wendland_c2"), for messages, kernel build options and the state a scene is saved in.
template <Choice E>
constexpr const char* name(E e) {
  for (const auto& [value, spelling] : Choices<E>::names)
    if (value == e) return spelling;
  return "?";
}
// Every spelling of a choice, in the schema's order (the schema's list of it).
template <Choice E>
std::vector<std::string> choice_names() {
  std::vector<std::string> out;
  for (const auto& entry : Choices<E>::names) out.emplace_back(entry.second);
  return out;
}

struct Material {
  std::string name;
  MaterialKind kind = MaterialKind::Fluid;
  double density = 1000.0;     // rest density rho0 [kg/m^3]
  double viscosity = 0.0;      // dynamic viscosity mu [Pa s] (fluids)
  double conductivity = 0.0;   // k [W/m/K]
  double specific_heat = 0.0;  // c [J/kg/K]
  double latent_heat = 0.0;    // L [J/kg] of an ice and the fluid it melts into; 0 otherwise
  double melting_point = 0.0;  // T_m [°C] of the same pair
  double cryoscopic_constant =
      1.86;                  // K_f [K kg/mol] of a fluid: its melting point falls K_f i b (substances)
  int partner = -1;          // ice: the fluid it melts into; fluid: the ice it freezes into; -1 none
  bool transparent = false;  // solids: drawn as glass (the renderer's business only)
  bool adiabatic = false;    // solids: an ideal insulator (heat.cl, adiabatic_state)
  // Variants the scene loader adds (named "<material> (...)"): a solid held at a temperature, and the
  // tank walls when they exchange heat with the outside.
  bool held = false;
  double held_temperature = 0.0;  // [°C]
  bool wall_heat = false;
};

// The scene's air particles (`air`): a region filled on the particle lattice with an air material,
// except where fluid, ice or solids are.
struct AirFill {
  int material = -1;  // an air material (index into Scene::materials); -1: the scene has no air particles
  Box region;         // the domain unless given
  double temperature = 20.0;  // initial [°C]
  Buoyancy buoyancy = Buoyancy::Boussinesq;
  double reference_temperature = 20.0;  // T0 [°C]
  double expansion = 1.0 / 293.15;      // beta [1/K]; an ideal gas's 1 / (T0 + 273.15) unless given
  // Eq 7's theta [1/K] (IdealGas): rho0(T) = rho_material (1 + theta T0) / (1 + theta T), the material's
  // density being the air's at T0. 1/273.15: the ideal gas; the paper set 0.005 by experiment.
  double theta = 1.0 / 273.15;
  // Domaradzki & Martyn sec. 7 (Fig. 6): air within face_depth of a side of the domain that is not
  // periodic relaxes toward heat.ambient_temperature with time constant face_time, so a dryer does not
  // heat a closed room without end; booked as ambient exchange. face_time 0: off.
  double face_time = 0.0;   // [s]
  double face_depth = 0.0;  // [m]; the scene loader puts one kernel support for 0
  // Domaradzki & Martyn eq 8: an upward acceleration sigma / (T_max - T) on every air particle, on top of
  // its buoyancy; 0: off (the default: Boussinesq is the physical force, eq 8 is for comparison).
  double artificial_buoyancy = 0.0;  // sigma [K m/s^2]
  double max_temperature = 100.0;    // T_max [°C]
};

// A substance the water carries (issue 20; docs/SUBSTANCES.md): dissolved in the bulk of the water, moved
// with its particles and by Fick's diffusion between them (Cleary & Monaghan 1999's pairwise form, as
// Orthmann et al. 2013 sec. 5 carry their bulk quantities). Each particle holds its amount [kg].
struct Substance {
  std::string name;
  double diffusivity = 1e-9;  // D in water [m^2/s]
  // Its phase diagram with the water (sim/kernels/liquidus.h, docs/SUBSTANCES.md): how far below the water's
  // melting point a melt holding it at mass fraction w freezes. Blagden: the dilute law, each mole of it per
  // kg of water lowers the melting point by the fluid's cryoscopic constant times `dissociation` (molar_mass
  // 0: it lowers nothing, a dye), capped at kMaxMeltingPointDrop; CrcNaCl: NaCl's measured freezing points
  // to its eutectic (kCrcNaCl); Table: `liquidus_points`, the last the eutectic.
  LiquidusLaw liquidus = LiquidusLaw::Blagden;
  double molar_mass = 0.0;    // M [kg/mol]
  double dissociation = 1.0;  // van 't Hoff's factor i: ions per formula unit (NaCl 2)
  // (w, the depression there [K]) rising in both, from the scene (Table) or kCrcNaCl (CrcNaCl)
  std::vector<std::array<double, 2>> liquidus_points;
  // The most a melt dissolves, kg of it per kg of melt; past it the rest stays undissolved with the particle.
  // 0: unlimited.
  double solubility = 0.0;
  bool enters_ice = false;  // false: water that freezes gives it up to the water around it
  bool lowers_melting_point() const { return liquidus != LiquidusLaw::Blagden || molar_mass > 0; }
  // The largest depression its melt reaches [K]: its eutectic's T_m - T_e (kMaxMeltingPointDrop by
  // Blagden's law); 0 where it lowers nothing.
  double eutectic_depression() const;
  // A surface-active substance (Orthmann et al. 2013 sec. 5-6.2) also sits on the water's free surface, an
  // amount per particle over its surface area (a surface excess Gamma [kg/m^2]), exchanged with the bulk by
  // Langmuir's kinetics, dGamma/dt = k_a c (1 - Gamma / Gamma_max) - k_d Gamma, and diffusing along the
  // surface with D_s. A bulk one stays in the bulk.
  SubstanceKind kind = SubstanceKind::Bulk;
  double surface_diffusivity = 1e-9;  // D_s [m^2/s]
  double adsorption_rate = 1e-4;      // k_a [m/s]
  double desorption_rate = 0.1;       // k_d [1/s]
  double surface_capacity = 1.2e-6;   // Gamma_max [kg/m^2]; 0: unlimited (Henry's law)
  TensionLaw tension_law = TensionLaw::Szyszkowski;
  double tension_scale = 7.9e-3;  // E = R T Gamma_inf [N/m] (SDS at 25 °C: 3.2e-6 mol/m^2)
  bool surface_active() const { return kind == SubstanceKind::SurfaceActive; }
  bool lowers_tension() const { return surface_active() && tension_law != TensionLaw::None; }
  // A coating (Orthmann et al. 2013 sec. 6.3-6.4: paint, dye that stains, grease) also sticks to the solids
  // and ice the water touches, an amount per boundary particle over its face (a deposit Gamma_R [kg/m^2]):
  // dGamma_R/dt = k_c c (1 - Gamma_R / Gamma_R,max) - k_r c_D Gamma_R, c its concentration in the water
  // there and c_D that of the substance that cleanses it (a detergent), which takes it back into the water.
  double coating_rate = 1e-5;      // k_c, the deposition velocity [m/s]
  double coating_capacity = 1e-4;  // Gamma_R,max [kg/m^2]; 0: unlimited
  int cleanser = -1;               // index of the substance that cleanses it; -1: none
  double cleansing_rate = 0.0;     // k_r [m^3/(kg s)]
  bool coating() const { return kind == SubstanceKind::Coating; }
  // The colour a thick layer of it gives white light (sRGB, each in [0, 1]): how the surface view tints water
  // that holds it and solids and ice a coating of it stains.
  std::array<float, 3> colour = {0.78f, 0.08f, 0.30f};
};
inline constexpr int kMaxSubstances = 4;  // per scene: the stage walks the neighbours once for all of them

struct FluidBlock {
  int material = 0;  // index into Scene::materials
  Shape shape;       // filled with particles on a lattice of the scene's spacing (a box unless it says)
  Box box;           // the shape's bounding box
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  double temperature = 20.0;       // initial [°C]
  std::vector<double> substances;  // initial concentration of each of Scene::substances [kg/m^3]
};

struct IceBlock {
  // Fixed ice is held where it starts (its particles are anchored); free ice moves as a rigid body.
  enum class Motion { Fixed, Free };
  int material = 0;  // an ice material
  Shape shape;       // filled with particles on a lattice of the scene's spacing (sim/geometry/voxelize.h)
  Box box;           // the shape's bounding box
  Motion motion = Motion::Fixed;
  double temperature = 0.0;  // initial [°C], at most the melting point
};

struct Solid {
  int material = 0;    // a held solid's material is its held variant
  bool plane = false;  // the half-space behind a plane, rather than a shape
  Shape shape;         // !plane: the solid, sampled as boundary particles near its surface
  Box box;             // !plane: the shape's bounding box
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // plane: a point on the surface
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // plane: unit, points into the fluid
  double temperature = 20.0;                          // initial, or held [°C]
  // The deposit of each of Scene::substances on its outer layer at the start [kg/m^2] (coatings only: a
  // dirty plate's grease).
  std::vector<double> deposits;
};

struct Lamp {
  bool on = true;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = -Eigen::Vector3d::UnitZ();  // unit, the emitting side
  double width = 0.1, height = 0.1;                    // [m]
  double temperature = 500.0;                          // T_s [°C]
  double emissivity = 0.9;
  int photons = 4096;  // per step
};

struct Dryer {
  DryerModel model = DryerModel::Cone;
  bool on = true;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();  // unit
  double half_angle = 15.0;                               // [deg]
  double reach = 0.3;                                     // [m]
  double temperature = 60.0;                              // air at the nozzle [°C]
  double speed = 10.0;                                    // air at the nozzle [m/s]
  double nozzle_diameter = 0.04;                          // [m]
  // model air: the nozzle's area pi d^2 / 4 [m^2]
  double area() const;
  // An air dryer that is blowing now (on, at a positive speed).
  bool blows_air() const { return model == DryerModel::Air && on && speed > 0; }
};

// A nozzle that pours fluid (Iwasaki et al. 2010, Fig. 7): layers of particles on the disc of the nozzle,
// leaving it along `direction` at `speed`, spaced so that the mass flow is rho A v (sim/emitters.h).
struct Emitter {
  bool open = true;                                       // the tap: closed, it pours nothing
  int material = 0;                                       // a fluid (index into Scene::materials)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();     // centre of the nozzle [m]
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();  // unit, where the fluid leaves
  double radius = 0.005;                                  // of the nozzle [m]
  double speed = 0.5;                                     // exit speed [m/s]
  double temperature = 20.0;                              // of the fluid poured [°C]
  std::vector<double> substances;  // each of Scene::substances in what it pours [kg/m^3]; fixed while it runs
  double start = 0.0;              // pours from this time on [s]
  double stop = 0.0;               // and until this time [s]; 0: for ever
  // The nozzle's area pi r^2 [m^2] and the volume flow A v [m^3/s] it pours while open.
  double area() const;
  double volume_flow() const { return area() * speed; }
};

struct HeatSettings {
  bool enabled = true;
  double time_scale = 1.0;  // heat runs this much faster than the flow
  // Heat steps a flow step may hold: where conduction (times time_scale) limits the step, the heat pass
  // runs up to this many sub-steps at fixed positions and the flow takes the longer step.
  int max_substeps = 1;
  ExposedArea exposed_area = ExposedArea::Brackbill1992;
  int area_interval = 4;              // flow steps between the surface stage's area updates
  double ambient_temperature = 20.0;  // [°C]
  double ambient_coefficient = 10.0;  // h [W/m^2/K]
  double wall_coefficient = 0.0;      // U through the tank walls [W/m^2/K]
  double wall_temperature = 20.0;     // outside the tank [°C]
};

// The scene's `tension`: the model, the water-air tension sigma it is calibrated to, and the contact angles
// water makes on solids and on ice, which set the adhesion (Young-Dupre: W = sigma (1 + cos theta)).
struct TensionSettings {
  TensionModel model = TensionModel::None;
  double coefficient = 0.0756;        // sigma [N/m]: water-air at 0 °C
  bool curvature = true;              // akinci2013: its curvature term (eq. 5)
  double solid_contact_angle = 90.0;  // [deg]
  double ice_contact_angle = 12.0;    // [deg]: water on ice (Knight 1967)
  bool enabled() const { return model != TensionModel::None; }
};

struct SolverSettings {
  KernelFunction kernel = KernelFunction::CubicSpline;
  double support_ratio = 2.0;  // kernel support radius / particle spacing
  PressureSolver pressure = PressureSolver::Wcsph;
  double density_tolerance = 0.001;     // dfsph: mean (rho - rho0) / rho0 the density solve stops at
  double divergence_tolerance = 0.001;  // dfsph: mean (D rho / Dt) dt / rho0 the divergence solve stops at
  int max_pressure_iterations = 100;    // dfsph: per solve and step
  double pressure_relaxation = 0.5;     // dfsph: the relaxed Jacobi's omega (sim/kernels/dfsph.cl)
  bool divergence_warm_start = false;   // dfsph: the divergence solve starts from last step's kappa
  DfsphBoundary boundary_pressure = DfsphBoundary::Adami2012;  // dfsph: extrapolated, or none (one-sided)
  Multiphase multiphase = Multiphase::HuAdams2006;             // dfsph, air beside water
  Eos eos = Eos::Tait;
  double gamma = 7.0;                  // Tait exponent
  double speed_of_sound = 0.0;         // [m/s]; 0 = sound_speed_factor * reference_speed
  double sound_speed_factor = 10.0;    // c = factor * v_ref keeps density error near 1/factor^2
  double reference_speed = 0.0;        // [m/s]; 0 = sqrt(2 g H) from the tallest fluid block
  double artificial_viscosity = 0.02;  // Monaghan alpha
  double boundary_viscosity = 0.0;     // alpha against static solids (0 = free slip)
  NoSlip no_slip = NoSlip::None;       // adami2012: no-slip walls with the fluid's viscosity (forces.cl)
  // Lattice: dx^3; Akinci2012: Akinci 2012 eq. 4, 1 / sum_k W_bk.
  BoundaryVolume boundary_volume = BoundaryVolume::Lattice;
  double cfl = 0.4;               // dt <= cfl * h / (c + v_max)
  double viscous_number = 0.125;  // dt <= viscous_number * min(h, spacing)^2 / nu
  double force_number = 0.25;     // dt <= force_number * sqrt(h / a_max)
  double max_dt = 1e-3;           // [s] user cap
  double min_dt = 1e-8;           // [s] below this the run stops as blown up
  double max_speed = 0.0;         // [m/s]; 0 = 5 * c; faster particles stop the run as blown up
  double output_interval = 0.01;  // [s] metrics / export cadence in sim time
  bool flow = true;               // false: particles stay put, only heat flows
  std::array<bool, 3> periodic = {false, false, false};  // axes the domain wraps around (flow = false)
  double diffusion_number = 0.1;  // dt <= diffusion_number * h^2 / (time_scale * alpha_max)
};

// How a viewer first sees the scene (the schema's `camera`): an orbit about `target` [m] (the domain's
// centre when absent) at `azimuth` and `elevation` [deg], `distance` [m] away (0: the distance that frames
// the domain), with a vertical field of view `fov` [deg].
struct SceneCamera {
  double azimuth = 30.0, elevation = 25.0, distance = 0.0, fov = 40.0;
  std::optional<Eigen::Vector3d> target;
};

struct Scene {
  std::string name;
  std::string description;
  Box domain;                      // particles leaving it are clamped back and counted
  std::vector<std::string> walls;  // domain sides lined with solid: any of -x +x -y +y -z +z
  // Sides water leaves through (removed and counted as outflow), as bits: 1 -x, 2 +x, 4 -y, 8 +y, 16 -z,
  // 32 +z. The other sides hold particles at the face (clamped and counted).
  unsigned open_faces = 0;
  int wall_material = -1;  // material of the domain walls (index), -1 when there are none
  int wall_layers = 0;     // 0 = as many as hold water (wall_layer_count)
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  double spacing = 0.01;  // particle spacing [m]
  SolverSettings solver;
  std::vector<Material> materials;
  std::vector<FluidBlock> fluids;
  AirFill air;
  bool has_air() const { return air.material >= 0; }
  // How many dryers blow air particles (dryers[].model "air").
  std::size_t air_dryer_count() const;
  // Fluids of more than one rest density can meet: air beside water, or beside the water ice melts into.
  bool several_rest_densities() const;
  // The fluid passes are built with the number-density multiphase form (sim/kernels/dfsph.cl): where
  // fluids of several rest densities meet, and where the air's rest density follows its temperature
  // (air.buoyancy ideal_gas).
  bool multiphase() const;
  // Between the light fluids' rest densities and the heavy ones' (their geometric mean) where they differ
  // five-fold or more, else below them all (0 where there is one: nothing is light): the multiphase
  // passes tell air from water by it.
  double rest_density_split() const;
  // The rest densities of every fluid the scene has or makes (blocks, emitters, melted ice, air).
  std::vector<double> fluid_rest_densities() const;
  std::vector<IceBlock> ice;
  std::vector<Solid> solids;
  HeatSettings heat;
  TensionSettings tension;
  std::vector<Lamp> lamps;
  std::vector<Dryer> dryers;
  std::vector<Emitter> emitters;
  std::vector<Substance> substances;  // in the document's order; at most kMaxSubstances
  SceneCamera camera;
  Json source;  // the validated document with every default filled in
};

// NaCl in water, measured (CRC Handbook of Chemistry and Physics, "Concentrative properties of aqueous
// solutions"): the freezing-point depression [K] at each mass fraction, the last point the eutectic
// (-21.1 °C at 23.3 %), and its solubility at 0 °C, 26.3 % (35.7 g per 100 g of water).
inline constexpr std::array<std::array<double, 2>, 6> kCrcNaCl = {
    {{0.01, 0.593}, {0.05, 3.05}, {0.10, 6.56}, {0.15, 10.89}, {0.20, 16.46}, {0.233, 21.1}}};
inline constexpr double kCrcNaClSolubility = 0.263;

// How far below its material's melting point a fluid holding `concentrations` of the scene's substances
// [kg/m^3] melts [K]: each substance's liquidus at its mass fraction (liquidus.h), Blagden's law over the
// water for those that follow it, capped at the eutectic; 0 for other materials. The substance stage
// computes the same per particle (sim/kernels/substance.cl).
inline constexpr double kMaxMeltingPointDrop =
    40.0;  // [K]: Blagden's law's cap; past NaCl's eutectic the dilute law means nothing
double melting_point_drop(const Scene& s, int material, const std::vector<double>& concentrations);
// Each of the scene's substances' phase diagram as the kernels read it (kMaxSubstances entries; those past
// the scene's substances lower nothing).
std::vector<thermal::Liquidus> liquidus_table(const Scene& s);
// The most of substance k that `concentrations` of fluid `material` may hold in solution [kg/m^3]: its
// solubility times the fluid's density; infinity where unlimited.
double most_dissolved(const Scene& s, int material, std::size_t k);

// A number as messages show it: the shortest form ("0.004", "1100", "1e-09").
std::string format_number(double v);

// One converter each way per live struct, shared by the scene loader, the solver's live setters and the
// service's replies. *_from_json takes an element the schema has validated (validate() fills the
// defaults) and refuses a zero or overflowing direction, naming `path` ("dryers[0]").
Json to_json(const Dryer& d);
Json to_json(const Lamp& l);
Dryer dryer_from_json(const Json& j, const std::string& path);
Lamp lamp_from_json(const Json& j, const std::string& path);
// An emitter names its material: to_json writes the name, emitter_from_json looks it up among `materials`
// (a fluid; SceneError at PATH.material otherwise) and takes the exit speed from `rate` [L/s] when the
// element gives one instead of `speed`.
Json to_json(const Emitter& e, const std::vector<Material>& materials);
Emitter emitter_from_json(const Json& j, const std::string& path, const std::vector<Material>& materials);
// What an emitter needs of the scene: a nozzle at least one spacing wide whose whole disc lies inside the
// domain (SceneError at PATH.radius or PATH.position), and not inside a solid or ice (PATH.position).
struct Scene;
void check_emitter(const Emitter& e, const Scene& scene, const std::string& path);
// What a dryer needs of the scene: a cone dryer, no air particles (they would carry its heat twice); an
// air dryer, the scene's air to blow, a nozzle at least two spacings wide and inside the domain (SceneError
// at PATH.model, PATH.nozzle_diameter or PATH.position).
void check_dryer(const Dryer& d, const Scene& scene, const std::string& path);
inline constexpr int kMaxAirDryers = 64;  // a scene's air dryers at most (their intake flags are bytes)
// A scene's lamps, dryers and emitters at most, each (the protocol addresses them by an index below this).
inline constexpr int kMaxAddressable = 64;

// `v` scaled to unit length; `path` names it in the SceneError when it is not a vector of moderate size:
// zero, or so long or so short that its squared length overflows or underflows a double. The protocol
// refuses the same vectors: [1e308, 1e308, 1e308] normalised to zeros, and the dryer delivered 0 J.
Eigen::Vector3d unit_direction(const Eigen::Vector3d& v, const std::string& path);

// Memory a run of `particles` particles needs [bytes]: 300 MB for the program, the OpenCL compiler and
// its kernels, and 360 bytes a particle. Measured with `thaw run dam-break --steps 2` on pocl: maximum
// RSS 363 MB at 335,072 particles and 936 MB at 2,132,512, i.e. 326 bytes a particle and 254 MB besides;
// heat's buffers add about 30 more a particle.
double estimated_memory_bytes(double particles);

// The memory a scene may use [bytes]: THAW_MEMORY_LIMIT when set ("16G", "800M", "123456" bytes; "off":
// no limit, +inf), else MemAvailable from /proc/meminfo (+inf where that cannot be read). Throws Error on
// a malformed THAW_MEMORY_LIMIT.
double memory_limit_bytes();

// The most particles a run may hold: 20 million, or as many as memory_limit_bytes() leaves room for
// (estimated_memory_bytes), whichever is fewer.
double particle_limit();

// Layers of particles in the domain walls and sampled solids: domain.wall_layers, or as many as hold water
// resting on them: one more than the support ratio above 2 spacings (4 at 3), else the ratio rounded up.
int wall_layer_count(const Scene& s);

// Loads a scene file: reads, applies `--set` overrides, validates, converts.
// Throws SceneError (with a JSON path) or Error (missing/unreadable file).
Scene load_scene(const std::string& file, const std::vector<std::string>& overrides = {});

// Same from an in-memory document (used by validation cases and tests). A relative `mesh` path is looked
// for in `folder` (the scene file's; empty: the working directory), then in configs/ of the source tree;
// the Scene's `source` holds the path it was found at.
// Refuses a scene whose fluids of several rest densities meet under a solver without a multiphase form,
// at solver.pressure.
void check_multiphase(const Scene& scene);

// Domaradzki & Martyn eq 7 (air.buoyancy ideal_gas): the rest density of `air` of a material of this
// density (the air's at air.reference_temperature) at `temperature` [°C].
double ideal_gas_rest_density(double material_density, const AirFill& air, double temperature);
// The rest density of a new particle of fluid `material` at `temperature`: the material's, or eq 7's for
// the scene's air when its buoyancy is ideal_gas. New particles (the fill, the emitters, the room's air)
// weigh this times dx^3, so that they start at rest on the lattice.
double rest_density_at(const Scene& scene, int material, double temperature);

Scene scene_from_json(Json doc, const std::vector<std::string>& overrides = {},
                      const std::string& folder = "");

// Applies one "path=value" override; value is JSON, or a bare string when it is not valid JSON.
// Paths: "solver.cfl", "fluids[0].box.max", "fluids.0.box.max", "gravity[2]".
void apply_override(Json& doc, const std::string& assignment);

// The same for a document of another schema (a validation case's parameters): keys the document
// leaves out start from `schema`'s defaults.
void apply_override(Json& doc, const std::string& assignment, const Field& schema);

// Markdown reference of the scene format, generated from the schema (docs/SCENES.md).
std::string scene_reference_markdown();

// Resolves a scene name: a path as given, else configs/NAME(.json) under the source tree.
// Throws Error naming the file and every place it looked.
std::string resolve_scene_path(const std::string& name);

// The declared scene format (sim/scene_schema.cpp), and its "solver" section on its own so that a
// validation case can embed it in its own parameter object.
const Field& scene_schema();
const Field& solver_schema();

// A field of ice and solid entries that several shapes take, such as `radius`. The schema ties a field to
// one value of `shape` only, so these are declared optional there and checked against this list when the
// scene converts (with the schema's messages: "only allowed when shape is ...", "missing: required ...").
struct SharedShapeField {
  std::string key;
  std::vector<std::string> shapes;  // the shapes that take it
  bool required = true;             // by those shapes
};
const std::vector<SharedShapeField>& shared_shape_fields();

// The typed settings of a "solver" object that has passed validate() against solver_schema().
SolverSettings solver_settings_from_json(const Json& solver);

// A small valid scene document: the example in docs/SCENES.md.
std::string scene_example_json();

// Reads a JSON file (comments allowed); a syntax error is an Error with file, line and column.
Json read_json_file(const std::string& file);

}  // namespace thaw
