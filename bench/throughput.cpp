#include "bench/throughput.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bench/reference_density.h"
#include "sim/solver.h"

namespace thaw {

Scene throughput_scene(std::size_t fluid) {
  // Tank 1 x 0.5 x 0.7 m, water 0.6 x 0.5 x 0.6 m in one end: fluid volume 0.18 m^3.
  const double dx = std::cbrt(0.18 / double(fluid));
  Json doc = {
      {"name", "bench/throughput"},
      {"domain", {{"min", {0, 0, 0}}, {"max", {1.0, 0.5, 0.7}}, {"walls", {"-x", "+x", "-y", "+y", "-z"}},
                  {"wall_material", "wall"}}},
      {"spacing", dx},
      {"materials", {{"water", {{"kind", "fluid"}, {"density", 1000.0}, {"viscosity", 1e-3}}},
                     {"wall", {{"kind", "solid"}, {"density", 2500.0}}}}},
      {"fluids", {{{"material", "water"}, {"box", {{"min", {0, 0, 0}}, {"max", {0.6, 0.5, 0.6}}}}}}},
  };
  return scene_from_json(doc);
}

namespace {

// Mean candidates visited and neighbours found per fluid particle (every 7th, for speed).
std::pair<double, double> neighbour_counts(const HostParticles& p, const std::vector<std::uint32_t>& starts,
                                           const ReferenceGrid& g, float H) {
  double cand = 0, neigh = 0;
  std::size_t count = 0;
  const int dims[3] = {g.nx, g.ny, g.nz};
  for (std::size_t i = 0; i < p.size(); i += 7) {
    if (p.phase[i] == static_cast<std::uint8_t>(Phase::Solid)) continue;
    int c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(int(std::floor((p.position[i][a] - g.origin[a]) * g.inv_cell)), 0, dims[a] - 1);
    for (int z = std::max(c[2] - g.reach, 0); z <= std::min(c[2] + g.reach, g.nz - 1); ++z)
      for (int y = std::max(c[1] - g.reach, 0); y <= std::min(c[1] + g.reach, g.ny - 1); ++y) {
        const int row = (z * g.ny + y) * g.nx;
        for (auto j = starts[row + std::max(c[0] - g.reach, 0)]; j < starts[row + std::min(c[0] + g.reach, g.nx - 1) + 1];
             ++j) {
          const float dx = p.position[i][0] - p.position[j][0], dy = p.position[i][1] - p.position[j][1],
                      dz = p.position[i][2] - p.position[j][2];
          cand += 1;
          neigh += dx * dx + dy * dy + dz * dz < H * H ? 1 : 0;
        }
      }
    ++count;
  }
  return {cand / double(std::max<std::size_t>(count, 1)), neigh / double(std::max<std::size_t>(count, 1))};
}

}  // namespace

Json bench_throughput(ClRuntime& cl, const ThroughputOptions& o, bool print) {
  Json out;
  out["device"] = cl.description();
  out["omp_threads"] = omp_get_max_threads();
  out["steps"] = o.steps;
  out["unit"] = "wall microseconds per fluid particle-step";
  Json rows = Json::array();
  if (print)
    std::printf("%-9s %-9s %8s %8s %8s %8s %8s %8s | %9s %6s\n", "fluid", "total", "grid", "density", "forces",
                "dt", "integr", "step", "ref dens", "ratio");
  for (std::size_t size : o.sizes) {
    const Scene scene = throughput_scene(size);
    Solver solver(cl, scene, initial_state(scene));
    solver.warm_up();
    for (int i = 0; i < 3; ++i) solver.step();  // past the first, untypical steps
    solver.timers().reset();
    const auto t0 = Clock::now();
    for (int i = 0; i < o.steps; ++i) solver.step();
    const double wall = seconds_since(t0);
    const auto p = solver.particles();
    const double fluid = double(p.count(Phase::Water));
    const double per = 1e6 / (fluid * o.steps);

    // The reference loop on exactly the data the device's density stage saw in the last step.
    solver.build_grid();
    solver.compute_density();
    const auto sorted = solver.particles();
    const auto starts = solver.cell_starts();
    const auto device_rho = solver.densities();
    const auto& gi = solver.grid();
    ReferenceGrid g{{gi.origin.x(), gi.origin.y(), gi.origin.z()}, 1.0f / gi.cell, gi.nx, gi.ny, gi.nz, gi.reach};
    std::vector<float> rho;
    reference_density(sorted.position, sorted.phase, starts, g, solver.constants().support,
                      solver.constants().rest_density, rho);  // warm caches and threads
    const int reps = std::max(3, o.steps);
    const auto r0 = Clock::now();
    for (int r = 0; r < reps; ++r)
      reference_density(sorted.position, sorted.phase, starts, g, solver.constants().support,
                        solver.constants().rest_density, rho);
    const double ref_us = 1e6 * seconds_since(r0) / (fluid * reps);
    double max_diff = 0;
    for (std::size_t i = 0; i < rho.size(); ++i)
      max_diff = std::max(max_diff, double(std::abs(rho[i] - device_rho[i]) / rho[i]));

    const auto& t = solver.timers();
    Json row;
    row["fluid_particles"] = std::size_t(fluid);
    row["total_particles"] = p.size();
    Json st;
    for (int s = 0; s < static_cast<int>(Stage::Count); ++s)
      st[kStageNames[s]] = t.seconds(static_cast<Stage>(s)) * per;
    st["step"] = wall * per;
    row["stage_us"] = st;
    row["reference_density_us"] = ref_us;
    row["density_ratio"] = double(st["density"]) / ref_us;
    row["reference_max_rel_diff"] = max_diff;
    const auto [cand, neigh] = neighbour_counts(sorted, starts, g, solver.constants().support);
    row["candidates_per_particle"] = cand;
    row["neighbours_per_particle"] = neigh;
    rows.push_back(row);
    if (print)
      std::printf("%-9zu %-9zu %8.4f %8.4f %8.4f %8.4f %8.4f %8.4f | %9.4f %6.2f\n", std::size_t(fluid), p.size(),
                  double(st["grid"]), double(st["density"]), double(st["forces"]), double(st["time_step"]),
                  double(st["integrate"]), double(st["step"]), ref_us, double(row["density_ratio"]));
    std::fflush(stdout);
  }
  if (print) std::printf("(wall us per fluid particle-step; ref dens: hand-written C++/OpenMP density loop, %d threads)\n", omp_get_max_threads());
  out["sizes"] = rows;
  return out;
}

}  // namespace thaw
