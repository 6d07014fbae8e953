#include "bench/throughput.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <thread>

#include "bench/reference_density.h"
#include "bench/reference_heat.h"
#include "sim/solver.h"
#include "sim/thermal.h"
#include "sim/validation/tank_scene.h"

namespace thaw {

Scene throughput_scene(std::size_t fluid) {
  // Tank 1 x 0.5 x 0.7 m, water 0.6 x 0.5 x 0.6 m in one end: fluid volume 0.18 m^3. The walled
  // extents (length and width) are rounded to whole spacings, as walls need; the water fills the width.
  const double dx = std::cbrt(0.18 / double(fluid));
  const double length = std::max(2.0, std::round(1.0 / dx)) * dx,
               width = std::max(1.0, std::round(0.5 / dx)) * dx;
  TankScene t{"bench/throughput", {length, width, 0.7}, {0.6, width, 0.6}, dx};
  t.heat = true;  // the whole step: water and heat (ambient air and conduction into the walls)
  Json doc = tank_scene_json(t);
  // The reference heat loop (bench/reference_heat.h) is Iwasaki's: it counts each particle's exposed faces
  // from its neighbours, as the heat pass does with iwasaki2010. The surface stage that brackbill1992 (the
  // default) needs is benchmarked on its own block (docs/SURFACE.md, bench/scenes/block.json).
  doc["heat"]["exposed_area"] = "iwasaki2010";
  return scene_from_json(doc);
}

namespace {

struct WalkCounts {
  double candidates = 0;  // particles in the visited cells
  double lane_slots = 0;  // candidates rounded up to whole 8-lane loads, row by row
  double neighbours = 0;  // candidates within the support
};

// Mean counts per fluid particle (every 7th, for speed), over the walk the device does.
WalkCounts walk_counts(const ReferenceParticles& p, const ReferenceGrid& g, float H) {
  WalkCounts w;
  std::size_t count = 0;
  const int dims[3] = {g.nx, g.ny, g.nz};
  for (std::size_t i = 0; i < p.size(); i += 7) {
    if (p.phase[i] == static_cast<std::uint8_t>(Phase::Solid)) continue;
    int c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(int(std::floor((p.pos[i][a] - g.origin[a]) * g.inv_cell)), 0, dims[a] - 1);
    for (int z = std::max(c[2] - g.reach, 0); z <= std::min(c[2] + g.reach, g.nz - 1); ++z)
      for (int y = std::max(c[1] - g.reach, 0); y <= std::min(c[1] + g.reach, g.ny - 1); ++y) {
        const int row = (z * g.ny + y) * g.nx;
        const auto jb = p.cell_start[row + std::max(c[0] - g.reach, 0)];
        const auto je = p.cell_start[row + std::min(c[0] + g.reach, g.nx - 1) + 1];
        w.lane_slots += double((je - jb + 7) / 8 * 8);
        for (auto j = jb; j < je; ++j) {
          const float dx = p.pos[i][0] - p.pos[j][0], dy = p.pos[i][1] - p.pos[j][1],
                      dz = p.pos[i][2] - p.pos[j][2];
          w.candidates += 1;
          w.neighbours += dx * dx + dy * dy + dz * dz < H * H ? 1 : 0;
        }
      }
    ++count;
  }
  const double c = double(std::max<std::size_t>(count, 1));
  w.candidates /= c;
  w.lane_slots /= c;
  w.neighbours /= c;
  return w;
}

double max_rel_diff(const std::vector<float>& ref, const std::vector<float>& dev) {
  double d = 0;
  for (std::size_t i = 0; i < ref.size(); ++i)
    d = std::max(d, double(std::abs(ref[i] - dev[i])) / std::max(double(std::abs(dev[i])), 1e-30));
  return d;
}

// Relative to the largest |value|: pressures are 0 wherever the EOS clamps, so per-particle relative
// differences mean nothing there.
double max_diff_of_range(const std::vector<float>& ref, const std::vector<float>& dev) {
  double d = 0, top = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    d = std::max(d, double(std::abs(ref[i] - dev[i])));
    top = std::max(top, double(std::abs(dev[i])));
  }
  return top > 0 ? d / top : d;
}

struct HeatComparison {
  double device_us = 0, lanes_us = 0, scalar_us = 0;  // per fluid particle
  double lanes_diff = 0, scalar_diff = 0;             // max |Q_ref - Q_dev| / max |Q_dev|
  double max_q = 0;                                   // max |Q_dev| [W]
};

// The heat stage against the reference conduction loops, on the sorted state build_grid() and
// compute_density() left. The device does not expose Q: one compute_heat(dt) adds Q dt_heat / mass to
// each particle's enthalpy, so Q_dev = (h_after - h_before) mass / dt_heat, with the inputs
// (T, k, V) of that same call (thermal_state runs first in compute_heat). The scene has no dryers,
// lamps, held or wall-heated materials, so Q = conduction + ambient air exchange.
HeatComparison compare_heat(ClRuntime& cl, Solver& solver, const Scene& scene, const ReferenceParticles& rp,
                            const ReferenceGrid& g, double fluid, int reps,
                            const std::function<void()>& pause) {
  HeatComparison c;
  const auto& k = solver.constants();
  const auto table = material_thermal_table(scene, k.rest_density);
  const float dt_heat = static_cast<float>(scene.heat.time_scale * solver.dt());
  const auto before = solver.particles();
  solver.compute_heat(solver.dt());
  cl.queue().finish();
  const auto after = solver.particles();
  const auto in = solver.thermal_inputs();
  std::vector<std::uint8_t> air(before.size());
  std::vector<float> q_dev(before.size());
  for (std::size_t i = 0; i < before.size(); ++i) {
    const auto& m = table[before.material[i]];
    air[i] = (m.flags & THAW_MAT_AIR_EXCHANGE) ? 1 : 0;
    const double dh = (double(after.enthalpy[i][0]) - before.enthalpy[i][0]) +
                      (double(after.enthalpy[i][1]) - before.enthalpy[i][1]);
    q_dev[i] = static_cast<float>(dh * (before.position[i][3] * m.thermal_mass_scale) / dt_heat);
  }
  const ReferenceThermal rt(in.temperature, in.conductivity, in.volume, air);
  ReferenceHeatParams prm;
  prm.H = k.support;
  prm.eta2 = 0.01f * k.smoothing * k.smoothing;
  const float dx = static_cast<float>(scene.spacing);
  prm.exposed_r2 = 1.44f * dx * dx;
  prm.wendland = scene.solver.kernel == KernelFunction::WendlandC2;
  prm.face_area = dx * dx;
  prm.ambient_temperature = static_cast<float>(scene.heat.ambient_temperature);
  prm.ambient_coefficient = static_cast<float>(scene.heat.ambient_coefficient);

  ReferenceHeat lanes, scalar;
  reference_conduction_lanes(rp, g, rt, prm, lanes);  // warm caches and threads
  reference_conduction(rp, g, rt, prm, scalar);
  // Timed with dt = 0: the kernel does all its work but adds no heat.
  double dev_best = std::numeric_limits<double>::infinity(), lanes_best = dev_best, scalar_best = dev_best;
  for (int r = 0; r < reps; ++r) {
    pause();
    auto t = Clock::now();
    solver.compute_heat(0.0);
    cl.queue().finish();
    dev_best = std::min(dev_best, seconds_since(t));
    pause();
    t = Clock::now();
    reference_conduction_lanes(rp, g, rt, prm, lanes);
    lanes_best = std::min(lanes_best, seconds_since(t));
    pause();
    t = Clock::now();
    reference_conduction(rp, g, rt, prm, scalar);
    scalar_best = std::min(scalar_best, seconds_since(t));
  }
  c.device_us = 1e6 * dev_best / fluid;
  c.lanes_us = 1e6 * lanes_best / fluid;
  c.scalar_us = 1e6 * scalar_best / fluid;
  std::vector<float> q_lanes(q_dev.size()), q_scalar(q_dev.size());
  for (std::size_t i = 0; i < q_dev.size(); ++i) {
    q_lanes[i] = lanes.q_conduction[i] + lanes.q_ambient[i];
    q_scalar[i] = scalar.q_conduction[i] + scalar.q_ambient[i];
    c.max_q = std::max(c.max_q, double(std::abs(q_dev[i])));
  }
  c.lanes_diff = max_diff_of_range(q_lanes, q_dev);
  c.scalar_diff = max_diff_of_range(q_scalar, q_dev);
  return c;
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
    std::printf("%-9s %-9s %8s %8s %8s %8s %8s %8s %8s | %8s %8s %8s %6s\n", "fluid", "total", "grid",
                "density", "forces", "dt", "heat", "integr", "step", "dens iso", "ref lane", "ref scal",
                "ratio");
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

    // The reference loops on exactly the data the device's density stage sees: the state after the
    // timed steps, sorted. Device and reference runs alternate, and each keeps its fastest run, so a
    // burst of load on the machine hits both alike.
    solver.build_grid();
    solver.compute_density();
    cl.queue().finish();
    const auto sorted = solver.particles();
    const ReferenceParticles rp(sorted.position, sorted.phase, solver.cell_starts());
    const auto device_rho = solver.densities();
    const auto device_state = solver.pressure_state();
    const auto& gi = solver.grid();
    const auto& k = solver.constants();
    const ReferenceGrid g{
        {gi.origin.x(), gi.origin.y(), gi.origin.z()}, 1.0f / gi.cell, gi.nx, gi.ny, gi.nz, gi.reach};
    ReferenceParams prm;
    prm.H = k.support;
    prm.rho0 = k.rest_density;
    prm.B = k.stiffness;
    prm.gamma = static_cast<float>(scene.solver.gamma);
    prm.tait = scene.solver.eos == Eos::Tait;
    prm.wendland = scene.solver.kernel == KernelFunction::WendlandC2;
    prm.visc_fluid = k.visc_fluid;
    prm.visc_boundary = k.visc_boundary;
    ReferenceDensity lanes, scalar;
    reference_density_lanes(rp, g, prm, lanes);  // warm caches and threads
    reference_density_scalar(rp, g, prm, scalar);
    const int reps = std::max(5, o.steps);
    double dev_best = std::numeric_limits<double>::infinity(), lanes_best = dev_best, scalar_best = dev_best;
    // Both runtimes keep their worker threads spinning a while after a parallel section; a pause
    // before each timed run lets the other's threads go to sleep first.
    const std::function<void()> pause = [] { std::this_thread::sleep_for(std::chrono::milliseconds(20)); };
    for (int r = 0; r < reps; ++r) {
      pause();
      auto t = Clock::now();
      solver.compute_density();
      cl.queue().finish();
      dev_best = std::min(dev_best, seconds_since(t));
      pause();
      t = Clock::now();
      reference_density_lanes(rp, g, prm, lanes);
      lanes_best = std::min(lanes_best, seconds_since(t));
      pause();
      t = Clock::now();
      reference_density_scalar(rp, g, prm, scalar);
      scalar_best = std::min(scalar_best, seconds_since(t));
    }
    const double dev_us = 1e6 * dev_best / fluid, lanes_us = 1e6 * lanes_best / fluid,
                 scalar_us = 1e6 * scalar_best / fluid;
    const double ref_us = std::min(lanes_us, scalar_us);
    std::vector<float> dev_p(device_state.size()), lanes_p(lanes.state.size()), scalar_p(scalar.state.size());
    for (std::size_t i = 0; i < device_state.size(); ++i) {
      dev_p[i] = device_state[i][3];
      lanes_p[i] = lanes.state[i][3];
      scalar_p[i] = scalar.state[i][3];
    }

    // The heat stage against its reference loops, on the same sorted data (and the same alternation).
    const HeatComparison heat = compare_heat(cl, solver, scene, rp, g, fluid, reps, pause);
    const double heat_ref_us = std::min(heat.lanes_us, heat.scalar_us);

    const auto& t = solver.timers();
    Json row;
    row["fluid_particles"] = std::size_t(fluid);
    row["total_particles"] = p.size();
    Json st;
    for (int s = 0; s < static_cast<int>(Stage::Count); ++s)
      st[kStageNames[s]] = t.seconds(static_cast<Stage>(s)) * per;
    st["step"] = wall * per;
    row["stage_us"] = st;
    row["density_isolated_us"] = dev_us;
    row["reference_density_lanes_us"] = lanes_us;
    row["reference_density_scalar_us"] = scalar_us;
    row["reference_density_us"] = ref_us;
    row["density_ratio"] = dev_us / ref_us;
    row["reference_lanes_max_rel_diff_rho"] = max_rel_diff(lanes.rho, device_rho);
    row["reference_scalar_max_rel_diff_rho"] = max_rel_diff(scalar.rho, device_rho);
    row["reference_lanes_max_diff_p_of_max_p"] = max_diff_of_range(lanes_p, dev_p);
    row["reference_scalar_max_diff_p_of_max_p"] = max_diff_of_range(scalar_p, dev_p);
    row["heat_isolated_us"] = heat.device_us;
    row["reference_heat_lanes_us"] = heat.lanes_us;
    row["reference_heat_scalar_us"] = heat.scalar_us;
    row["reference_heat_us"] = heat_ref_us;
    row["heat_ratio"] = heat.device_us / heat_ref_us;
    row["reference_heat_lanes_max_rel_diff_q"] = heat.lanes_diff;
    row["reference_heat_scalar_max_rel_diff_q"] = heat.scalar_diff;
    row["reference_heat_max_rel_diff_q"] = std::max(heat.lanes_diff, heat.scalar_diff);
    row["heat_max_q_w"] = heat.max_q;
    const WalkCounts w = walk_counts(rp, g, k.support);
    row["grid_reach"] = gi.reach;
    row["candidates_per_particle"] = w.candidates;
    row["lane_slots_per_particle"] = w.lane_slots;
    row["neighbours_per_particle"] = w.neighbours;
    rows.push_back(row);
    if (print) {
      std::printf("%-9zu %-9zu %8.4f %8.4f %8.4f %8.4f %8.4f %8.4f %8.4f | %8.4f %8.4f %8.4f %6.2f\n",
                  std::size_t(fluid), p.size(), double(st["grid"]), double(st["density"]),
                  double(st["forces"]), double(st["time_step"]), double(st["heat"]), double(st["integrate"]),
                  double(st["step"]), dev_us, lanes_us, scalar_us, dev_us / ref_us);
      std::printf(
          "          check vs device: rho max rel diff %.2e (lanes) %.2e (scalar); p max diff / max p "
          "%.2e / %.2e; per fluid particle %.1f candidates (%.1f lane slots), %.1f neighbours\n",
          double(row["reference_lanes_max_rel_diff_rho"]), double(row["reference_scalar_max_rel_diff_rho"]),
          double(row["reference_lanes_max_diff_p_of_max_p"]),
          double(row["reference_scalar_max_diff_p_of_max_p"]), w.candidates, w.lane_slots, w.neighbours);
      std::printf(
          "          heat: iso %.4f, ref lane %.4f, ref scal %.4f, ratio %.2f; check vs device: Q max diff / "
          "max |Q| %.2e (lanes) %.2e (scalar), max |Q| %.3g W\n",
          heat.device_us, heat.lanes_us, heat.scalar_us, heat.device_us / heat_ref_us, heat.lanes_diff,
          heat.scalar_diff, heat.max_q);
    }
    std::fflush(stdout);
  }
  if (print)
    std::printf(
        "(wall us per fluid particle-step; dens iso: the device density stage alone, run alternately with "
        "the\n"
        " hand-written C++/OpenMP loops over the same sorted data, %d threads: ref lane (8 candidates at a "
        "time,\n"
        " as the device) and ref scal (one at a time); ratio: dens iso / the faster reference; fastest of %d "
        "runs each.\n"
        " heat: the same for the device heat stage alone (compute_heat with dt = 0: thermal state, "
        "conduction,\n"
        " sources, budget) against the reference conduction loop with the air exchange; its Q check takes "
        "the\n"
        " device's Q from the enthalpy change of one compute_heat(dt))\n",
        omp_get_max_threads(), std::max(5, o.steps));
  out["sizes"] = rows;
  return out;
}

}  // namespace thaw
