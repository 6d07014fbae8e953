// Coatings on a solid (issue 20; docs/SUBSTANCES.md): a layer of water of depth L held on a solid plane
// (solver.flow = false), periodic along x and y so the plane has no edge, no gravity, heat off. The water
// is res spacings deep; the plane's outer layer of boundary particles holds the deposits.
//   coating: a coating starts dissolved at c0, nothing on the plane; Henry's law (no capacity), no
//     cleanser. The water loses it through the plane at k_c c and it diffuses in the water with D, so the
//     dissolved total decays, once the layer's faster modes have died, at D lambda^2 / L^2, lambda the
//     first root of lambda tan(lambda) = Bi = k_c L / D (a slab with a Robin face and a closed one; Carslaw
//     & Jaeger 3.11). Metrics: that rate, fitted to ln(dissolved) over the run's second half; the closure.
//   cleansing: a coating starts on the plane at Gamma0 and a cleanser fills the water at c_D; nothing
//     deposits (k_c = 0). The cleanser is not used up (sec. 6.3's micelles take both into the water), so
//     every face loses its deposit at k_r c_D: Gamma(t) = Gamma0 exp(-k_r c_D t) whatever the water does
//     with the grease. Metrics: the rate fitted to ln(deposit) through the origin; the closure.
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/substance_stage.h"
#include "sim/validation/substance_cases.h"

namespace thaw {
namespace {

constexpr const char* kCoating = "coating";
constexpr const char* kCleanser = "cleanser";

Field layer_params(std::vector<Field> own) {
  return held_case_params(
      number("depth", "L, the depth of the water on the plane").in("m").def(0.004).above(0), std::move(own));
}

// The layer: water [0, L) deep over a plane at z = 0, 6 spacings along the periodic x and y.
Scene layer_scene(const std::string& name, const Json& prm, int res, const Json& substances,
                  const Json& water_substances, const Json& deposits) {
  require_held(prm, "the coating cases");
  const double L = prm["depth"], dx = L / res, side = 6 * dx;
  Json solver = prm["solver"];
  solver["periodic"] = {"x", "y"};
  return scene_from_json({
      {"name", name},
      {"domain", {{"min", {0.0, 0.0, 0.0}}, {"max", {side, side, L + 3 * dx}}}},
      {"gravity", {0.0, 0.0, 0.0}},
      {"spacing", dx},
      {"solver", solver},
      {"heat", {{"enabled", false}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"}, {"density", prm["density"]}, {"conductivity", 0.56}, {"specific_heat", 4200.0}}},
        {"plate",
         {{"kind", "solid"}, {"density", 2500.0}, {"conductivity", 1.0}, {"specific_heat", 840.0}}}}},
      {"substances", substances},
      {"solids",
       {{{"shape", "plane"},
         {"material", "plate"},
         {"point", {0.0, 0.0, 0.0}},
         {"normal", {0.0, 0.0, 1.0}},
         {"deposits", deposits}}}},
      {"fluids",
       {{{"material", "water"},
         {"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {side, side, L}}}},
         {"substances", water_substances}}}},
  });
}

// The first root of lambda tan(lambda) = bi in (0, pi / 2), by bisection.
double robin_root(double bi) {
  double lo = 0, hi = 0.5 * M_PI;
  for (int k = 0; k < 200; ++k) {
    const double m = 0.5 * (lo + hi);
    (m * std::tan(m) < bi ? lo : hi) = m;
  }
  return 0.5 * (lo + hi);
}

Field coating_params() {
  return layer_params({
      number("concentration", "c0, the dissolved concentration at the start").in("kg/m^3").def(1.0).above(0),
      number("coating_rate", "k_c (the default makes k_c L / D = 0.2)").in("m/s").def(5e-5).above(0),
      number("diffusivity", "D in the water").in("m^2/s").def(1e-6).above(0),
      number("duration", "Run for this many decay times L^2 / (D lambda^2)").def(1.0).above(0).at_most(10),
      integer("samples", "Times the dissolved total is measured at, evenly over the run")
          .def(20)
          .at_least(4)
          .at_most(1000),
      number("rate_gate", "Gate on the relative error of the decay rate").def(0.02).above(0),
  });
}

CaseResult run_coating(ClRuntime& cl, const Json& prm, int res) {
  const double kc = prm["coating_rate"], D = prm["diffusivity"], L = prm["depth"];
  const Json substances = {{kCoating,
                            {{"kind", "coating"},
                             {"diffusivity", D},
                             {"coating_rate", kc},
                             {"coating_capacity", 0.0},
                             {"cleansing_rate", 0.0}}}};
  const Scene scene = layer_scene("validation/coating", prm, res, substances,
                                  {{kCoating, {{"concentration", prm["concentration"]}}}}, Json::object());
  Solver solver(cl, scene, initial_state(scene));
  solver.warm_up();
  const double lambda = robin_root(kc * L / D);
  const double rate = D * lambda * lambda / (L * L);
  const std::string dissolved = substance_field(kCoating).name;
  const double n0 = field_total(solver, dissolved);
  std::vector<double> t, y;
  const int samples = prm["samples"];
  const double wall = run_sampled(solver, double(prm["duration"]) / rate, samples, [&](double time) {
    t.push_back(time);
    y.push_back(-std::log(std::max(field_total(solver, dissolved) / n0, 1e-300)));
  });
  // The second half: the layer's higher modes decay at (pi / L)^2 D and faster, gone by then.
  const std::vector<double> t2(t.begin() + samples / 2, t.end()), y2(y.begin() + samples / 2, y.end());
  const double fitted = least_squares_line(t2, y2).slope;
  return substance_case_result(
      solver, wall, {{"decay_rate", {fitted, rate, std::abs(fitted - rate) / rate, prm["rate_gate"]}}},
      prm["closure_gate"]);
}

Field cleansing_params() {
  return layer_params({
      number("deposit", "Gamma0, the coating on the plane at the start").in("kg/m^2").def(1e-4).above(0),
      number("cleanser_concentration", "c_D, the cleanser's concentration in the water")
          .in("kg/m^3")
          .def(5.0)
          .above(0),
      number("cleansing_rate", "k_r").in("m^3/(kg s)").def(0.02).above(0),
      number("diffusivity", "D of the coating in the water").in("m^2/s").def(1e-6).at_least(0),
      number("decay", "Run until the deposit has fallen by exp(-this)").def(1.0).above(0).at_most(5),
      integer("samples", "Times the deposit is measured at, evenly over the run")
          .def(20)
          .at_least(2)
          .at_most(1000),
      number("rate_gate", "Gate on the relative error of the cleansing rate").def(0.01).above(0),
  });
}

CaseResult run_cleansing(ClRuntime& cl, const Json& prm, int res) {
  const double kr = prm["cleansing_rate"], cD = prm["cleanser_concentration"];
  const Json substances = {{kCoating,
                            {{"kind", "coating"},
                             {"diffusivity", prm["diffusivity"]},
                             {"coating_rate", 0.0},
                             {"cleansed_by", kCleanser},
                             {"cleansing_rate", kr}}},
                           {kCleanser, {{"diffusivity", 0.0}}}};
  const Scene scene =
      layer_scene("validation/cleansing", prm, res, substances, {{kCleanser, {{"concentration", cD}}}},
                  {{kCoating, {{"deposit", prm["deposit"]}}}});
  Solver solver(cl, scene, initial_state(scene));
  solver.warm_up();
  const double rate = kr * cD;
  const std::string stuck = deposited_field(kCoating).name;
  const double r0 = field_total(solver, stuck);
  std::vector<double> t, y;
  const double wall = run_sampled(solver, double(prm["decay"]) / rate, prm["samples"], [&](double time) {
    t.push_back(time);
    y.push_back(-std::log(std::max(field_total(solver, stuck) / r0, 1e-300)));
  });
  const double fitted = slope_through_origin(t, y);
  return substance_case_result(solver, wall,
                               {{"rate", {fitted, rate, std::abs(fitted - rate) / rate, prm["rate_gate"]}}},
                               prm["closure_gate"]);
}

}  // namespace

ValidationCase coating_case() {
  return {
      "coating",
      "A coating deposits from held water onto a plane (Henry): the dissolved total decays at D lambda^2 / "
      "L^2, lambda tan(lambda) = k_c L / D (gate 2 %), closure 1e-9; res = spacings across the depth L",
      8, coating_params, run_coating};
}

ValidationCase cleansing_case() {
  return {
      "cleansing",
      "A cleanser at c_D takes a deposit off a plane: Gamma0 exp(-k_r c_D t) (gate 1 %), closure 1e-9; res "
      "= spacings across the depth L",
      6, cleansing_params, run_cleansing};
}

}  // namespace thaw
