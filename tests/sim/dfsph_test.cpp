// DFSPH (sim/dfsph_stage.h, solver.pressure "dfsph"): a still tank holds its rest density at a time step
// several times WCSPH's, a dam break runs at a sixth of WCSPH's steps with the same front, two runs and a
// resumed run are bitwise the same, a tolerance the iteration cap cannot meet is reported, a run that
// blows up stops naming the step and the particle, melting ice joins the solve, and the walls carry the
// full load with their extrapolated pressure.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "sim/error.h"
#include "sim/kernels/sph_kernel.h"
#include "sim/metrics.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;
using testing::read_file_bytes;
using testing::TempDir;

class DfsphTest : public ClSuite {};

// configs/hydrostatic-tank.json at 2 cm: a 20 x 20 cm tank, water 25 cm deep.
Scene tank(const std::vector<std::string>& extra = {}) {
  std::vector<std::string> o = {"spacing=0.02"};
  o.insert(o.end(), extra.begin(), extra.end());
  return load_scene("hydrostatic-tank", o);
}

double mean_dt(Solver& s, double until) {
  const double t0 = s.time();
  const std::uint64_t n0 = s.steps();
  while (s.time() < until) s.step();
  return (s.time() - t0) / double(s.steps() - n0);
}

// Still water in a tank: the density solve keeps the mean compression within its tolerance each step,
// the mass stays, nothing blows up, and the time step (the velocity CFL; solver.max_dt raised from its
// 1 ms default, which would cap it at 2.8x) is at least 5x the weakly compressible one (the sound
// speed's) in the same tank. Its mean speed is reported and gated only against a blow-up here: this tank
// settles for 0.3 s, not the 1.5 s of the hydrostatic case, where issue 17's 1e-3 sqrt(g H) is gated
// (Validation.HydrostaticWithDfsphPassesAtCiResolution).
TEST_F(DfsphTest, StillWaterHoldsItsDensityAtAFiveTimesLongerStep) {
  const Scene wc = tank({"solver.pressure=wcsph"});
  Solver w(cl(), wc, initial_state(wc));
  const double dt_wcsph = mean_dt(w, 0.05);

  const Scene df = tank({"solver.pressure=dfsph", "solver.max_dt=0.005"});
  Solver d(cl(), df, initial_state(df));
  ASSERT_NE(d.dfsph(), nullptr);
  const double mass0 = measure(d).fluid_mass;
  d.set_velocity_damping(5.0);
  const double dt_dfsph = mean_dt(d, 0.3);
  d.set_velocity_damping(0.0);
  mean_dt(d, 0.5);
  const Metrics m = measure(d);
  const double H = 0.25, g = 9.81;
  const HostParticles p = d.particles();
  double speed = 0;
  int fluid = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.phase[i] == static_cast<std::uint8_t>(Phase::Water)) {
      speed += std::sqrt(double(p.velocity[i][0]) * p.velocity[i][0] +
                         double(p.velocity[i][1]) * p.velocity[i][1] +
                         double(p.velocity[i][2]) * p.velocity[i][2]);
      ++fluid;
    }
  speed /= fluid;
  std::printf(
      "[ info ] dt WCSPH %.3g s, DFSPH %.3g s (%.1fx); density solve %d iterations, error %.3g; mean "
      "density error %.3g, max %.3g; mean iterations %.2f / %.2f; max speed %.3g m/s, mean %.3g sqrt(g H)\n",
      dt_wcsph, dt_dfsph, dt_dfsph / dt_wcsph, d.dfsph()->last_density().iterations,
      d.dfsph()->last_density().error, m.mean_density_error, m.max_density_error,
      double(d.dfsph()->totals().density_iterations) / double(d.dfsph()->totals().steps),
      double(d.dfsph()->totals().divergence_iterations) / double(d.dfsph()->totals().steps), m.max_speed,
      speed / std::sqrt(g * H));
  EXPECT_GE(dt_dfsph, 5.0 * dt_wcsph);
  EXPECT_TRUE(d.dfsph()->last_density().converged);
  EXPECT_LE(d.dfsph()->last_density().error, df.solver.density_tolerance);
  EXPECT_EQ(d.dfsph()->totals().density_unconverged, 0u);
  EXPECT_LE(m.mean_density_error,
            2 * df.solver.density_tolerance);  // the measured density, not the predicted
  EXPECT_NEAR(m.fluid_mass, mass0, 1e-9 * mass0);
  EXPECT_LT(speed, 0.05 * std::sqrt(g * H));
  EXPECT_EQ(d.clamped(), 0u);
}

// Water sampled on the scene's lattice starts at rest: the density solve aims at the density a resting
// lattice sums to (1.003 rho0 for Wendland C2 over 3 spacings), not at rho0, which made it expand all the
// water by 0.3 % in its first step (ice-bunny's water rose at 0.17 m/s on average).
TEST_F(DfsphTest, WaterOnTheLatticeStartsAtRestWithWendland) {
  EXPECT_NEAR(sph::lattice_sum(sph::wendland_c2_w, 0.01, 0.03), 1.003, 5e-4);
  EXPECT_NEAR(sph::lattice_sum(sph::cubic_spline_w, 0.01, 0.02), 1.0, 1e-4);
  const Scene s = tank({"solver.pressure=dfsph", "solver.kernel=wendland_c2", "solver.support_ratio=3"});
  Solver d(cl(), s, initial_state(s));
  for (int i = 0; i < 5; ++i) d.step();
  const HostParticles p = d.particles();
  double rise = 0;
  int fluid = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.phase[i] == static_cast<std::uint8_t>(Phase::Water)) {
      rise += p.velocity[i][2];
      ++fluid;
    }
  rise /= fluid;
  std::printf("[ info ] after 5 steps (%.3g s) the water's mean vertical velocity is %.3g m/s\n", d.time(),
              rise);
  EXPECT_LT(std::abs(rise), 0.05);  // measured 0.0069 m/s; 0.705 when aiming at rho0
  // The metrics measure compression against that same density: against rho0 still water read 0.3 %.
  const Metrics m = measure(d);
  std::printf("[ info ] mean density error %.3g, max %.3g\n", m.mean_density_error, m.max_density_error);
  EXPECT_LT(m.mean_density_error, 2 * s.solver.density_tolerance);
}

// The divergence solve starts from zero by default (its warm start's sweeps cost 14 % of the dam break's
// wall time for nothing measurable: docs/BENCHMARKS.md); solver.divergence_warm_start puts Bender &
// Koschier's warm start back. Both hold still water, and the setting is honoured (the runs differ).
TEST_F(DfsphTest, DivergenceWarmStartIsSelectableAndBothHoldStillWater) {
  std::map<bool, std::vector<Float4>> positions;
  for (const bool warm : {false, true}) {
    const Scene s = tank(
        {"solver.pressure=dfsph", std::string("solver.divergence_warm_start=") + (warm ? "true" : "false")});
    ASSERT_EQ(s.solver.divergence_warm_start, warm);
    Solver d(cl(), s, initial_state(s));
    while (d.time() < 0.1) d.step();
    const Metrics m = measure(d);
    std::printf(
        "[ info ] divergence warm start %d: %llu steps, %.2f divergence iterations a step, mean density "
        "error %.3g, max speed %.3g m/s\n",
        int(warm), static_cast<unsigned long long>(d.steps()),
        double(d.dfsph()->totals().divergence_iterations) / double(d.dfsph()->totals().steps),
        m.mean_density_error, m.max_speed);
    EXPECT_LE(m.mean_density_error, 2 * s.solver.density_tolerance) << warm;
    EXPECT_LT(m.max_speed, 0.05 * std::sqrt(9.81 * 0.25)) << warm;
    EXPECT_EQ(d.clamped(), 0u) << warm;
    positions[warm] = d.particles().position;
  }
  EXPECT_NE(positions[false], positions[true]);
}

// Whole-number settings reach the kernels as valid OpenCL C: "1.00000000f", not "1f", which failed to
// build (plain Jacobi, solver.pressure_relaxation 1, and a lattice sum of exactly 1).
TEST_F(DfsphTest, PlainJacobiBuilds) {
  const Scene s = tank({"solver.pressure=dfsph", "solver.pressure_relaxation=1"});
  Solver d(cl(), s, initial_state(s));
  EXPECT_NO_THROW(d.step());
}

// The dam break at 2 cm: the front stays within 5 % of WCSPH's at 0.25 s in a third of the steps or fewer
// (measured: 250 against 1,040, with the default 1 ms cap on the step).
TEST_F(DfsphTest, ADamBreakRunsInFarFewerStepsWithTheSameFront) {
  auto run = [&](const std::string& pressure, double& front) {
    const Scene s = load_scene("dam-break", {"spacing=0.02", "solver.pressure=" + pressure});
    Solver solver(cl(), s, initial_state(s));
    while (solver.time() < 0.25) solver.step();
    const HostParticles p = solver.particles();
    front = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.phase[i] == static_cast<std::uint8_t>(Phase::Water))
        front = std::max(front, double(p.position[i][0]));
    return solver.steps();
  };
  double wc_front = 0, df_front = 0;
  const std::uint64_t wc_steps = run("wcsph", wc_front), df_steps = run("dfsph", df_front);
  std::printf("[ info ] at 0.25 s: WCSPH %llu steps, front %.3f m; DFSPH %llu steps, front %.3f m\n",
              (unsigned long long)wc_steps, wc_front, (unsigned long long)df_steps, df_front);
  EXPECT_LE(3 * df_steps, wc_steps);
  EXPECT_NEAR(df_front, wc_front, 0.05 * wc_front);
}

std::string state_bytes(const Solver& s, const TempDir& dir, const std::string& name) {
  write_state_file(dir / name, s.state());
  return read_file_bytes(dir / name);
}

// Determinism: two runs give the same bytes; a run resumed from a state file mid-run (the warm-start
// kappa and the last dt are in it) continues bitwise.
void expect_runs_and_resume_bitwise(ClRuntime& cl, const Scene& s, int half) {
  TempDir dir("dfsph-resume");
  Solver a(cl, s, initial_state(s));
  for (int i = 0; i < half; ++i) a.step();
  write_state_file(dir / "mid.state", a.state());
  for (int i = 0; i < half; ++i) a.step();
  const std::string expected = state_bytes(a, dir, "a.state");

  Solver b(cl, s, initial_state(s));
  for (int i = 0; i < 2 * half; ++i) b.step();
  EXPECT_TRUE(state_bytes(b, dir, "b.state") == expected) << "two runs differ";

  Solver resumed(cl, s, read_state_file(dir / "mid.state"));
  while (resumed.steps() < a.steps()) resumed.step();
  EXPECT_TRUE(state_bytes(resumed, dir, "resumed.state") == expected) << "the resumed run differs";
}

TEST_F(DfsphTest, TwoRunsAndAResumedRunAreBitwiseTheSame) {
  expect_runs_and_resume_bitwise(cl(), load_scene("dam-break", {"spacing=0.025", "solver.pressure=dfsph"}),
                                 20);
}

// The same with free ice bodies floating and melting in warm water (the default scene, coarse).
TEST_F(DfsphTest, FreeIceInWarmWaterResumesBitwise) {
  const Scene s = load_scene("default", {"spacing=0.006", "solver.pressure=dfsph"});
  ASSERT_FALSE(s.ice.empty());
  expect_runs_and_resume_bitwise(cl(), s, 15);
}

// A tolerance two sweeps cannot meet is reported, step by step, in the metrics: never passed over.
TEST_F(DfsphTest, AToleranceTheCapCannotMeetIsReported) {
  const Scene s =
      tank({"solver.pressure=dfsph", "solver.density_tolerance=1e-9", "solver.max_pressure_iterations=2"});
  Solver d(cl(), s, initial_state(s));
  for (int i = 0; i < 10; ++i) d.step();
  const Json j = metrics_json(measure(d), 0, Json::object());
  ASSERT_TRUE(j.contains("dfsph")) << j.dump();
  EXPECT_FALSE(j["dfsph"]["density"]["converged"].get<bool>());
  EXPECT_EQ(j["dfsph"]["density"]["iterations"].get<int>(), 2);
  EXPECT_GT(j["dfsph"]["unconverged_density_steps"].get<int>(), 0);
  EXPECT_GT(j["dfsph"]["worst_unconverged_density_error"].get<double>(), 1e-9);
  // WCSPH has no such report.
  const Scene w = tank();
  Solver ws(cl(), w, initial_state(w));
  ws.step();
  EXPECT_FALSE(metrics_json(measure(ws), 0, Json::object()).contains("dfsph"));
}

// A blow-up stops the run with the step and the particle named.
TEST_F(DfsphTest, ABlowUpNamesTheStepAndTheParticle) {
  const Scene s = load_scene("dam-break", {"spacing=0.025", "solver.pressure=dfsph", "solver.max_speed=0.5"});
  Solver d(cl(), s, initial_state(s));
  try {
    for (int i = 0; i < 2000; ++i) d.step();
    FAIL() << "a dam break faster than 0.5 m/s did not stop";
  } catch (const BlowUpError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("step "), std::string::npos) << what;
    EXPECT_NE(what.find("particle "), std::string::npos) << what;
  }
}

// A tap pours into an empty tank under DFSPH: the solver grows its capacity on the way (its stages are
// rebuilt from the state, warm-start kappa included), every poured particle is there, almost none is
// clamped, and the density solves keep their tolerance.
TEST_F(DfsphTest, ATapFillsATankWithEveryParticleAccountedFor) {
  const Scene s = scene_from_json(Json::parse(R"({
    "name": "tap", "description": "a tap pouring into an empty tank",
    "domain": {"min": [0, 0, 0], "max": [0.1, 0.1, 0.12], "walls": ["-x", "+x", "-y", "+y", "-z"],
               "wall_material": "steel"},
    "spacing": 0.005,
    "solver": {"pressure": "dfsph"},
    "materials": {
      "water": {"kind": "fluid", "density": 1000.0, "viscosity": 1.0e-3, "conductivity": 0.56, "specific_heat": 4217},
      "steel": {"kind": "solid", "density": 7800.0, "conductivity": 16, "specific_heat": 500}
    },
    "emitters": [{"material": "water", "position": [0.05, 0.05, 0.1], "radius": 0.012, "speed": 1}]
  })"));
  Solver d(cl(), s, initial_state(s));
  const std::size_t capacity0 = d.capacity();
  while (d.capacity() == capacity0 && d.time() < 1.5) d.step();
  for (int i = 0; i < 20; ++i) d.step();
  const Metrics m = measure(d);
  const InflowBooks in = d.inflow();
  std::printf(
      "[ info ] poured %llu particles (%.4g kg) in %llu steps; capacity %zu -> %zu; density error %.3g\n",
      (unsigned long long)in.particles, in.mass, (unsigned long long)d.steps(), capacity0, d.capacity(),
      d.dfsph()->last_density().error);
  EXPECT_GT(d.capacity(), capacity0) << "the tap should have outgrown the first capacity";
  EXPECT_EQ(m.count[static_cast<int>(Phase::Water)], in.particles);
  EXPECT_NEAR(m.fluid_mass, in.mass, 1e-9 * in.mass);
  // A few drops of the jet reach the floor's face and are clamped back (4 in this run; WCSPH's stiffer
  // wall push: 0): counted, never lost. Bounded here so that a wall that leaks shows.
  std::printf("[ info ] clamped %llu\n", (unsigned long long)d.clamped());
  EXPECT_LE(d.clamped(), in.particles / 200);
  EXPECT_EQ(d.dfsph()->totals().density_unconverged, 0u);
}

// Ice melting into the solve: configs/ice-on-plate.json (fixed ice on a 40 °C plate) under DFSPH until its
// first meltwater has run for a while. A particle that melts in the heat stage, between the alpha pass and
// the density solve, has no alpha of its own that step; it once read the walls' flag as alpha 1, took a
// kappa 10^7 times too large and the run blew up at t = 0.646 s. Checked: no blow-up (the solver throws),
// water appeared, mass and energy accounted for, the solves within tolerance.
TEST_F(DfsphTest, MeltwaterJoinsTheSolveWithoutABlowUp) {
  const Scene s = load_scene("ice-on-plate", {"solver.pressure=dfsph"});
  Solver d(cl(), s, initial_state(s));
  const double mass0 = measure(d).ice_mass + measure(d).water_mass;
  while (d.time() < 1.0) d.step();
  const Metrics m = measure(d);
  std::printf("[ info ] at %.3g s: water %.4g kg of %.4g kg, energy closure %.3g J of %.4g J in; %zu steps\n",
              d.time(), m.water_mass, mass0, m.closure(), m.budget.heat_in(), std::size_t(d.steps()));
  EXPECT_GT(m.count[static_cast<int>(Phase::Water)], 0u)
      << "no meltwater: the case no longer tests its way in";
  // Per particle, an ice mass is its boundary mass times rho_ice / rho0 in float: 1.1e-9 relative apart
  // from the water's after 100 of 1000 particles melted. The bound is float rounding, not a loss.
  EXPECT_NEAR(m.ice_mass + m.water_mass, mass0, 1e-7 * mass0);
  EXPECT_LT(std::abs(m.closure()), 1e-6 * m.budget.heat_in());
  EXPECT_EQ(d.dfsph()->totals().density_unconverged, 0u);
  EXPECT_EQ(d.clamped(), 0u);
}

// The walls' pressure in the solves (solver.boundary_pressure): extrapolated from the water (Adami et al.
// 2012, the default), the floor holds the water's first layer half a spacing above its face, where the
// lattice puts it; with none of their own (akinci2012, the 2017 paper's one-sided coupling, kept for
// comparison) the floor carries half the load and the water sinks into it. Measured: the median over
// columns of the lowest water particle, in spacings.
TEST_F(DfsphTest, WallsCarryTheFullLoadWithTheirExtrapolatedPressure) {
  auto first_layer = [&](const char* boundary) {
    const Scene s = tank({"solver.pressure=dfsph", std::string("solver.boundary_pressure=") + boundary});
    Solver d(cl(), s, initial_state(s));
    d.set_velocity_damping(5.0);
    while (d.time() < 0.5) d.step();
    const HostParticles p = d.particles();
    const double dx = s.spacing;
    std::map<std::pair<int, int>, double> lowest;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.phase[i] != static_cast<std::uint8_t>(Phase::Water)) continue;
      const auto key = std::make_pair(int(p.position[i][0] / dx), int(p.position[i][1] / dx));
      const auto it = lowest.find(key);
      if (it == lowest.end() || p.position[i][2] < it->second) lowest[key] = p.position[i][2];
    }
    std::vector<double> z;
    for (const auto& [key, v] : lowest) z.push_back(v / dx);
    std::nth_element(z.begin(), z.begin() + std::ptrdiff_t(z.size() / 2), z.end());
    return z[z.size() / 2];
  };
  const double adami = first_layer("adami2012"), akinci = first_layer("akinci2012");
  std::printf(
      "[ info ] the water's first layer above the floor: %.3f spacings (adami2012), %.3f (akinci2012)\n",
      adami, akinci);
  EXPECT_GT(adami, 0.4);
  EXPECT_LT(akinci, adami - 0.1);
}

}  // namespace
}  // namespace thaw
