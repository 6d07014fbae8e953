#include "sim/solver_constants.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "sim/fluid_stage.h"
#include "sim/tension_stage.h"
#include "sim/thermal.h"

namespace thaw {

SolverConstants derive_constants(const Scene& scene) {
  const auto& s = scene.solver;
  SolverConstants k;
  k.support = static_cast<float>(s.support_ratio * scene.spacing);
  k.smoothing = 0.5f * k.support;

  // The first fluid block's material (or, in a scene of ice alone, the water it melts into) sets the rest
  // density that boundary particles carry (Akinci 2012) and the stiffness scale; each fluid's own
  // properties are rows of the flow table (material_flow_table in sim/fluid_stage.h).
  int fluid_material = scene.fluids.empty() ? -1 : scene.fluids.front().material;
  if (fluid_material < 0 && !scene.emitters.empty()) fluid_material = scene.emitters.front().material;
  for (const auto& c : scene.ice)
    if (fluid_material < 0) fluid_material = scene.materials[static_cast<std::size_t>(c.material)].partner;
  if (fluid_material < 0 && scene.has_air()) fluid_material = scene.air.material;
  const Material* fluid = fluid_material >= 0 ? &scene.materials[fluid_material] : nullptr;
  k.rest_density = static_cast<float>(fluid ? fluid->density : 1000.0);
  // The viscous limit on dt takes the largest kinematic viscosity of any fluid present or melted into.
  double nu = 0;
  auto consider = [&](int m) {
    if (m < 0) return;
    const Material& mat = scene.materials[static_cast<std::size_t>(m)];
    if (flows(mat.kind)) nu = std::max(nu, double(static_cast<float>(mat.viscosity / mat.density)));
  };
  for (const auto& f : scene.fluids) consider(f.material);
  for (const auto& c : scene.ice) consider(scene.materials[static_cast<std::size_t>(c.material)].partner);
  for (const auto& e : scene.emitters) consider(e.material);
  if (scene.has_air()) consider(scene.air.material);
  k.kinematic_viscosity = static_cast<float>(nu);

  // Reference speed: free fall from the highest fluid or ice to the bottom of the domain, or the fastest
  // initial velocity, whichever is larger.
  double v_ref = s.reference_speed;
  if (v_ref <= 0) {
    const double g = scene.gravity.norm();
    if (g > 0) {
      const Eigen::Vector3d up = -scene.gravity / g;
      double top = -std::numeric_limits<double>::infinity();
      // Ice turns into water where it stands, so its top counts too.
      for (const auto& f : scene.fluids) top = std::max(top, f.box.max_along(up));
      for (const auto& c : scene.ice) top = std::max(top, c.box.max_along(up));
      const double bottom = -scene.domain.max_along(-up);
      if (!scene.fluids.empty() || !scene.ice.empty())
        v_ref = std::sqrt(2.0 * g * std::max(0.0, top - bottom));
      // A jet lands at sqrt(v^2 + 2 g fall) (a closed tap may open at any time).
      for (const auto& e : scene.emitters)
        v_ref = std::max(v_ref,
                         std::sqrt(e.speed * e.speed + 2.0 * g * std::max(0.0, up.dot(e.position) - bottom)));
    }
    for (const auto& f : scene.fluids) v_ref = std::max(v_ref, f.velocity.norm());
    for (const auto& e : scene.emitters) v_ref = std::max(v_ref, e.speed);
    for (const auto& d : scene.dryers)
      if (d.model == DryerModel::Air) v_ref = std::max(v_ref, d.speed);
    v_ref = std::max(v_ref, 0.1);  // a still fluid in zero gravity still needs a finite stiffness
  }
  // Tension's pair forces pull bulk water in with a cohesive pressure p_c that the equation of state holds:
  // the stiffness must dwarf it as it does the flow's dynamic pressure, so v_ref is at least sqrt(2 p_c /
  // rho0) (without it drops blew up: docs/TENSION.md).
  if (scene.tension.enabled())
    v_ref =
        std::max(v_ref, std::sqrt(2.0 * tension_coefficients(scene, k).cohesive_pressure / k.rest_density));
  k.sound_speed = static_cast<float>(s.speed_of_sound > 0 ? s.speed_of_sound : s.sound_speed_factor * v_ref);
  k.max_speed = static_cast<float>(s.max_speed > 0 ? s.max_speed : 5.0 * k.sound_speed);
  const float h = k.smoothing;
  const fluid::MaterialFlow first = flow_row(s, k.rest_density, k.kinematic_viscosity, k.sound_speed, h);
  k.stiffness = first.stiffness;
  k.visc_fluid = first.viscosity;
  k.visc_boundary = static_cast<float>(s.boundary_viscosity * k.sound_speed * h);
  const double dx = scene.spacing;
  // The walls' push is a spring of angular frequency c_push / dx: with WCSPH's acoustic step that is the
  // sound speed. DFSPH's steps are as long as the flow allows, and symplectic Euler needs omega dt < 2:
  // there the spring stiffens only enough to stop the fastest expected flow within a third of a spacing,
  // c_push = 3 v_ref (omega dt = 0.66 at the default max_dt in a 25 cm column).
  const double c_push = s.pressure == PressureSolver::Dfsph ? std::min(double(k.sound_speed), 3.0 * v_ref)
                                                            : double(k.sound_speed);
  k.repulsion = static_cast<float>(c_push * c_push / (dx * dx * k.rest_density * dx * dx * dx));
  k.repulsion_range = static_cast<float>(0.95 * dx);
  k.repulsion_damping = static_cast<float>(dx / c_push);
  k.capillary_dt =
      scene.tension.enabled()
          ? std::sqrt(k.rest_density * dx * dx * dx / (2.0 * std::numbers::pi * scene.tension.coefficient))
          : std::numeric_limits<double>::infinity();

  const double inf = std::numeric_limits<double>::infinity();
  const double alpha = max_diffusivity(scene);
  k.diffusion_dt = alpha > 0 ? s.diffusion_number * double(h) * h / (scene.heat.time_scale * alpha) : inf;
  // Explicit Newton cooling of a particle of capacity rho c dx^3 through at most 6 dx^2 is stable for
  // dt < rho c dx / (6 h); the time step keeps half of that (Solver::heat_time_step).
  k.exposed_capacity = inf;
  k.wall_dt = inf;
  for (const Material& m : scene.materials) {
    if (m.kind == MaterialKind::Fluid || m.kind == MaterialKind::Ice)
      k.exposed_capacity = std::min(k.exposed_capacity, m.density * m.specific_heat * dx / 6.0);
    if (m.wall_heat) {
      k.wall_dt = std::min(k.wall_dt, 0.5 * m.density * m.specific_heat * dx * wall_layer_count(scene) /
                                          (scene.heat.time_scale * scene.heat.wall_coefficient));
    }
  }
  return k;
}

}  // namespace thaw
