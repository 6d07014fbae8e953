// Surface area (issue 19, docs/SURFACE.md): the surface stage's areas summed over particle-sampled shapes
// against the shapes' own areas, with the lattice turned three ways. The sphere (radius R = res spacings)
// and the box (half-side R) are cut from a lattice turned about the origin, so their particles differ with
// the turn (and a shift) while the shape does not: reference 4 pi R^2 and 24 R^2. The sheets, one and two
// layers thick, are a square layer lattice turned as a whole: reference both faces and the rim, 2 L^2 + 4 L t
// with L = n dx and t = layers dx. Metrics: each shape's error of the mean over the turns, and its spread
// (max - min) / mean. The heat-only mode holds the particles; nothing is stepped.
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/validation/case.h"

namespace thaw {
namespace {

Field params() {
  return object(
      "", {
              number("radius", "R: the sphere's radius and the box's half-side").in("m").def(0.01).above(0),
              choice("model", {"brackbill1992", "orthmann2013"}, "heat.exposed_area: the area model")
                  .def("brackbill1992"),
              number("area_gate", "Gate on each shape's error of the mean area over the turns")
                  .def(0.02)
                  .above(0),
              number("spread_gate", "Gate on each shape's spread over the turns").def(0.01).above(0),
              solver_schema_with({{"flow", false}, {"max_dt", 3600.0}}),
          });
}

std::vector<Eigen::Matrix3d> turns() {
  using Eigen::AngleAxisd;
  using Eigen::Vector3d;
  return {Eigen::Matrix3d::Identity(), AngleAxisd(M_PI / 6, Vector3d::UnitX()).toRotationMatrix(),
          (AngleAxisd(0.35, Vector3d::UnitZ()) * AngleAxisd(0.61, Vector3d::UnitY()) *
           AngleAxisd(0.87, Vector3d::UnitX()))
              .toRotationMatrix()};
}

// The summed area of the particles at `points` (ice at -10 °C in still air).
double summed_area(ClRuntime& cl, const Json& prm, const std::vector<Eigen::Vector3d>& points, double dx,
                   double& wall_s) {
  double reach = 0;
  for (const auto& p : points) reach = std::max(reach, p.cwiseAbs().maxCoeff());
  const double L = reach + 4 * dx;
  const Json ice = {
      {"density", 1000.0}, {"conductivity", 2.22}, {"specific_heat", 2050.0}, {"latent_heat", 334000.0}};
  const Json block = {{"material", "ice"},
                      {"box", {{"min", {-dx, -dx, -dx}}, {"max", {dx, dx, dx}}}},
                      {"temperature", -10.0}};
  const Scene scene = scene_from_json(ice_in_air_scene("validation/surface-area", L, dx, prm["solver"], 10.0,
                                                       20.0, prm["model"], ice, block));
  SimState st = initial_state(scene);
  HostParticles& p = st.particles;
  const HostParticles one = p;
  p.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    p.position[i] = {float(points[i].x()), float(points[i].y()), float(points[i].z()), one.position[0][3]};
    p.velocity[i] = one.velocity[0];
    p.density[i] = one.density[0];
    p.phase[i] = one.phase[0];
    p.material[i] = one.material[0];
    p.id[i] = static_cast<std::uint32_t>(i);
    p.enthalpy[i] = one.enthalpy[0];
    p.anchored[i] = one.anchored[0];
  }
  const auto t0 = std::chrono::steady_clock::now();
  Solver solver(cl, scene, st);
  solver.warm_up();
  const std::vector<float> a = solver.surface_areas();
  wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (a.size() != points.size()) throw Error("surface-area: the scene built no surface stage");
  double sum = 0;
  for (float x : a) sum += x;
  return sum;
}

CaseResult run(ClRuntime& cl, const Json& prm, int res) {
  const double R = prm["radius"], dx = R / res;
  const int m = static_cast<int>(std::ceil(R * std::sqrt(3.0) / dx)) + 2;
  CaseResult r;
  double wall = 0;
  struct Shape {
    std::string name;
    double reference;
    std::vector<double> ratios;
  };
  std::vector<Shape> shapes = {{"sphere", 4 * M_PI * R * R, {}}, {"box", 24 * R * R, {}}};
  const int n = 2 * res;  // the sheets' side in particles
  for (int layers : {1, 2}) {
    const double side = n * dx, t = layers * dx;
    shapes.push_back({"sheet" + std::to_string(layers), 2 * side * side + 4 * side * t, {}});
  }
  // Each turn also shifts the lattice, so the sphere's particles differ with it (a sphere about a lattice
  // point is the same set turned).
  const std::vector<Eigen::Vector3d> shifts = {{0, 0, 0}, {0.21, 0.37, 0.13}, {0.43, 0.11, 0.29}};
  const std::vector<Eigen::Matrix3d> all = turns();
  for (std::size_t u = 0; u < all.size(); ++u) {
    const Eigen::Matrix3d& turn = all[u];
    std::vector<Eigen::Vector3d> sphere, box;
    for (int i = -m; i < m; ++i)
      for (int j = -m; j < m; ++j)
        for (int k = -m; k < m; ++k) {
          const Eigen::Vector3d x = turn * ((Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5) + shifts[u]) * dx);
          if (x.norm() < R) sphere.push_back(x);
          if (x.cwiseAbs().maxCoeff() < R) box.push_back(x);
        }
    shapes[0].ratios.push_back(summed_area(cl, prm, sphere, dx, wall) / shapes[0].reference);
    shapes[1].ratios.push_back(summed_area(cl, prm, box, dx, wall) / shapes[1].reference);
    for (int layers : {1, 2}) {
      std::vector<Eigen::Vector3d> sheet;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          for (int k = 0; k < layers; ++k)
            sheet.push_back(
                turn * (Eigen::Vector3d(i - 0.5 * (n - 1), j - 0.5 * (n - 1), k - 0.5 * (layers - 1)) * dx));
      Shape& s = shapes[static_cast<std::size_t>(1 + layers)];
      s.ratios.push_back(summed_area(cl, prm, sheet, dx, wall) / s.reference);
      r.particles += sheet.size();
    }
    r.particles += sphere.size() + box.size();
  }
  for (const Shape& s : shapes) {
    double mean = 0, lo = 1e300, hi = -1e300;
    for (double x : s.ratios) {
      mean += x / double(s.ratios.size());
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    r.metrics.push_back({s.name + "_area", {mean, 1.0, std::abs(mean - 1.0), prm["area_gate"]}});
    r.metrics.push_back({s.name + "_spread", {hi - lo, 0.0, (hi - lo) / mean, prm["spread_gate"]}});
  }
  r.wall_s = wall;
  return r;
}

}  // namespace

Json ice_in_air_scene(const std::string& name, double half, double dx, const Json& solver, double h,
                      double air_temperature, const Json& model, const Json& ice, const Json& ice_object) {
  Json ice_material = ice;
  ice_material["kind"] = "ice";
  ice_material["melts_into"] = "water";
  ice_material["melting_point"] = 0.0;
  return {
      {"name", name},
      {"domain", {{"min", {-half, -half, -half}}, {"max", {half, half, half}}}},
      {"gravity", {0, 0, 0}},
      {"spacing", dx},
      {"solver", solver},
      {"ambient", {{"heat_transfer_coefficient", h}, {"temperature", air_temperature}}},
      {"heat", {{"exposed_area", model}}},
      {"materials",
       {{"water",
         {{"kind", "fluid"}, {"density", 1000.0}, {"conductivity", 0.56}, {"specific_heat", 4217.0}}},
        {"ice", ice_material}}},
      {"ice", {ice_object}},
  };
}

ValidationCase surface_area_case() {
  return {"surface-area",
          "Summed particle areas of a sphere, a box and sheets one and two particles thick against their own "
          "areas, over three turns of the lattice (gate 2 %, spread 1 %); res = particles across R. Fails at "
          "every res measured: the sphere passes from res 16, the box from 40, the two-layer sheet at none "
          "(-16 % at res 10, -4.6 % at 40, falling as 1/res: docs/SURFACE.md)",
          10, params, run};
}

}  // namespace thaw
