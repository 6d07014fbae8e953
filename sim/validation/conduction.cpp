// Heat conduction (docs/VALIDATION-RESULTS.md): a 3-D Gaussian temperature pulse spreading in a still
// medium, particles held in place (solver.flow = false). Reference: the exact solution
// T = T_inf + A (s0^2/(s0^2 + 2 alpha t))^(3/2) exp(-r^2 / (2 (s0^2 + 2 alpha t))) with alpha = k/(rho c)
// from the parameters. Metrics: the L2 error of T, the effective diffusivity from the growth of the
// pulse's second moment (which a pairwise antisymmetric scheme measures directly), and energy closure.
// res = particles across s0.
#include <chrono>
#include <cmath>
#include <random>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/thermal.h"
#include "sim/validation/case.h"
#include "sim/validation/heat_reference.h"

namespace thaw {
namespace {

Field params() {
  return object(
      "",
      {
          number("sigma0", "Initial width s0 of the pulse").in("m").def(0.01).above(0),
          number("variance_growth", "Run until s0^2 + 2 alpha t = (1 + this) s0^2")
              .def(1.0)
              .above(0)
              .at_most(20),
          number("half_width", "Half-width of the cubic domain, in final pulse widths sqrt(s0^2 + 2 alpha t)")
              .def(4.0)
              .at_least(2)
              .at_most(10),
          number("background", "T_inf").in("°C").def(20.0).above(-273.15),
          number("amplitude", "A, the excess at the centre at t = 0").in("K").def(10.0),
          number("conductivity", "k").in("W/m/K").def(0.56).above(0),
          number("specific_heat", "c").in("J/kg/K").def(4217.0).above(0),
          number("density", "rho").in("kg/m^3").def(1000.0).above(0),
          number("jitter", "Particles displaced uniformly by up to this fraction of the spacing on each axis")
              .def(0.0)
              .at_least(0)
              .at_most(0.3),
          integer("seed", "Random seed of the jitter").def(1).at_least(0),
          number("l2_gate", "Gate on the L2 error of T - T_inf on ordered particles").def(0.01).above(0),
          number("l2_gate_jittered", "The same with jitter > 0").def(0.03).above(0),
          number("diffusivity_gate", "Gate on the relative error of the effective diffusivity")
              .def(0.03)
              .above(0),
          number("energy_gate", "Gate on the energy closure, relative to the pulse's heat")
              .def(1e-5)
              .above(0),
          solver_schema_with({{"flow", false}, {"max_dt", 3600.0}}),
      });
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  GaussianPulse pulse;
  pulse.background = prm["background"];
  pulse.amplitude = prm["amplitude"];
  pulse.sigma0 = prm["sigma0"];
  const double k = prm["conductivity"], c = prm["specific_heat"], rho = prm["density"];
  pulse.diffusivity = k / (rho * c);
  pulse.dimensions = 3;
  const double s0 = pulse.sigma0;
  const double t_end = double(prm["variance_growth"]) * s0 * s0 / (2.0 * pulse.diffusivity);
  const double dx = s0 / res;
  const double L = std::ceil(double(prm["half_width"]) * std::sqrt(pulse.variance(t_end)) / dx) * dx;

  const Json settings = prm["solver"];
  if (settings["flow"].get<bool>())
    throw SceneError("solver.flow", "the conduction case holds particles in place: it needs flow = false");
  const Json doc = {
      {"name", "validation/conduction"},
      {"domain", {{"min", {-L, -L, -L}}, {"max", {L, L, L}}}},
      {"gravity", {0, 0, 0}},
      {"spacing", dx},
      {"solver", settings},
      {"ambient", {{"heat_transfer_coefficient", 0.0}}},
      {"materials",
       {{"medium", {{"kind", "fluid"}, {"density", rho}, {"conductivity", k}, {"specific_heat", c}}}}},
      {"fluids", {{{"material", "medium"}, {"box", {{"min", {-L, -L, -L}}, {"max", {L, L, L}}}}}}},
  };
  const Scene scene = scene_from_json(doc);
  SimState st = initial_state(scene);
  auto& p = st.particles;
  std::mt19937 rng(static_cast<unsigned>(prm["seed"].get<int>()));
  const double jitter = prm["jitter"];
  std::uniform_real_distribution<double> shift(-jitter * dx, jitter * dx);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (jitter > 0)
      for (int a = 0; a < 3; ++a) p.position[i][a] += static_cast<float>(shift(rng));
    const double r2 = double(p.position[i][0]) * p.position[i][0] +
                      double(p.position[i][1]) * p.position[i][1] +
                      double(p.position[i][2]) * p.position[i][2];
    const double h = enthalpy_at(scene, p.material[i], pulse.temperature(r2, 0.0));
    const float hi = static_cast<float>(h);
    p.enthalpy[i] = {hi, static_cast<float>(h - hi)};
  }

  auto as_double = [](const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); };

  Solver solver(cl, scene, st);
  solver.warm_up();
  const double m2_start = pulse.second_moment(solver.particles().position, as_double(solver.temperatures()));
  const auto t0 = std::chrono::steady_clock::now();
  // The reference is evaluated at the time actually reached (the last step may pass t_end).
  while (solver.time() < t_end * (1.0 - 1e-12)) solver.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const HostParticles q = solver.particles();
  const std::vector<double> T = as_double(solver.temperatures());
  const double t = solver.time();
  double heat = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const double r2 = double(q.position[i][0]) * q.position[i][0] +
                      double(q.position[i][1]) * q.position[i][1] +
                      double(q.position[i][2]) * q.position[i][2];
    heat += double(q.position[i][3]) * c * std::abs(pulse.temperature(r2, t) - pulse.background);
  }
  const double alpha_eff = (pulse.second_moment(q.position, T) - m2_start) / (2.0 * 3.0 * t);
  const double closure =
      solver.total_enthalpy() - solver.energy_budget().initial - solver.energy_budget().heat_in();

  CaseResult r;
  r.particles = q.size();
  r.steps = solver.steps();
  r.wall_s = wall;
  const double l2 = pulse.l2_error(q.position, T, t);
  r.metrics = {
      {"temperature_l2",
       {l2, 0.0, l2, jitter > 0 ? double(prm["l2_gate_jittered"]) : double(prm["l2_gate"])}},
      {"effective_diffusivity",
       {alpha_eff, pulse.diffusivity, std::abs(alpha_eff - pulse.diffusivity) / pulse.diffusivity,
        prm["diffusivity_gate"]}},
      {"energy_closure", {closure, 0.0, std::abs(closure) / heat, prm["energy_gate"]}},
  };
  return r;
}

}  // namespace

ValidationCase conduction_case() {
  return {"conduction",
          "Gaussian heat pulse in 3-D: L2 error (gate 1 %, 3 % jittered) and effective diffusivity; res = "
          "particles across s0",
          3, params, run};
}

}  // namespace thaw
