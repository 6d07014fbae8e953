#include "sim/validation/case.h"

#include <cstring>

#include "sim/error.h"
#include "sim/run_digest.h"
#include "sim/stage_timers.h"

namespace thaw {

bool CaseResult::passed() const {
  if (metrics.empty()) return false;
  for (const auto& [key, m] : metrics)
    if (!m.passed()) return false;
  return true;
}

Json CaseResult::to_json() const {
  Json j;
  j["case"] = name;
  j["passed"] = passed();
  j["res"] = res;
  j["particles"] = particles;
  j["steps"] = steps;
  j["wall_s"] = wall_s;
  Json m = Json::object();
  for (const auto& [key, r] : metrics)
    m[key] = {{"value", r.value}, {"reference", r.reference}, {"error", r.error}, {"gate", r.gate}};
  j["metrics"] = m;
  return j;
}

const std::vector<ValidationCase>& validation_cases() {
  static const std::vector<ValidationCase> cases = {
      hydrostatic_case(),       dam_break_case(),        conduction_case(),    stefan_case(),
      rigid_spin_case(),        floating_case(),         cavity_case(),        jet_case(),
      air_sphere_case(),        air_water_case(),        surface_area_case(),  ambient_sphere_case(),
      laplace_case(),           drop_oscillation_case(), contact_angle_case(), diffusion_bulk_case(),
      brine_melting_case(),     brine_freezing_case(),   conservation_case(),  adsorption_case(),
      surface_diffusion_case(), coating_case(),          cleansing_case(),     marangoni_case()};
  return cases;
}

const ValidationCase& find_case(const std::string& name) {
  std::string names;
  for (const auto& c : validation_cases()) {
    if (c.name == name) return c;
    names += (names.empty() ? "" : ", ") + c.name;
  }
  throw Error("unknown validation case '" + name + "' (cases: " + names + ")");
}

Json case_parameters(const ValidationCase& c, const std::vector<std::string>& overrides) {
  const Field schema = c.params();
  Json doc = Json::object();
  for (const auto& o : overrides) apply_override(doc, o, schema);
  validate(doc, schema, "");
  return doc;
}

CaseResult run_validation(ClRuntime& cl, const std::string& name, int res,
                          const std::vector<std::string>& overrides) {
  const auto& c = find_case(name);
  if (res < 0) throw Error("--res must be positive");
  const Json params = case_parameters(c, overrides);
  CaseResult r = c.run(cl, params, res > 0 ? res : c.default_res);
  r.name = c.name;
  r.res = res > 0 ? res : c.default_res;
  return r;
}

namespace {

// Both runs under digests of `detail`; where the second parted from the first, or "".
std::string compare_twice(ClRuntime& cl, const std::string& name, int res,
                          const std::vector<std::string>& sets, RunDigest::Detail detail, std::uint64_t steps,
                          CaseResult (&result)[2]) {
  auto run = [&](CaseResult& r) {
    try {
      r = run_validation(cl, name, res, sets);
    } catch (const RunDigest::Stopped&) {
      r = CaseResult{};
    }
  };
  const auto t0 = Clock::now();
  RunDigest first(detail, steps);
  run(result[0]);
  RunDigest second(detail, steps);
  run(result[1]);
  result[0].wall_s = seconds_since(t0);
  for (const RunDigest::Entry& e : first.entries()) result[0].steps = std::max(result[0].steps, e.step);
  std::string difference = first.first_difference(second);
  const auto& a = result[0].metrics;
  const auto& b = result[1].metrics;
  for (std::size_t k = 0; difference.empty() && k < a.size(); ++k)
    if (k >= b.size() || std::memcmp(&a[k].second.value, &b[k].second.value, sizeof(double)) != 0)
      difference = "the metric " + a[k].first + " differs";
  return difference;
}

}  // namespace

Repeated run_validation_twice(ClRuntime& cl, const std::string& name, int res,
                              const std::vector<std::string>& overrides, std::uint64_t steps) {
  // The solvers' last states first (cheap); where they differ, again with every stage's, to say where.
  CaseResult r[2];
  Repeated out;
  out.difference = compare_twice(cl, name, res, overrides, RunDigest::Detail::Ends, steps, r);
  if (!out.difference.empty()) {
    const std::string where = compare_twice(cl, name, res, overrides, RunDigest::Detail::Stages, steps, r);
    out.difference = where.empty() ? out.difference +
                                         "; two more runs, compared stage by stage, agreed: the runs "
                                         "differ only now and then"
                                   : where;
  }
  out.first = r[0];
  out.first.name = name;
  out.first.res = res > 0 ? res : find_case(name).default_res;
  return out;
}

}  // namespace thaw

namespace thaw {

Field solver_schema_with(const std::vector<std::pair<std::string, Json>>& defaults) {
  Field f = solver_schema();
  for (const auto& [key, value] : defaults) {
    bool found = false;
    for (auto& child : f.fields)
      if (child.key == key) child.def(value), found = true;
    if (!found) throw Error("solver_schema_with: no solver field '" + key + "'");
  }
  return f;
}

Field air_case_schema(std::vector<Field> own) {
  own.push_back(number("density", "rho of the air").in("kg/m^3").def(1.2).above(0));
  own.push_back(number("viscosity", "mu of the air").in("Pa s").def(1.8e-5).above(0));
  own.push_back(number("conductivity", "k of the air").in("W/m/K").def(0.025).above(0));
  own.push_back(number("specific_heat", "c of the air").in("J/kg/K").def(1006.0).above(0));
  return object("", std::move(own));
}

Json air_material(const Json& params) {
  return {{"kind", "air"},
          {"density", params["density"]},
          {"viscosity", params["viscosity"]},
          {"conductivity", params["conductivity"]},
          {"specific_heat", params["specific_heat"]}};
}

Json air_insulator(const Json& params) {
  return {{"kind", "solid"},
          {"density", params["density"]},
          {"conductivity", 0.0},
          {"specific_heat", params["specific_heat"]},
          {"adiabatic", true}};
}

Json convection_scene(const std::string& name, const Eigen::Vector3d& max, const Json& walls, double g,
                      double dx, const Json& solver, double temperature, double beta,
                      const std::string& buoyancy, const Json& params) {
  return {
      {"name", name},
      {"domain",
       {{"min", {0.0, 0.0, 0.0}},
        {"max", {max.x(), max.y(), max.z()}},
        {"walls", walls},
        {"wall_material", "insulator"}}},
      {"gravity", {0.0, 0.0, -g}},
      {"spacing", dx},
      {"solver", solver},
      {"ambient", {{"temperature", temperature}}},
      {"materials",
       {{"air", air_material(params)},
        // Adiabatic, the air beside it conducting along it as in bulk (heat.cl).
        {"insulator", air_insulator(params)},
        {"conductor",
         {{"kind", "solid"},
          {"density", params["density"]},
          {"conductivity", params["conductivity"]},
          {"specific_heat", params["specific_heat"]}}}}},
      {"air",
       {{"material", "air"},
        {"temperature", temperature},
        {"buoyancy", buoyancy},
        {"reference_temperature", temperature},
        {"expansion", beta}}},
      {"solids", Json::array()},
  };
}

Line least_squares_line(const std::vector<double>& x, const std::vector<double>& y,
                        const std::vector<double>& w) {
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double wk = w.empty() ? 1.0 : w[k];
    sw += wk, sx += wk * x[k], sy += wk * y[k], sxx += wk * x[k] * x[k], sxy += wk * x[k] * y[k];
  }
  Line l;
  l.slope = (sw * sxy - sx * sy) / (sw * sxx - sx * sx);
  l.intercept = (sy - l.slope * sx) / sw;
  return l;
}

}  // namespace thaw
