// The solver as a whole: bitwise determinism and resume (in process and through `thaw run`), exact
// mass, a dam break that stays finite, the CFL cap on the time step, blow-up reports that name the
// step and the particle, and particles clamped back into the domain.
#include "sim/solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "sim/error.h"
#include "sim/metrics.h"
#include "sim/state_file.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;
using testing::read_file_bytes;
using testing::TempDir;

// configs/dam-break.json at 2 cm (3000 water and 9192 wall particles), or coarser for long runs.
Scene dam_break(const std::vector<std::string>& extra = {}, const std::string& spacing = "0.02") {
  std::vector<std::string> overrides = {"spacing=" + spacing};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return load_scene("dam-break", overrides);
}

bool is_fluid(const HostParticles& p, std::size_t i) {
  return p.phase[i] != static_cast<std::uint8_t>(Phase::Solid);
}

std::size_t first_fluid(const HostParticles& p) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (is_fluid(p, i)) return i;
  return p.size();
}

void run_steps(Solver& s, int n) {
  for (int i = 0; i < n; ++i) s.step();
}

// Where two byte strings first differ, for a readable failure.
std::string difference(const std::string& a, const std::string& b) {
  if (a == b) return "identical";
  const std::size_t n = std::min(a.size(), b.size());
  std::size_t i = 0;
  while (i < n && a[i] == b[i]) ++i;
  return "sizes " + std::to_string(a.size()) + " and " + std::to_string(b.size()) +
         ", first difference at byte " + std::to_string(i);
}

std::string state_bytes(const Solver& s, const TempDir& dir, const std::string& name) {
  const std::string path = dir / name;
  write_state_file(path, s.state());
  return read_file_bytes(path);
}

// Every id 0..n-1 exactly once.
bool is_permutation_of_indices(const std::vector<std::uint32_t>& ids) {
  std::vector<std::uint32_t> sorted = ids;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < sorted.size(); ++i)
    if (sorted[i] != i) return false;
  return true;
}

// Fluid mass summed in id order, so the sum does not depend on the device's sort order.
double fluid_mass(const HostParticles& p) {
  std::vector<std::size_t> by_id(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) by_id[p.id[i]] = i;
  double m = 0;
  for (const std::size_t i : by_id)
    if (is_fluid(p, i)) m += p.position[i][3];
  return m;
}

bool all_finite(const HostParticles& p, std::string* where) {
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(p.position[i][a]) || !std::isfinite(p.velocity[i][a])) {
        *where = "particle " + std::to_string(p.id[i]);
        return false;
      }
  return true;
}

class SolverTest : public ClSuite {};

TEST_F(SolverTest, TwoRunsOfTheSameSceneAreBitwiseIdentical) {
  const Scene scene = dam_break();
  const SimState start = initial_state(scene);
  Solver a(cl(), scene, start), b(cl(), scene, start);
  run_steps(a, 200);
  run_steps(b, 200);
  TempDir dir("determinism");
  const std::string sa = state_bytes(a, dir, "a.state"), sb = state_bytes(b, dir, "b.state");
  EXPECT_EQ(a.steps(), 200u);
  EXPECT_GT(a.time(), 0.0);
  EXPECT_TRUE(sa == sb) << difference(sa, sb);
  // The state did move, so the comparison is not between two copies of the start.
  Solver fresh(cl(), scene, start);
  const std::string s0 = state_bytes(fresh, dir, "start.state");
  EXPECT_NE(s0, sa);
}

// The per-tile passes (the sort, the time-step limits, the heat budget) are cut into 32 tiles on a CPU
// and thousands on a GPU (ClRuntime::layout_tiles), where the sort's scan runs in chunks of 32 tiles
// (grid.cl): the particles come out the same whatever the cut, with heat and water leaving through an
// open side (only the budget's float sums are regrouped).
TEST_F(SolverTest, TheTileCountChangesNoParticle) {
  const Scene scene = dam_break(
      {"domain.walls=[\"-x\", \"-y\", \"+y\", \"-z\"]", "domain.open=[\"+x\"]", "fluids[0].temperature=30"});
  const SimState start = initial_state(scene);
  Solver a(cl(), scene, start);
  ::setenv("THAW_TILES", "7", 1);
  Solver b(cl(), scene, start);
  ::setenv("THAW_TILES", "1000000", 1);  // tiles of 256 particles: more than one chunk of the scan
  Solver c(cl(), scene, start);
  ::unsetenv("THAW_TILES");
  ASSERT_NE(a.layout().ntiles, b.layout().ntiles);
  ASSERT_GT(c.layout().ntiles, 32u);
  int steps = 0;
  while (a.outflow().particles == 0 && steps < 20000) {
    a.step();
    ++steps;
  }
  ASSERT_GT(a.outflow().particles, 0u) << "no water left in " << steps << " steps";
  run_steps(a, 20);
  const HostParticles pa = a.particles();
  for (Solver* other : {&b, &c}) {
    SCOPED_TRACE(other->layout().ntiles);
    run_steps(*other, steps + 20);
    EXPECT_EQ(a.outflow().particles, other->outflow().particles);
    const HostParticles po = other->particles();
    ASSERT_EQ(pa.size(), po.size());
    EXPECT_TRUE(pa.position == po.position && pa.velocity == po.velocity && pa.enthalpy == po.enthalpy &&
                pa.id == po.id);
    EXPECT_NEAR(a.energy_budget().outflow, other->energy_budget().outflow,
                1e-9 * std::abs(a.energy_budget().outflow));
  }
}

TEST_F(SolverTest, ResumingFromAStateFileContinuesBitwiseIdentically) {
  const Scene scene = dam_break();
  TempDir dir("resume");
  Solver straight(cl(), scene, initial_state(scene));
  run_steps(straight, 200);
  const std::string expected = state_bytes(straight, dir, "straight.state");

  {
    Solver first(cl(), scene, initial_state(scene));
    run_steps(first, 100);
    write_state_file(dir / "half.state", first.state());
  }
  const SimState half = read_state_file(dir / "half.state");
  EXPECT_EQ(half.step, 100u);
  const Scene again = scene_from_json(Json::parse(half.scene_json));
  Solver second(cl(), again, half);
  run_steps(second, 100);
  EXPECT_EQ(second.steps(), 200u);
  const std::string resumed = state_bytes(second, dir, "resumed.state");
  EXPECT_TRUE(resumed == expected) << difference(resumed, expected);
}

TEST_F(SolverTest, ResumingThroughTheCommandLineContinuesBitwiseIdentically) {
  TempDir dir("cli-resume");
  Json doc = read_json_file(resolve_scene_path("dam-break"));
  doc["spacing"] = 0.02;
  testing::write_text(dir / "scene.json", doc.dump(2));
  const std::string scene = testing::shell_quote(dir / "scene.json");

  const auto a = testing::run_thaw("run " + scene + " --quiet --steps 200 --state-out a.state", dir);
  ASSERT_TRUE(a.exited && a.exit_code == 0) << a.err;
  const auto h = testing::run_thaw("run " + scene + " --quiet --steps 100 --state-out h.state", dir);
  ASSERT_TRUE(h.exited && h.exit_code == 0) << h.err;
  const auto b = testing::run_thaw("run --quiet --state-in h.state --steps 100 --state-out b.state", dir);
  ASSERT_TRUE(b.exited && b.exit_code == 0) << b.err;

  const std::string sa = read_file_bytes(dir / "a.state"), sb = read_file_bytes(dir / "b.state");
  ASSERT_FALSE(sa.empty());
  EXPECT_EQ(read_state_file(dir / "b.state").step, 200u);
  EXPECT_TRUE(sa == sb) << difference(sa, sb);
  EXPECT_NE(read_file_bytes(dir / "h.state"), sa);
}

TEST_F(SolverTest, FluidMassIsExactAndNoParticleIsLost) {
  const Scene scene = dam_break();
  const SimState start = initial_state(scene);
  const double mass0 = fluid_mass(start.particles);
  ASSERT_GT(mass0, 0.0);
  Solver solver(cl(), scene, start);
  run_steps(solver, 500);
  const HostParticles p = solver.particles();
  ASSERT_EQ(p.size(), start.particles.size());
  EXPECT_TRUE(is_permutation_of_indices(p.id));
  EXPECT_EQ(fluid_mass(p), mass0);
  // Each particle keeps its own mass and phase, not just the total.
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::uint32_t id = p.id[i];
    ASSERT_EQ(p.phase[i], start.particles.phase[id]) << "particle " << id;
    if (is_fluid(p, i)) {
      ASSERT_EQ(p.position[i][3], start.particles.position[id][3]) << "particle " << id;
    }
  }
  EXPECT_EQ(p.count(Phase::Water), start.particles.count(Phase::Water));
}

TEST_F(SolverTest, DamBreakStaysFiniteAndInsideTheTank) {
  // 1600 water and 6048 wall particles.
  const Scene scene = dam_break({}, "0.025");
  Solver solver(cl(), scene, initial_state(scene));
  std::string where;
  for (int block = 0; block < 10; ++block) {
    ASSERT_NO_THROW(run_steps(solver, 200)) << "after step " << solver.steps();
    ASSERT_TRUE(all_finite(solver.particles(), &where)) << where << " at step " << solver.steps();
  }
  EXPECT_EQ(solver.steps(), 2000u);
  const HostParticles p = solver.particles();
  // The front has crossed the tank (a = 0.25 m; it reaches the far wall at x = 4a near t = 0.4 s).
  const float slack = solver.constants().support;
  float front = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!is_fluid(p, i)) continue;
    front = std::max(front, p.position[i][0]);
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(p.position[i][a], float(scene.domain.min[a]) - slack) << "particle " << p.id[i];
      EXPECT_LE(p.position[i][a], float(scene.domain.max[a]) + slack) << "particle " << p.id[i];
    }
  }
  EXPECT_GT(solver.time(), 0.3);
  EXPECT_GT(front, 0.5f);
}

TEST_F(SolverTest, TimeStepObeysTheCflLimitWhateverMaxDt) {
  const Scene scene = dam_break({"solver.max_dt=1.0"});
  ASSERT_EQ(scene.solver.max_dt, 1.0);
  Solver solver(cl(), scene, initial_state(scene));
  const auto& k = solver.constants();
  const double cfl = scene.solver.cfl, h = k.smoothing, c = k.sound_speed;
  ASSERT_GT(c, 0.0);
  for (int i = 0; i < 300; ++i) {
    double vmax = 0;
    if (i % 10 == 0) {
      const HostParticles p = solver.particles();
      for (std::size_t j = 0; j < p.size(); ++j) {
        const auto& v = p.velocity[j];
        if (is_fluid(p, j))
          vmax = std::max(vmax, std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]));
      }
    }
    solver.step();
    // dt <= cfl h / (c + v_max), up to the rounding of dt to float.
    const double limit = cfl * h / (c + vmax);
    ASSERT_LE(solver.dt(), limit * (1 + 1e-6)) << "step " << solver.steps();
    ASSERT_GT(solver.dt(), 0.0);
  }
  EXPECT_LT(solver.dt(), 1e-2);
  std::string where;
  EXPECT_TRUE(all_finite(solver.particles(), &where)) << where;
}

// A BlowUpError's text; fails the test when `f` does not throw one.
template <class F>
std::string blow_up_message(F&& f) {
  try {
    f();
  } catch (const BlowUpError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no BlowUpError";
  return "";
}

TEST_F(SolverTest, NonFiniteVelocityStopsNamingStepAndParticle) {
  const Scene scene = dam_break();
  SimState st = initial_state(scene);
  // A water particle in the middle of the column, so it has many neighbours.
  std::size_t victim = st.particles.size();
  for (std::size_t i = 0; i < st.particles.size(); ++i) {
    const auto& x = st.particles.position[i];
    if (is_fluid(st.particles, i) && std::abs(x[0] - 0.13f) < 0.011f && std::abs(x[1] - 0.1f) < 0.011f &&
        std::abs(x[2] - 0.25f) < 0.011f) {
      victim = i;
      break;
    }
  }
  ASSERT_LT(victim, st.particles.size());
  const std::uint32_t id = st.particles.id[victim];
  st.particles.velocity[victim][0] = std::numeric_limits<float>::quiet_NaN();
  Solver solver(cl(), scene, st);
  const std::string msg = blow_up_message([&] { solver.step(); });
  EXPECT_NE(msg.find("step 1 "), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle " + std::to_string(id) + " "), std::string::npos)
      << "expected the particle with the NaN velocity, " << id << ": " << msg;
}

TEST_F(SolverTest, RunawaySpeedStopsNamingStepAndParticle) {
  const Scene scene = dam_break();
  SimState st = initial_state(scene);
  st.step = 41;  // a resumed state: the step named is the one being taken
  const std::size_t victim = first_fluid(st.particles) + 100;
  ASSERT_TRUE(is_fluid(st.particles, victim));
  const std::uint32_t id = st.particles.id[victim];
  st.particles.velocity[victim] = {0.f, 0.f, 1e6f, 0.f};
  Solver solver(cl(), scene, st);
  const std::string msg = blow_up_message([&] { solver.step(); });
  EXPECT_NE(msg.find("step 42 "), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle " + std::to_string(id) + " "), std::string::npos)
      << "particle " << id << ": " << msg;
  EXPECT_NE(msg.find("max_speed"), std::string::npos) << msg;
  EXPECT_EQ(solver.steps(), 41u) << "the failed step must not count";
}

TEST_F(SolverTest, TimeStepBelowMinDtStopsNamingMinDt) {
  // min_dt must stay below max_dt: the scene itself refuses that.
  try {
    dam_break({"solver.min_dt=1"});
    ADD_FAILURE() << "min_dt above max_dt was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("min_dt"), std::string::npos) << e.what();
  }
  // A min_dt far above what the CFL condition allows stops the first step.
  const Scene scene = dam_break({"solver.max_dt=1", "solver.min_dt=0.5"});
  Solver solver(cl(), scene, initial_state(scene));
  const std::string msg = blow_up_message([&] { solver.step(); });
  EXPECT_NE(msg.find("solver.min_dt"), std::string::npos) << msg;
  EXPECT_NE(msg.find("step 1 "), std::string::npos) << msg;
}

TEST_F(SolverTest, ParticleLeavingTheDomainIsClampedAndCounted) {
  const Scene scene = dam_break();
  SimState st = initial_state(scene);
  // Above the open top of the tank, far from any other particle, flying upwards.
  const std::size_t i = first_fluid(st.particles);
  ASSERT_LT(i, st.particles.size());
  const std::uint32_t id = st.particles.id[i];
  const float top = float(scene.domain.max.z());
  st.particles.position[i] = {0.6f, 0.1f, top + 0.05f, st.particles.position[i][3]};
  st.particles.velocity[i] = {0.f, 0.f, 2.f, 0.f};
  Solver solver(cl(), scene, st);
  EXPECT_EQ(solver.clamped(), 0u);
  solver.step();
  EXPECT_EQ(solver.clamped(), 1u);
  const HostParticles p = solver.particles();
  const auto at = static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), id) - p.id.begin());
  ASSERT_LT(at, p.size());
  for (int a = 0; a < 3; ++a) {
    EXPECT_GE(p.position[at][a], float(scene.domain.min[a])) << "axis " << a;
    EXPECT_LE(p.position[at][a], float(scene.domain.max[a])) << "axis " << a;
  }
  EXPECT_LE(p.velocity[at][2], 0.f) << "the outward velocity is removed";
  // Counted once, and carried into the state.
  solver.step();
  EXPECT_EQ(solver.clamped(), 1u);
  EXPECT_EQ(solver.state().clamped, 1u);
}

// Walls deep enough to hold water: one layer more than the support ratio above 2 spacings, so that the
// kernel's whole support next to a wall is filled. With 3 layers under Wendland's support of 3 spacings,
// still water crept into the wall and the domain clamp held it (33,221 clamps in this case) until the
// walls' short-range push (forces.cl) came; now neither clamps, and the default 4 never may.
TEST_F(SolverTest, WallsHoldStillWaterUnderAWideKernel) {
  // 5 x 5 cm, 7 cm deep at 5 mm: 1,400 water particles (the clamp starts at about 0.3 s with 3 layers).
  const std::vector<std::string> wide = {"solver.kernel=wendland_c2", "solver.support_ratio=3",
                                         "spacing=0.005", "domain.max=[0.05,0.05,0.09]",
                                         "fluids[0].box.max=[0.05,0.05,0.07]"};
  auto with = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), wide.begin(), wide.end());
    return load_scene("hydrostatic-tank", extra);
  };
  EXPECT_EQ(wall_layer_count(with({})), 4);
  EXPECT_EQ(wall_layer_count(with({"solver.support_ratio=3.5"})), 4);
  EXPECT_EQ(wall_layer_count(load_scene("hydrostatic-tank")), 2);  // cubic spline over 2 spacings
  EXPECT_EQ(wall_layer_count(load_scene("hydrostatic-tank", {"solver.support_ratio=2.5"})), 3);
  EXPECT_EQ(wall_layer_count(with({"domain.wall_layers=6"})), 6);
  std::uint64_t clamped[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const Scene scene =
        with(k == 0 ? std::vector<std::string>{"domain.wall_layers=3"} : std::vector<std::string>{});
    Solver solver(cl(), scene, initial_state(scene));
    while (solver.time() < 0.6) solver.step();
    clamped[k] = solver.clamped();
  }
  std::printf("clamp events in 0.6 s: %llu with 3 wall layers, %llu with the default 4\n",
              static_cast<unsigned long long>(clamped[0]), static_cast<unsigned long long>(clamped[1]));
  EXPECT_EQ(clamped[0], 0u);
  EXPECT_EQ(clamped[1], 0u);
}

// Drops too small for pressure (a single particle, a patch of four) resting on a wall: the wall's
// short-range push holds them a spacing's fraction above its face. Without it they sank half a spacing,
// onto the domain's face, and the clamp caught them every step (2,801 times in 0.3 s here), which is
// what the clamp counts in melting scenes came from.
TEST_F(SolverTest, LoneDropsRestOnAWallWithoutTheClamp) {
  const double dx = 0.003;
  const Json water = {{"kind", "fluid"},
                      {"density", 1000},
                      {"viscosity", 1e-3},
                      {"conductivity", 0.56},
                      {"specific_heat", 4217}};
  const Json glass = {{"kind", "solid"}, {"density", 2500}, {"conductivity", 1.0}, {"specific_heat", 840}};
  auto block = [&](double x0, double x1) {
    return Json{{"material", "water"}, {"box", {{"min", {x0, x0, dx}}, {"max", {x1, x1, 2 * dx}}}}};
  };
  const Json doc = {
      {"name", "lone-drops"},
      {"domain",
       {{"min", {0, 0, 0}}, {"max", {0.03, 0.03, 0.03}}, {"walls", {"-z"}}, {"wall_material", "glass"}}},
      {"spacing", dx},
      {"heat", {{"enabled", false}}},
      {"materials", {{"water", water}, {"glass", glass}}},
      {"fluids", {block(0.015, 0.018), block(0.006, 0.012)}}};
  const Scene scene = scene_from_json(doc);
  Solver solver(cl(), scene, initial_state(scene));
  while (solver.time() < 0.3) solver.step();
  const HostParticles p = solver.particles();
  std::size_t drops = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.phase[i] != std::uint8_t(Phase::Water)) continue;
    ++drops;
    EXPECT_GT(p.position[i][2], 0.1 * dx) << "particle " << i;
    EXPECT_LT(p.position[i][2], 0.6 * dx) << "particle " << i;
    const Eigen::Vector3d v(p.velocity[i][0], p.velocity[i][1], p.velocity[i][2]);
    EXPECT_LT(v.norm(), 1e-3) << "particle " << i << ": at rest";
  }
  EXPECT_EQ(drops, 5u);
  EXPECT_EQ(solver.clamped(), 0u);
}

// Flow properties are a table per material (sim/fluid_stage.h): a boundary material carries the rest
// density of the fluid it bounds; the viscous time-step limit takes the most viscous fluid; two rest
// densities need DFSPH's multiphase form, and WCSPH refuses them by name.
TEST_F(SolverTest, FlowPropertiesArePerMaterialAndTwoRestDensitiesNeedDfsph) {
  Scene scene =
      dam_break({"materials.syrup={\"kind\": \"fluid\", \"density\": 1000, \"viscosity\": 0.5, "
                 "\"conductivity\": 0.5, \"specific_heat\": 3000}"});
  const int water = scene.fluids.at(0).material;
  int syrup = -1, wall = scene.wall_material;
  for (std::size_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].name == "syrup") syrup = int(m);
  ASSERT_GE(syrup, 0);
  ASSERT_GE(wall, 0);
  FluidBlock second = scene.fluids.at(0);
  second.material = syrup;
  second.box.min.z() = second.box.max.z() + 0.1;
  second.box.max.z() = second.box.min.z() + 0.1;
  second.shape = Shape::box(second.box.min, second.box.max);
  scene.fluids.push_back(second);
  const SolverConstants k = derive_constants(scene);
  EXPECT_FLOAT_EQ(k.kinematic_viscosity, 0.5f / 1000.0f) << "the most viscous fluid sets the viscous limit";
  const std::vector<fluid::MaterialFlow> table = material_flow_table(scene, k);
  ASSERT_EQ(table.size(), scene.materials.size());
  EXPECT_EQ(table[std::size_t(wall)].rest_density, table[std::size_t(water)].rest_density);
  EXPECT_GT(table[std::size_t(syrup)].viscosity, table[std::size_t(water)].viscosity);
  Solver both(cl(), scene, initial_state(scene));
  both.step();

  // Two rest densities: DFSPH's multiphase form only (sim/kernels/dfsph.cl); WCSPH is refused by name.
  scene.materials[std::size_t(syrup)].density = 1100;
  scene.solver.pressure = PressureSolver::Wcsph;
  try {
    Solver refused(cl(), scene, initial_state(scene));
    FAIL() << "two rest densities were accepted by wcsph";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "solver.pressure");
    EXPECT_NE(std::string(e.what()).find("dfsph"), std::string::npos) << e.what();
  }
  scene.solver.pressure = PressureSolver::Dfsph;
  Solver multiphase(cl(), scene, initial_state(scene));
  multiphase.step();
}

// Water that runs out through an open side is removed and booked, not held at the face: the fluid's mass
// now plus what left is its mass at the start, the enthalpy books close with the outflow, nothing is
// clamped on that side, and a run that removed particles resumes bit for bit.
TEST_F(SolverTest, WaterLeavingThroughAnOpenSideIsRemovedAndBooked) {
  const std::vector<std::string> open = {"domain.walls=[\"-x\", \"-y\", \"+y\", \"-z\"]",
                                         "domain.open=[\"+x\"]"};
  for (const double water_temperature : {20.0, 30.0}) {  // isothermal (no heat stage), and heat built
    std::vector<std::string> extra = open;
    extra.push_back("fluids[0].temperature=" + std::to_string(water_temperature));
    const Scene scene = dam_break(extra);
    const SimState start = initial_state(scene);
    Solver s(cl(), scene, start);
    const Metrics m0 = measure(s);
    std::size_t steps = 0;
    while (s.outflow().particles < 200 && steps < 20000) {
      s.step();
      ++steps;
    }
    ASSERT_GE(s.outflow().particles, 200u) << "no water left in " << steps << " steps";
    const Metrics m = measure(s);
    EXPECT_EQ(s.size() + s.outflow().particles, start.particles.size());
    EXPECT_NEAR(m.fluid_mass + s.outflow().mass, m0.fluid_mass, 1e-12 * m0.fluid_mass);
    EXPECT_GT(s.outflow().momentum.x(), 0.0) << "it left along +x";
    EXPECT_EQ(s.clamped(), 0u) << "nothing is held at the open side (the others hold no water here)";
    EXPECT_GT(s.energy_budget().outflow, 0.0);
    EXPECT_LT(std::abs(m.closure()), 1e-9 * m.enthalpy_scale) << "the enthalpy books close with the outflow";
    // A particle past the open side is removed at the next step's grid build: one there now crossed it
    // in this step's drift (x = x_before + v dt), which device rounding decides (a GPU left one 0.6 mm
    // past it where pocl left none).
    const HostParticles p = s.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      ASSERT_LE(p.position[i][0] - p.velocity[i][0] * s.dt(), scene.domain.max.x() + 1e-6)
          << "particle " << i;
  }

  // Resumed after particles have left: bit for bit, the books included.
  const Scene scene = dam_break(open);
  TempDir dir("outflow-resume");
  Solver straight(cl(), scene, initial_state(scene));
  while (straight.outflow().particles == 0) straight.step();
  run_steps(straight, 20);
  write_state_file(dir / "mid.state", straight.state());
  run_steps(straight, 40);
  const std::string expected = state_bytes(straight, dir, "straight.state");
  Solver resumed(cl(), scene, read_state_file(dir / "mid.state"));
  run_steps(resumed, 40);
  EXPECT_EQ(resumed.outflow().particles, straight.outflow().particles);
  const std::string got = state_bytes(resumed, dir, "resumed.state");
  EXPECT_TRUE(got == expected) << difference(got, expected);

  // A side cannot be both walled and open.
  try {
    dam_break({"domain.open=[\"-x\"]"});
    FAIL() << "an open side with a wall was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "domain.open");
  }
}

}  // namespace
}  // namespace thaw
