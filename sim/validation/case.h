#pragma once
// Validation cases: a scene built from the case's parameters plus the formula of its reference.
// Every reference is computed from the parameters, so any of them can be changed with --set.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "sim/cl_runtime.h"
#include "sim/scene.h"
#include "sim/schema.h"

namespace thaw {

struct MetricResult {
  double value = 0, reference = 0, error = 0, gate = 0;
  bool passed() const { return error <= gate; }
};

struct CaseResult {
  std::string name;
  int res = 0;
  std::size_t particles = 0;
  std::uint64_t steps = 0;
  double wall_s = 0;
  std::vector<std::pair<std::string, MetricResult>> metrics;
  bool passed() const;
  Json to_json() const;
};

struct ValidationCase {
  std::string name;
  std::string summary;
  int default_res;                // particles across the characteristic length
  std::function<Field()> params;  // the case's parameter document (may embed solver_schema())
  std::function<CaseResult(ClRuntime&, const Json& params, int res)> run;
};

const std::vector<ValidationCase>& validation_cases();
const ValidationCase& find_case(const std::string& name);  // throws Error listing the cases

// Applies --set overrides to the case's parameters, validates them (errors name the path) and runs.
CaseResult run_validation(ClRuntime& cl, const std::string& name, int res,
                          const std::vector<std::string>& overrides);

// A case run twice from the start, each run stopped after `steps` steps of any solver it makes (0: run
// whole): `first` is the first run's result (without metrics where it stopped; `steps` the most any solver
// took, `wall_s` both runs'), `difference` where the second run's solver states (sim/run_digest.h) or metrics
// first differ from the first's, "" where they agree bit for bit.
struct Repeated {
  CaseResult first;
  std::string difference;
};
Repeated run_validation_twice(ClRuntime& cl, const std::string& name, int res,
                              const std::vector<std::string>& overrides, std::uint64_t steps);

// The parameter document of a case after overrides and defaults.
Json case_parameters(const ValidationCase& c, const std::vector<std::string>& overrides);

// The cases, one file each.
ValidationCase hydrostatic_case();
ValidationCase dam_break_case();
ValidationCase conduction_case();
ValidationCase stefan_case();
ValidationCase rigid_spin_case();
ValidationCase floating_case();
ValidationCase cavity_case();
ValidationCase jet_case();
ValidationCase air_sphere_case();
ValidationCase air_water_case();
ValidationCase surface_area_case();
ValidationCase ambient_sphere_case();
ValidationCase laplace_case();
ValidationCase drop_oscillation_case();
ValidationCase contact_angle_case();
ValidationCase diffusion_bulk_case();
ValidationCase brine_melting_case();
ValidationCase brine_freezing_case();
ValidationCase conservation_case();
ValidationCase adsorption_case();
ValidationCase surface_diffusion_case();
ValidationCase coating_case();
ValidationCase cleansing_case();
ValidationCase marangoni_case();

// A scene of ice held in still air, for the surface cases (sim/validation/surface_area.cpp): the cube
// [-half, half]^3 at spacing dx without gravity, the ambient at air_temperature through h, heat.exposed_area
// `model`, the materials "ice" (density, conductivity, specific_heat and latent_heat from `ice`, melting at
// 0 °C) and the "water" it melts into; `ice_object` is its one ice entry.
Json ice_in_air_scene(const std::string& name, double half, double dx, const Json& solver, double h,
                      double air_temperature, const Json& model, const Json& ice, const Json& ice_object);

// Churchill's correlation for natural convection around a sphere: Nu(Ra, Pr) (sim/validation/air_sphere.cpp).
double churchill_sphere_nusselt(double rayleigh, double prandtl);

}  // namespace thaw

namespace thaw {
// A case's parameter schema: its own fields, then the properties of its air (rho 1.2, mu 1.8e-5, k 0.025,
// c 1006 by default: density, viscosity, conductivity, specific_heat); and the air material they make.
Field air_case_schema(std::vector<Field> own);
Json air_material(const Json& params);
// An adiabatic solid with the air's density and specific heat (walls that pass no heat, sim/kernels/heat.cl).
Json air_insulator(const Json& params);
// The scene a natural-convection case starts from: the box [0, max] of air at `temperature` (also the
// ambient and the reference of `buoyancy` (air.buoyancy: boussinesq with expansion beta, ideal_gas or none),
// the given walls of air_insulator, gravity -g along z, and a material "conductor" that conducts like the
// air, so that held solids made of it put the air beside them at their temperature. No solids yet.
Json convection_scene(const std::string& name, const Eigen::Vector3d& max, const Json& walls, double g,
                      double dx, const Json& solver, double temperature, double beta,
                      const std::string& buoyancy, const Json& params);

// solver_schema() with some defaults changed, for a case that needs other solver defaults.
Field solver_schema_with(const std::vector<std::pair<std::string, Json>>& defaults);

// The weighted least-squares line y = intercept + slope x through the points (x[k], y[k]), weights w[k]
// (all 1 when w is empty). Needs two distinct x.
struct Line {
  double slope = 0, intercept = 0;
};
Line least_squares_line(const std::vector<double>& x, const std::vector<double>& y,
                        const std::vector<double>& w = {});
}  // namespace thaw
