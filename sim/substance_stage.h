#pragma once
// The substance stage (issue 20, docs/SUBSTANCES.md): substances dissolved in the water, each water
// particle holding its amount of each as a field "substance_<name>" (kg, a compensated pair hi + lo), carried
// by the flow and diffused between water particles by Fick's law in Cleary & Monaghan's pairwise form
// (sim/kernels/substance.cl), conserving each substance's total to round-off. Built by the solver only when
// the scene declares substances.
#include <CL/opencl.hpp>
#include <string>
#include <vector>

#include "sim/cl_runtime.h"
#include "sim/kernels/substance_params.h"
#include "sim/particle_store.h"
#include "sim/scene.h"
#include "sim/stage.h"

namespace thaw {

struct SolverConstants;

// The field that holds each particle's amount of substance `name` [kg]: two floats (hi, lo), saved; the VTU
// export shows it as the mass fraction, amount over the particle's mass (sim/particle_export.cpp).
FieldSpec substance_field(const std::string& name);
inline constexpr const char* kSubstancePrefix = "substance_";
inline constexpr const char* kMeltShiftField = "melt_shift";
// The field of each particle's melt shift [K] where the scene's substances lower the melting point
// (substances_lower_melting): saved, so partly melted ice resumes from its last shift, and exported.
FieldSpec melt_shift_field();
// The field of each particle's amount of surface-active substance `name` on the free surface [kg] (two
// floats, hi + lo), saved; the VTU export shows it as the surface excess, amount over the particle's area.
inline constexpr const char* kAdsorbedPrefix = "adsorbed_";
FieldSpec adsorbed_field(const std::string& name);
// The field of each solid or ice particle's deposit of coating `name` [kg] (two floats, hi + lo), saved; the
// VTU export shows the amount [kg] (over the spacing squared, the deposit per area).
inline constexpr const char* kDepositedPrefix = "deposited_";
FieldSpec deposited_field(const std::string& name);
// A solid or ice particle takes deposits over a face of a spacing squared once this share of its kernel's
// volume is water; less wetted, over that share of it. The first boundary layer under a flat, lattice-
// sampled pool has 0.128 of its volume in water (Wendland C2, support 2 spacings), the second none.
inline constexpr double kWetFraction = 0.1;
// Whether the scene's surface-active substances lower its surface tension: some has a tension_law, and the
// scene has flow and tension. The substance stage then keeps each water particle's tension over the scene's,
// sigma_i / sigma0, in the field kTensionRatioField (1 off the surface; saved), and the tension stage reads
// it.
bool substances_lower_tension(const Scene& scene);
inline constexpr const char* kTensionRatioField = "tension_ratio";
FieldSpec tension_ratio_field();
// Whether some substance of the scene is a coating: then boundary particles hold deposits.
bool substances_coat(const Scene& scene);

// A water particle with more surface area than this many spacings squared is a surface particle and holds
// surface-active substances on the surface; one with less hands them to its bulk.
inline constexpr double kSurfaceMinArea = 0.05;
// Where a surface particle's point on the surface lies: this many spacings out along its normal. A flat
// face's outer layer lies half a spacing inside its surface, a lattice sphere's outer particles anywhere
// from 0 to 1 spacing; on surface-diffusion, half a spacing made the decay 5-7 % slow, none 2-8 % fast,
// a quarter within 3 % from res 6 to 20 (docs/SUBSTANCES.md). Measured, not derived.
inline constexpr double surface_depth_spacings = 0.25;
// Whether some substance of the scene is surface-active: then the solver builds the surface stage for it.
bool substances_need_surface(const Scene& scene);
// The surface stage's fields the substance stage reads.
struct SurfaceFields {
  ParticleStore::Field area = 0, normal = 0;
};

// Whether the scene's substances lower the melting point where it matters: some substance has a molar mass,
// and some water can melt from or freeze into ice. The heat stage then reads the substance stage's melt
// shift (heat.cl, THAW_MELT_SHIFT).
bool substances_lower_melting(const Scene& scene);
// Whether water that freezes gives substances up: some substance does not enter ice, and the scene has ice
// for water to freeze into.
bool substances_rejected_by_ice(const Scene& scene);

// Gives particles their substances: each particle of range b, [first_of[b], first_of[b + 1]), the
// concentrations[b] of each substance [kg/m^3] times its volume (mass over its material's rest density);
// particles past the ranges none. For the fluid blocks a scene samples and what its emitters pour.
void add_substance_columns(HostParticles& p, const Scene& scene, const std::vector<std::size_t>& first_of,
                           const std::vector<std::vector<double>>& concentrations);
// Gives the scene's coatings their deposit fields: each (particle, solid) of `outer`, the particles of a
// solid's outer layer, that solid's deposits [kg/m^2] times the spacing squared; every other particle none.
void add_deposit_columns(HostParticles& p, const Scene& scene,
                         const std::vector<std::pair<std::size_t, std::size_t>>& outer);

class SubstanceStage {
 public:
  // `scene` must outlive the stage (the solver's own copy). `enthalpy`: the heat stage's field, null without
  // heat (then nothing melts or freezes, and neither the melt shift nor ice giving substances up is built).
  // `surface`: the surface stage's area and normal fields, which scenes with surface-active substances
  // need (substances_need_surface); null otherwise.
  SubstanceStage(const StageContext& c, const ParticleStore::Field* enthalpy, const SurfaceFields* surface);

  // The amount field of each of the scene's substances, in its order.
  const std::vector<ParticleStore::Field>& fields() const { return fields_; }
  // The fields that hold substance s, which all count to its total: its amount in the bulk, on the surface
  // for a surface-active one, and on solids and ice for a coating.
  std::vector<ParticleStore::Field> amount_fields(std::size_t s) const;

  // The diffusion's limit on dt [s]: solver.diffusion_number h^2 / D of the fastest substance.
  double max_dt() const { return max_dt_; }

  // Before the heat pass: each particle's mass fraction, and where substances lower the melting point, its
  // melt shift (ice's from the water around it); with ice that water froze into, what that ice gives up.
  void prepare(const NeighbourView& nv);
  // After the heat pass: diffuses every substance over a step of dt, and hands what freezing ice gives up
  // to the water around it.
  void diffuse(double dt, const NeighbourView& nv);

  // Whether this run lowers melting points: substances that do and the heat stage to read them (heat.cl's
  // THAW_MELT_SHIFT). Then melt_shift() is the field [K] that prepare() renews before the heat pass.
  bool lowers_melting() const { return lowers_; }
  ParticleStore::Field melt_shift() const { return shift_; }
  // The melt shift of each particle as the last prepare() left it [K]; empty unless lowers_melting().
  std::vector<float> melt_shifts() const;

  // The field of sigma_i / sigma0 (substances_lower_tension), renewed by diffuse(); 0 without one.
  ParticleStore::Field tension_ratio() const { return ratio_; }

  // Each substance's total over all particles [kg], summed in double from the device's pairs.
  std::vector<double> totals() const;
  // Where each substance is [kg]: dissolved in the water, on its free surface, stuck to solids and ice.
  // What it holds of each substance [kg]: in the bulk of the water (`dissolved`, as the books name it), on
  // the free surface, on solids; and, once a step has split them (`split`), how much of the bulk amount is
  // undissolved (past the melt's solubility, or held by ice with no melt) and the highest mass fraction any
  // melt holds.
  struct Parts {
    double dissolved = 0, on_surface = 0, on_solids = 0;
    bool split = false;
    double undissolved = 0, most_fraction = 0;
  };
  std::vector<Parts> parts() const;

 private:
  ClRuntime& cl_;
  ParticleStore& store_;
  CoreFields core_;
  const Scene& scene_;
  const ParticleLayout& layout_;  // the solver's: the particle count changes when water leaves
  std::vector<ParticleStore::Field> fields_;
  std::vector<double> diffusivity_;
  double max_dt_ = 0;
  substance::SubstanceParams params_{};
  bool ice_pass_ = false;  // substance_ice is built: the melt shift or ice giving substances up
  bool lowers_ = false, has_shift_ = false;  // THAW_MELT_SHIFT is built; the melt_shift field is declared
  cl::Kernel k_state_, k_ice_, k_diffuse_;
  ParticleStore::Field shift_ = 0, enthalpy_ = 0;
  // Surface-active substances (THAW_SURFACE): their adsorbed fields by substance (-1: none), the surface
  // stage's fields, and each one's rates [1/s, m/s] for the step's constants.
  bool surface_ = false;
  double sigma2_over_h4_ = 0, rest_density_ = 0;
  std::vector<int> adsorbed_;
  std::vector<ParticleStore::Field> adsorbed_fields_;
  SurfaceFields surface_fields_;
  cl::Kernel k_norm_;
  const cl::Buffer& on_surface(std::size_t s) const;  // substance s's adsorbed field, or any past the last
  // Coatings (THAW_DEPOSIT): their deposit fields by substance (-1: none).
  bool deposit_ = false;
  std::vector<int> deposited_;
  std::vector<ParticleStore::Field> deposited_fields_;
  cl::Kernel k_wet_, k_cells_, k_around_;
  // A byte per grid cell (substance_cells): what it holds, what the cells around it hold.
  cl::Buffer held_cells_, around_cells_;
  std::size_t cell_count_ = 0;
  bool lowers_tension_ = false;  // THAW_TENSION_LAW
  ParticleStore::Field ratio_ = 0;
  const cl::Buffer& on_solids(std::size_t s) const;  // substance s's deposit field, or any past the last
  cl::Buffer sub_, fluid_, law_, liquidus_;
  std::vector<thermal::Liquidus> liquidus_table_;
  bool split_ =
      false;  // prepare has run: the M and W blocks hold each particle's melt and dissolved fractions
  std::size_t split_n_ = 0;                       // the particles it ran over
  const cl::Buffer& amount(std::size_t s) const;  // substance s's field, or the first's past the last
};

}  // namespace thaw
