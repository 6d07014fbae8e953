// Surface-active substances on a held sphere of water (issue 20; docs/SUBSTANCES.md): a sphere of radius R
// sampled on the lattice (R = res spacings), particles held in place (solver.flow = false), no gravity, heat
// off, one surface-active substance. The surface is the surface stage's (brackbill1992's areas).
//   adsorption: the substance starts dissolved, well mixed (its bulk diffusion time R^2 / D far below the
//     exchange's), and nothing on the surface. With Henry's law (surface_capacity 0) the surface amount S of
//     a well-mixed bulk of volume V under an area A obeys dS/dt = k_a A (N - S) / V - k_d S, so
//       S(t) = S_eq (1 - exp(-k t)),  k = k_d + k_a A / V,  S_eq = N (k_a A / V) / k,
//     N the total. A and V are the model's own: the summed areas of the surface particles and the water's
//     volume sum m / rho0, so the metrics test the exchange (eq. 10) and not the area (the surface-area
//     case does). Metrics: the rate fitted to ln(1 - S / S_eq), the largest deviation of S from S(t) over
//     the run (as a share of S_eq), and the closure.
//   surface-diffusion: only on the surface (no exchange, no bulk diffusion), the surface excess starts as
//     Gamma = Gamma0 + Gamma1 cos(theta); its l = 1 part decays as Gamma1 exp(-2 D_s t / R^2) (the surface
//     Laplacian's eigenvalue l (l + 1) / R^2). Metrics: the decay rate fitted to the l = 1 amplitude's log
//     (Gamma1 from the particles by least squares, sum S_i cos / sum a_i cos^2), and the closure.
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/substance_stage.h"
#include "sim/validation/substance_cases.h"

namespace thaw {
namespace {

// The substance's name in both cases' scenes.
constexpr const char* kSurfactant = "surfactant";

Field sphere_params(std::vector<Field> own) {
  return held_case_params(number("radius", "R of the sphere of water").in("m").def(0.005).above(0),
                          std::move(own));
}

// The held sphere with `substance` (its schema fields) and its concentration in the water.
Scene sphere_scene(const std::string& name, const Json& prm, int res, const Json& substance,
                   double concentration) {
  require_held(prm, "the surface transport cases");
  const double R = prm["radius"], dx = R / res, half = R + 3 * dx;
  Json water = {{"material", "water"}, {"shape", "sphere"}, {"centre", {0.0, 0.0, 0.0}}, {"radius", R}};
  if (concentration > 0) water["substances"] = {{kSurfactant, {{"concentration", concentration}}}};
  return scene_from_json({
      {"name", name},
      {"domain", {{"min", {-half, -half, -half}}, {"max", {half, half, half}}}},
      {"gravity", {0.0, 0.0, 0.0}},
      {"spacing", dx},
      {"solver", prm["solver"]},
      {"heat", {{"enabled", false}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"},
          {"density", prm["density"]},
          {"conductivity", 0.56},
          {"specific_heat", 4200.0}}}}},
      {"substances", {{kSurfactant, substance}}},
      {"fluids", {water}},
  });
}

Field adsorption_params() {
  return sphere_params({
      number("concentration", "c0, the dissolved concentration at the start").in("kg/m^3").def(1.0).above(0),
      number("adsorption_rate", "k_a").in("m/s").def(2e-6).above(0),
      number("desorption_rate", "k_d").in("1/s").def(2e-3).at_least(0),
      number("diffusivity", "D in the bulk: large enough that the bulk stays well mixed (k_a R / D << 1)")
          .in("m^2/s")
          .def(1e-6)
          .above(0),
      number("duration", "Run for this many relaxation times 1 / k").def(2.0).above(0).at_most(20),
      integer("samples", "Times S is compared at, evenly over the run").def(40).at_least(4).at_most(1000),
      number("rate_gate", "Gate on the relative error of the fitted rate").def(0.02).above(0),
      number("amount_gate", "Gate on the largest |S - S(t)| over S_eq").def(0.02).above(0),
  });
}

CaseResult run_adsorption(ClRuntime& cl, const Json& prm, int res) {
  const Json substance = {{"kind", "surface_active"},
                          {"diffusivity", prm["diffusivity"]},
                          {"surface_diffusivity", 0.0},
                          {"adsorption_rate", prm["adsorption_rate"]},
                          {"desorption_rate", prm["desorption_rate"]},
                          {"surface_capacity", 0.0}};
  const Scene scene = sphere_scene("validation/adsorption", prm, res, substance, prm["concentration"]);
  Solver solver(cl, scene, initial_state(scene));
  solver.warm_up();

  // The model's A and V: the surface particles' areas and the water's volume.
  const HostParticles start = solver.particles();
  const double rho0 = solver.constants().rest_density, dx = scene.spacing;
  const float* area = start.column("surface_area")->as<float>();
  double A = 0, V = 0;
  for (std::size_t i = 0; i < start.size(); ++i) {
    if (area[i] > kSurfaceMinArea * dx * dx) A += area[i];
    V += double(start.position[i][3]) / rho0;
  }
  const double ka = prm["adsorption_rate"], kd = prm["desorption_rate"];
  const double k = kd + ka * A / V;
  const double N = solver.substance_totals().at(0);
  const double S_eq = N * (ka * A / V) / k;
  auto on_surface = [&] { return field_total(solver, adsorbed_field(kSurfactant).name); };

  std::vector<double> t, y;
  double worst = 0;
  const double wall = run_sampled(solver, double(prm["duration"]) / k, prm["samples"], [&](double time) {
    const double S = on_surface();
    worst = std::max(worst, std::abs(S - S_eq * (1.0 - std::exp(-k * time))) / S_eq);
    t.push_back(time);
    y.push_back(-std::log(std::max(1.0 - S / S_eq, 1e-300)));
  });
  const double k_fit = slope_through_origin(t, y);
  return substance_case_result(solver, wall,
                               {{"rate", {k_fit, k, std::abs(k_fit - k) / k, prm["rate_gate"]}},
                                {"surface_amount", {worst, 0.0, worst, prm["amount_gate"]}}},
                               prm["closure_gate"]);
}

Field surface_diffusion_params() {
  return sphere_params({
      number("surface_diffusivity", "D_s").in("m^2/s").def(1e-9).above(0),
      number("mean", "Gamma0, the mean surface excess").in("kg/m^2").def(1e-6).at_least(0),
      number("amplitude", "Gamma1, the amplitude of its cos(theta) part").in("kg/m^2").def(5e-7).above(0),
      number("decay", "Run until Gamma1 has fallen by exp(-this)").def(1.0).above(0).at_most(5),
      integer("samples", "Times Gamma1 is measured at, evenly over the run")
          .def(20)
          .at_least(2)
          .at_most(1000),
      number("rate_gate", "Gate on the relative error of the decay rate").def(0.03).above(0),
  });
}

CaseResult run_surface_diffusion(ClRuntime& cl, const Json& prm, int res) {
  const double Ds = prm["surface_diffusivity"], R = prm["radius"];
  const Json substance = {{"kind", "surface_active"}, {"diffusivity", 0.0},     {"surface_diffusivity", Ds},
                          {"adsorption_rate", 0.0},   {"desorption_rate", 0.0}, {"surface_capacity", 0.0}};
  const Scene scene = sphere_scene("validation/surface-diffusion", prm, res, substance, 0.0);
  // The areas first, then Gamma0 + Gamma1 cos(theta) times each surface particle's area on its surface.
  HostParticles p;
  SimState st;
  {
    Solver areas(cl, scene, initial_state(scene));
    areas.warm_up();
    st = areas.state();
    p = areas.particles();
  }
  const double dx = scene.spacing, g0 = prm["mean"], g1 = prm["amplitude"];
  const float* area = p.column("surface_area")->as<float>();
  Float2* s = p.column(adsorbed_field(kSurfactant).name)->as<Float2>();
  auto cosine = [&](std::size_t i) {
    const Float4& x = p.position[i];
    const double r = std::sqrt(double(x[0]) * x[0] + double(x[1]) * x[1] + double(x[2]) * x[2]);
    return r > 0 ? double(x[2]) / r : 0.0;
  };
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double a = area[i] > kSurfaceMinArea * dx * dx ? double(area[i]) : 0.0;
    const double S = a * (g0 + g1 * cosine(i));
    const float hi = static_cast<float>(S);
    s[i] = {hi, static_cast<float>(S - double(hi))};
  }
  st.particles = p;
  st.substances.clear();  // the books start from these amounts
  Solver solver(cl, scene, st);
  solver.warm_up();
  // Gamma1 by least squares over the surface particles (positions are held, but the order is the solver's).
  auto amplitude = [&] {
    const HostParticles now = solver.particles();
    const float* a = now.column("surface_area")->as<float>();
    const Float2* q = now.column(adsorbed_field(kSurfactant).name)->as<Float2>();
    double sc = 0, acc = 0;
    for (std::size_t i = 0; i < now.size(); ++i) {
      const Float4& x = now.position[i];
      const double r = std::sqrt(double(x[0]) * x[0] + double(x[1]) * x[1] + double(x[2]) * x[2]);
      const double c = r > 0 ? double(x[2]) / r : 0.0;
      sc += pair_amount(q[i]) * c;
      if (a[i] > kSurfaceMinArea * dx * dx) acc += double(a[i]) * c * c;
    }
    return acc > 0 ? sc / acc : 0.0;
  };
  const double rate = 2.0 * Ds / (R * R);
  const double a0 = amplitude();
  std::vector<double> t, y;
  const double wall = run_sampled(solver, double(prm["decay"]) / rate, prm["samples"], [&](double time) {
    t.push_back(time);
    y.push_back(-std::log(std::max(amplitude() / a0, 1e-300)));
  });
  const double fitted = slope_through_origin(t, y);
  return substance_case_result(
      solver, wall, {{"decay_rate", {fitted, rate, std::abs(fitted - rate) / rate, prm["rate_gate"]}}},
      prm["closure_gate"]);
}

}  // namespace

ValidationCase adsorption_case() {
  return {"adsorption",
          "Henry adsorption onto a held sphere of well-mixed water: the surface amount relaxes at k_d + k_a "
          "A / V "
          "(gate 2 %) to its equilibrium split (2 %), closure 1e-9; res = spacings across R",
          6, adsorption_params, run_adsorption};
}

ValidationCase surface_diffusion_case() {
  return {"surface-diffusion",
          "Surface diffusion on a held sphere: Gamma1 cos(theta) decays at 2 D_s / R^2 (gate 3 %), closure "
          "1e-9; res = spacings across R",
          10, surface_diffusion_params, run_surface_diffusion};
}

double field_total(const Solver& solver, const std::string& field) {
  const HostParticles p = solver.particles();
  const HostColumn* c = p.column(field);
  double sum = 0;
  for (std::size_t i = 0; c && i < p.size(); ++i) sum += pair_amount(c->as<Float2>()[i]);
  return sum;
}

double slope_through_origin(const std::vector<double>& t, const std::vector<double>& y) {
  double ty = 0, tt = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    ty += t[k] * y[k];
    tt += t[k] * t[k];
  }
  return tt > 0 ? ty / tt : 0.0;
}

CaseResult substance_case_result(const Solver& solver, double wall,
                                 std::vector<std::pair<std::string, MetricResult>> metrics, double gate,
                                 std::size_t substance) {
  CaseResult r;
  r.particles = solver.size();
  r.steps = solver.steps();
  r.wall_s = wall;
  r.metrics = std::move(metrics);
  const double initial = solver.substance_books().initial.at(substance);
  const double closure = solver.substance_totals().at(substance) - initial;
  r.metrics.push_back({"closure", {closure, 0.0, std::abs(closure) / initial, gate}});
  return r;
}

Field held_case_params(Field size, std::vector<Field> own) {
  std::vector<Field> f = {std::move(size),
                          number("density", "rho of water").in("kg/m^3").def(1000.0).above(0)};
  for (Field& x : own) f.push_back(std::move(x));
  f.push_back(solver_schema_with({{"flow", false}, {"max_dt", 3600.0}}));
  f.push_back(
      number("closure_gate", "Gate on the substance's closure, relative to its total").def(1e-9).above(0));
  return object("", std::move(f));
}

void require_held(const Json& params, const std::string& cases) {
  if (params["solver"]["flow"].get<bool>())
    throw SceneError("solver.flow", cases + " hold particles in place: they need flow = false");
}

}  // namespace thaw

namespace thaw {

Json still_detergent(const Json& law, const Json& tension_scale) {
  return {{"soap",
           {{"kind", "surface_active"},
            {"diffusivity", 0.0},
            {"surface_diffusivity", 0.0},
            {"adsorption_rate", 0.0},
            {"desorption_rate", 0.0},
            {"surface_capacity", 1e-6},
            {"tension_law", law},
            {"tension_scale", tension_scale}}}};
}

SimState with_surface_coverage(ClRuntime& cl, const Scene& scene, double theta,
                               const std::function<double(double, double, double)>& shape) {
  if (scene.substances.empty() || !scene.substances[0].surface_active())
    throw Error("with_surface_coverage: the scene's first substance must be surface-active");
  Solver areas(cl, scene, initial_state(scene));
  areas.warm_up();
  SimState st = areas.state();
  HostParticles& p = st.particles;
  const HostColumn* area_column = p.column("surface_area");
  HostColumn* col = p.column(adsorbed_field(scene.substances[0].name).name);
  if (!area_column || !col)
    throw Error("with_surface_coverage: the state has no surface areas or no surface amounts");
  const float* area = area_column->as<float>();
  const double dx = scene.spacing, capacity = scene.substances[0].surface_capacity;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (area[i] <= kSurfaceMinArea * dx * dx) continue;
    const double amount =
        theta * capacity * area[i] * shape(p.position[i][0], p.position[i][1], p.position[i][2]);
    col->as<Float2>()[i] = {static_cast<float>(amount), 0.0f};
  }
  st.substances.clear();  // the books start from these amounts
  return st;
}

std::map<std::uint32_t, StepForce> second_step_forces(ClRuntime& cl, const Scene& scene, const SimState& st) {
  Solver s(cl, scene, st);
  s.step();
  const HostParticles a = s.particles();
  const double t1 = s.time();
  s.step();
  const HostParticles b = s.particles();
  const double dt = s.time() - t1;
  std::map<std::uint32_t, Eigen::Vector3d> before;
  for (std::size_t i = 0; i < a.size(); ++i)
    before[a.id[i]] = Eigen::Vector3d(a.velocity[i][0], a.velocity[i][1], a.velocity[i][2]);
  std::map<std::uint32_t, StepForce> out;
  for (std::size_t i = 0; i < b.size(); ++i) {
    const Eigen::Vector3d v(b.velocity[i][0], b.velocity[i][1], b.velocity[i][2]);
    out[b.id[i]] = {Eigen::Vector3d(b.position[i][0], b.position[i][1], b.position[i][2]),
                    double(b.position[i][3]) * (v - before.at(b.id[i])) / dt};
  }
  return out;
}

}  // namespace thaw
