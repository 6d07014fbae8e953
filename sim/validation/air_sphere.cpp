// Natural convection around a cold sphere in still air (issue 18's `air-sphere`): a sphere of diameter D
// held at T_s (0 °C: ice that does not melt) in a closed box of air at T_inf (20 °C), Boussinesq
// buoyancy (or eq 7's ideal gas, `buoyancy`). The air it cools sinks below it as a plume. Reference:
// Churchill's correlation for a sphere (Churchill 1983, as quoted by Incropera & DeWitt eq 9.35, valid for Pr
// >= 0.7 and Ra <= 1e11)
//   Nu = 2 + 0.589 Ra^(1/4) / [1 + (0.469 / Pr)^(9/16)]^(4/9),  Ra = g beta |T_inf - T_s| D^3 / (nu alpha),
// with beta the air's expansion coefficient as the run uses it (an ideal gas's 1 / (T_inf + 273.15 K)),
// so the reference follows every parameter. Metric: Nu = Q / (pi D k |T_inf - T_s|), Q the heat the air
// gives the sphere (Solver::held_power) averaged over the last part of the run; gate 20 % (the
// correlation's own scatter is about 10 %). The far air stays near T_inf: the box's sides relax toward
// it (air.face_exchange_time, Domaradzki & Martyn sec. 7), as the room beyond them would; without that
// the box's air would cool by the heat the sphere takes. res = particles across the diameter.
#include <chrono>
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

Field params() {
  return air_case_schema({
      number("diameter", "D of the sphere").in("m").def(0.03).above(0).at_most(1),
      number("sphere_temperature", "T_s, where the sphere is held")
          .in("°C")
          .def(0.0)
          .above(-100)
          .at_most(500),
      number("air_temperature", "T_inf, the air's starting and reference temperature")
          .in("°C")
          .def(20.0)
          .above(-100)
          .at_most(500),
      number("gravity", "g").in("m/s^2").def(9.81).above(0),
      choice("buoyancy", {"boussinesq", "ideal_gas"},
             "air.buoyancy: Boussinesq's force, or eq 7's rest density (the air expands)")
          .def("boussinesq"),
      number("width", "The box's width and depth, in diameters").def(4.0).at_least(2).at_most(20),
      number("below", "Air below the sphere's centre (the plume's side), in diameters")
          .def(4.0)
          .at_least(1)
          .at_most(20),
      number("above", "Air above the sphere's centre, in diameters").def(2.0).at_least(1).at_most(20),
      number("face_exchange_time",
             "tau of the sides' relaxation toward T_inf (air.face_exchange_time); 0: a closed box")
          .in("s")
          .def(0.5)
          .at_least(0),
      number("time", "Simulated time").in("s").def(3.0).above(0).at_most(100),
      number("average", "The last fraction of the run the heat flux is averaged over")
          .def(0.5)
          .above(0)
          .at_most(1),
      integer("samples", "Heat-flux samples over the averaging window").def(40).at_least(2).at_most(100000),
      number("nusselt_gate", "Gate on |Nu - Nu_ref| / Nu_ref").def(0.2).above(0),
      // As the cavity: Wendland C2 over 3 spacings and no-slip walls (Adami 2012).
      solver_schema_with({{"pressure", "dfsph"},
                          {"kernel", "wendland_c2"},
                          {"support_ratio", 3.0},
                          {"artificial_viscosity", 0.0},
                          {"density_tolerance", 0.005},
                          {"no_slip", "adami2012"},
                          {"max_dt", 0.05}}),
  });
}

}  // namespace

// Churchill's Nusselt number for a sphere in natural convection (the file's header).
double churchill_sphere_nusselt(double rayleigh, double prandtl) {
  return 2.0 +
         0.589 * std::pow(rayleigh, 0.25) / std::pow(1.0 + std::pow(0.469 / prandtl, 9.0 / 16.0), 4.0 / 9.0);
}

namespace {

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double D = prm["diameter"], Ts = prm["sphere_temperature"], Tinf = prm["air_temperature"];
  const double rho = prm["density"], mu = prm["viscosity"], k = prm["conductivity"], c = prm["specific_heat"];
  const double g = prm["gravity"];
  const double nu = mu / rho, alpha = k / (rho * c), pr = nu / alpha;
  const double dT = std::abs(Tinf - Ts);
  if (dT <= 0) throw SceneError("sphere_temperature", "must differ from air_temperature");
  const double beta = 1.0 / (Tinf + 273.15);
  const double ra = g * beta * dT * D * D * D / (nu * alpha);
  const double dx = D / res;
  // Whole spacings: the box's extents, the sphere's centre on a lattice point between cells.
  auto spacings = [&](double diameters) { return std::round(diameters * res) * dx; };
  const double half_w = 0.5 * spacings(double(prm["width"]));
  const double below = spacings(double(prm["below"])), above = spacings(double(prm["above"]));
  const Eigen::Vector3d centre(half_w, half_w, below);

  Json settings = prm["solver"];
  if (!settings["flow"].get<bool>()) throw SceneError("solver.flow", "the sphere's plume needs flow");
  // The plume's speed scales with the free-fall speed sqrt(g beta dT D).
  if (settings["reference_speed"].get<double>() == 0.0)
    settings["reference_speed"] = std::sqrt(g * beta * dT * D);

  // The sphere of the conductor, so the air's temperature is T_s at its surface (as the cavity's walls).
  Json doc = convection_scene("validation/air-sphere", {2 * half_w, 2 * half_w, below + above},
                              {"-x", "+x", "-y", "+y", "-z", "+z"}, g, dx, settings, Tinf, beta,
                              prm["buoyancy"].get<std::string>(), prm);
  doc["air"]["face_exchange_time"] = prm["face_exchange_time"];
  doc["solids"] = {{{"shape", "sphere"},
                    {"material", "conductor"},
                    {"centre", {centre.x(), centre.y(), centre.z()}},
                    {"radius", 0.5 * D},
                    {"temperature", Ts},
                    {"hold_temperature", true}}};
  const Scene scene = scene_from_json(doc);
  int held = -1;
  for (std::size_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].held) held = static_cast<int>(m);
  if (held < 0) throw Error("air-sphere: the held sphere is missing from the scene");

  Solver solver(cl, scene, initial_state(scene));
  solver.warm_up();
  const double t_end = prm["time"];
  const int samples = prm["samples"];
  const double window = double(prm["average"]) * t_end, t_avg = t_end - window;
  std::vector<double> q;
  const auto t0 = std::chrono::steady_clock::now();
  int next = 0;
  while (solver.time() < t_end * (1.0 - 1e-12)) {
    solver.step();
    if (next < samples && solver.time() >= t_avg + window * (next + 0.5) / samples) {
      // Held power is what the held solid gives the rest: the air gives the cold sphere -that.
      const double p = solver.held_power()[static_cast<std::size_t>(held)];
      q.push_back(Ts < Tinf ? -p : p);
      ++next;
    }
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (q.size() < 2) throw Error("air-sphere: fewer than two heat-flux samples; raise time or average");
  auto mean = [&](std::size_t b, std::size_t e) {
    double s = 0;
    for (std::size_t i = b; i < e; ++i) s += q[i];
    return s / double(e - b);
  };
  const double scale = 1.0 / (M_PI * D * k * dT);  // Nu = h D / k, h = Q / (pi D^2 dT)
  const std::size_t n = q.size(), half = n / 2;
  const double nusselt = scale * mean(0, n);
  const double drift = scale * (mean(half, n) - mean(0, half));
  const double ref = churchill_sphere_nusselt(ra, pr);
  const double gate = prm["nusselt_gate"];

  CaseResult r;
  r.particles = solver.size();
  r.steps = solver.steps();
  r.wall_s = wall_s;
  r.metrics = {
      {"nusselt", {nusselt, ref, std::abs(nusselt - ref) / ref, gate}},
      // The window's second half minus its first: a run still settling shows here.
      {"nusselt_drift", {drift, 0.0, std::abs(drift) / ref, gate}},
  };
  return r;
}

}  // namespace

ValidationCase air_sphere_case() {
  return {
      "air-sphere",
      "a cold sphere held in still air, natural convection (Churchill's correlation): mean Nusselt number "
      "within 20 %; res = particles across the diameter",
      10, params, run};
}

}  // namespace thaw
