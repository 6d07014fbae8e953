// marangoni (issue 20 item 6, docs/SUBSTANCES.md): the stress a surface-active substance puts along the
// water's surface where it lowers the tension unevenly (Marangoni's), in tension.model brackbill1992.
//
// A flat layer of water `depth` deep on a plane, periodic along y and z over `length`, holds on its free
// surface a substance at coverage Gamma / Gamma_max = theta (1 + eps sin k y), k = 2 pi / length, with
// nothing to move it (no diffusion, no exchange). The tension law (Szyszkowski's sigma0 + E ln(1 - theta),
// or the linear sigma0 - E theta) makes sigma(y) along the surface, and the surface stress on the water is
// its gradient, d sigma / dy per area. Over the whole surface its first Fourier mode is
//   F = sum_i f_y,i cos(k y_i) = L_z int_0^L_y d sigma/dy cos(k y) dy,
// computed here by quadrature from the parameters (the linear law: -E theta eps k L_y L_z / 2). The force on
// each particle is its velocity change over a step of `dt` (the second step: the first renews the tension
// ratios from the coverage), less that of the same layer with the substance spread evenly, so the pressure,
// the normal tension and everything else the two share cancels.
#include <chrono>
#include <cmath>
#include <numbers>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/substance_stage.h"
#include "sim/surface_stage.h"
#include "sim/validation/case.h"
#include "sim/validation/substance_cases.h"

namespace thaw {
namespace {

Field marangoni_params() {
  return object("",
                {
                    number("length", "L, the layer's period along y and z").in("m").def(0.012).above(0),
                    number("depth", "The water's depth over the plane").in("m").def(0.005).above(0),
                    number("density", "rho of water").in("kg/m^3").def(1000.0).above(0),
                    number("sigma", "sigma0, the clean water's tension (tension.coefficient)")
                        .in("N/m")
                        .def(0.0756)
                        .above(0),
                    choice("law", {"szyszkowski", "linear"}, "The substance's tension_law").def("linear"),
                    number("tension_scale", "E in the law").in("N/m").def(0.02).above(0),
                    number("coverage", "theta, the mean Gamma / Gamma_max").def(0.5).above(0).below(1),
                    number("amplitude", "eps, the relative amplitude of the coverage's sine")
                        .def(0.5)
                        .above(0)
                        .below(1),
                    number("dt", "The time step of the two steps").in("s").def(1e-6).above(0),
                    number("force_gate", "Gate on the relative error of the force's mode").def(0.1).above(0),
                });
}

// sigma at coverage theta under the parameters' law.
double tension_at(const Json& prm, double theta) {
  const double sigma0 = prm["sigma"], E = prm["tension_scale"];
  return prm["law"] == "linear" ? sigma0 - E * theta : sigma0 + E * std::log(1.0 - theta);
}

// L_z int_0^L_y dsigma/dy cos(k y) dy, by parts: k L_z int_0^L sigma(y) sin(k y) dy (the boundary terms
// cancel over a period), by the midpoint rule over 4096 points (spectrally accurate for a periodic
// integrand).
double reference_force(const Json& prm) {
  const double L = prm["length"], theta = prm["coverage"], eps = prm["amplitude"];
  const double k = 2.0 * std::numbers::pi / L;
  const int n = 4096;
  double sum = 0;
  for (int q = 0; q < n; ++q) {
    const double y = (q + 0.5) * L / n;
    sum += tension_at(prm, theta * (1.0 + eps * std::sin(k * y))) * std::sin(k * y);
  }
  return k * L * sum * L / n;
}

Json layer_scene(const Json& prm, double dx) {
  const double L = prm["length"], depth = prm["depth"];
  return {
      {"name", "validation/marangoni"},
      {"domain", {{"min", {-0.8 * depth, 0.0, 0.0}}, {"max", {2.4 * depth, L, L}}}},
      {"gravity", {0.0, 0.0, 0.0}},
      {"spacing", dx},
      {"heat", {{"enabled", false}}},
      {"solver", {{"periodic", {"y", "z"}}, {"max_dt", prm["dt"]}, {"reference_speed", 0.2}}},
      {"tension", {{"model", "brackbill1992"}, {"coefficient", prm["sigma"]}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"},
          {"density", prm["density"]},
          {"viscosity", 0.001},
          {"conductivity", 0.56},
          {"specific_heat", 4200.0}}},
        {"glass",
         {{"kind", "solid"}, {"density", 2500.0}, {"conductivity", 1.0}, {"specific_heat", 800.0}}}}},
      {"substances", still_detergent(prm["law"], prm["tension_scale"])},
      {"solids",
       {{{"shape", "plane"},
         {"material", "glass"},
         {"point", {0.0, 0.0, 0.0}},
         {"normal", {1.0, 0.0, 0.0}}}}},
      {"fluids", {{{"material", "water"}, {"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {depth, L, L}}}}}}},
  };
}

CaseResult run_marangoni(ClRuntime& cl, const Json& prm, int res) {
  const double L = prm["length"], theta = prm["coverage"], eps = prm["amplitude"];
  const double dx = L / res, k = 2.0 * std::numbers::pi / L;
  const Scene scene = scene_from_json(layer_scene(prm, dx));
  const auto t0 = std::chrono::steady_clock::now();
  const SimState even = with_surface_coverage(cl, scene, theta, [](double, double, double) { return 1.0; });
  const SimState uneven = with_surface_coverage(
      cl, scene, theta, [&](double, double y, double) { return 1.0 + eps * std::sin(k * y); });
  const auto fe = second_step_forces(cl, scene, even), fu = second_step_forces(cl, scene, uneven);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double along = 0;
  for (const auto& [id, u] : fu) along += (u.f.y() - fe.at(id).f.y()) * std::cos(k * u.x.y());
  const double expected = reference_force(prm);
  CaseResult r;
  r.name = "marangoni";
  r.res = res;
  r.particles = fu.size();
  r.steps = 4;
  r.wall_s = wall;
  r.metrics.push_back(
      {"marangoni_force", {along, expected, std::abs(along / expected - 1.0), prm["force_gate"]}});
  return r;
}

}  // namespace

ValidationCase marangoni_case() {
  return {
      "marangoni",
      "A flat layer whose surface holds a detergent at theta (1 + eps sin k y): the force's first mode along "
      "the surface against L int dsigma/dy cos(k y) dy from the tension law (brackbill1992, gate 10 %); res "
      "= "
      "spacings along the period L",
      12, marangoni_params, run_marangoni};
}

}  // namespace thaw
