// Diffusion of a substance in the water's bulk (issue 20; docs/SUBSTANCES.md): a 3-D Gaussian pulse of a
// dissolved substance spreading in still water, particles held in place (solver.flow = false), as the
// conduction case does for heat. Reference: the exact solution for the mass fraction,
//   w = w_inf + A (s0^2 / (s0^2 + 2 D t))^(3/2) exp(-r^2 / (2 (s0^2 + 2 D t))),
// with D from the parameters. Metrics: the L2 error of w - w_inf, the effective diffusivity from the growth
// of the pulse's second moment, and the substance's closure (its total now against the start's: the pair
// transfers are antisymmetric to the bit, sim/kernels/substance.cl). res = particles across s0.
#include <chrono>
#include <cmath>
#include <random>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/validation/case.h"
#include "sim/validation/heat_reference.h"

namespace thaw {
namespace {

Field params() {
  return object(
      "",
      {
          number("sigma0", "Initial width s0 of the pulse").in("m").def(0.01).above(0),
          number("variance_growth", "Run until s0^2 + 2 D t = (1 + this) s0^2").def(1.0).above(0).at_most(20),
          number("half_width", "Half-width of the cubic domain, in final pulse widths sqrt(s0^2 + 2 D t)")
              .def(4.0)
              .at_least(2)
              .at_most(10),
          number("background", "w_inf, the mass fraction far from the pulse")
              .def(0.001)
              .at_least(0)
              .at_most(0.5),
          number("amplitude", "A, the excess mass fraction at the centre at t = 0")
              .def(0.01)
              .above(0)
              .at_most(0.5),
          number("diffusivity", "D of the substance in the water")
              .in("m^2/s")
              .def(1e-9)
              .above(0)
              .at_most(1e-2),
          number("density", "rho of the water").in("kg/m^3").def(1000.0).above(0),
          number("jitter", "Particles displaced uniformly by up to this fraction of the spacing on each axis")
              .def(0.0)
              .at_least(0)
              .at_most(0.3),
          integer("seed", "Random seed of the jitter").def(1).at_least(0),
          number("l2_gate", "Gate on the L2 error of w - w_inf on ordered particles").def(0.01).above(0),
          number("l2_gate_jittered", "The same with jitter > 0").def(0.03).above(0),
          number("diffusivity_gate", "Gate on the relative error of the effective diffusivity")
              .def(0.03)
              .above(0),
          number("closure_gate", "Gate on the substance's closure, relative to its total").def(1e-9).above(0),
          solver_schema_with({{"flow", false}, {"max_dt", 3600.0}}),
      });
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  GaussianPulse pulse;
  pulse.background = prm["background"];
  pulse.amplitude = prm["amplitude"];
  pulse.sigma0 = prm["sigma0"];
  pulse.diffusivity = prm["diffusivity"];
  pulse.dimensions = 3;
  const double s0 = pulse.sigma0, rho = prm["density"];
  const double t_end = double(prm["variance_growth"]) * s0 * s0 / (2.0 * pulse.diffusivity);
  const double dx = s0 / res;
  const double L = std::ceil(double(prm["half_width"]) * std::sqrt(pulse.variance(t_end)) / dx) * dx;

  const Json settings = prm["solver"];
  if (settings["flow"].get<bool>())
    throw SceneError("solver.flow",
                     "the bulk diffusion case holds particles in place: it needs flow = false");
  const Json box = {{"min", {-L, -L, -L}}, {"max", {L, L, L}}};
  const Json doc = {
      {"name", "validation/diffusion-bulk"},
      {"domain", {{"min", {-L, -L, -L}}, {"max", {L, L, L}}}},
      {"gravity", {0, 0, 0}},
      {"spacing", dx},
      {"solver", settings},
      {"heat", {{"enabled", false}}},
      {"materials",
       {{"water", {{"kind", "fluid"}, {"density", rho}, {"conductivity", 0.6}, {"specific_heat", 4186.0}}}}},
      {"substances", {{"tracer", {{"diffusivity", pulse.diffusivity}}}}},
      {"fluids", {{{"material", "water"}, {"box", box}}}},
  };
  const Scene scene = scene_from_json(doc);
  SimState st = initial_state(scene);
  HostParticles& p = st.particles;
  HostColumn* column = p.column(substance_field("tracer").name);
  if (!column) throw Error("diffusion-bulk: the sampled particles carry no tracer");
  Float2* q = column->as<Float2>();
  std::mt19937 rng(static_cast<unsigned>(prm["seed"].get<int>()));
  const double jitter = prm["jitter"];
  std::uniform_real_distribution<double> shift(-jitter * dx, jitter * dx);
  auto r2_of = [](const Float4& x) {
    return double(x[0]) * x[0] + double(x[1]) * x[1] + double(x[2]) * x[2];
  };
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (jitter > 0)
      for (int a = 0; a < 3; ++a) p.position[i][a] += static_cast<float>(shift(rng));
    const double amount = pulse.temperature(r2_of(p.position[i]), 0.0) * double(p.position[i][3]);
    const float hi = static_cast<float>(amount);
    q[i] = {hi, static_cast<float>(amount - double(hi))};
  }

  // Each particle's mass fraction, and the second moment of the excess weighted by mass (equal masses).
  auto fractions = [](const HostParticles& h) {
    const Float2* a = h.column(substance_field("tracer").name)->as<Float2>();
    std::vector<double> w(h.size());
    for (std::size_t i = 0; i < h.size(); ++i) w[i] = (double(a[i][0]) + double(a[i][1])) / h.position[i][3];
    return w;
  };
  Solver solver(cl, scene, st);
  solver.warm_up();
  const HostParticles start = solver.particles();
  const double m2_start = pulse.second_moment(start.position, fractions(start));
  const auto t0 = std::chrono::steady_clock::now();
  while (solver.time() < t_end * (1.0 - 1e-12)) solver.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const HostParticles end = solver.particles();
  const std::vector<double> w = fractions(end);
  const double t = solver.time();
  const double d_eff = (pulse.second_moment(end.position, w) - m2_start) / (2.0 * 3.0 * t);
  const double total = solver.substance_totals().at(0), initial = solver.substance_books().initial.at(0);
  const double closure = total - initial;

  CaseResult r;
  r.particles = end.size();
  r.steps = solver.steps();
  r.wall_s = wall;
  const double l2 = pulse.l2_error(end.position, w, t);
  r.metrics = {
      {"fraction_l2", {l2, 0.0, l2, jitter > 0 ? double(prm["l2_gate_jittered"]) : double(prm["l2_gate"])}},
      {"effective_diffusivity",
       {d_eff, pulse.diffusivity, std::abs(d_eff - pulse.diffusivity) / pulse.diffusivity,
        prm["diffusivity_gate"]}},
      {"closure", {closure, 0.0, std::abs(closure) / initial, prm["closure_gate"]}},
  };
  return r;
}

}  // namespace

ValidationCase diffusion_bulk_case() {
  return {"diffusion-bulk",
          "Gaussian pulse of a dissolved substance in 3-D: L2 error of the mass fraction (gate 1 %, 3 % "
          "jittered), effective diffusivity and closure; res = particles across s0",
          3, params, run};
}

}  // namespace thaw
