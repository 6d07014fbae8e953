// Validation cases at CI-sized resolution, and the references' own properties.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/validation/case.h"
#include "sim/validation/hydrostatic_profile.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;
using testing::TempDir;
using testing::run_thaw;

class Validation : public ClSuite {};

void print(const CaseResult& r) {
  for (const auto& [key, m] : r.metrics)
    std::printf("  %-28s value %-12.6g reference %-12.6g error %-10.4g gate %g\n", key.c_str(), m.value, m.reference,
                m.error, m.gate);
}

TEST_F(Validation, HydrostaticPassesAtCiResolution) {
  const CaseResult r = run_validation(cl(), "hydrostatic", 20, {});
  print(r);
  EXPECT_TRUE(r.passed());
  ASSERT_EQ(r.metrics.size(), 4u);
  for (const auto& [key, m] : r.metrics) EXPECT_LE(m.error, m.gate) << key;
}

// Issue 17's hydrostatic gate for DFSPH: the same tank and reference, the profile within 1 % of rho0 g H
// and the mean speed below 1e-3 sqrt(gH), the step far longer than WCSPH's (DfsphTest checks the ratio).
// DFSPH's pressure is a per-step impulse that swings from step to step with the Jacobi iterations it took,
// so every step of a longer window is sampled (at the WCSPH setting, 1 step in 5 over 0.1 s, the case
// measured 0.14 % and 0.95e-3: a thin margin on the speed). Tolerance 0.05 % as SPlisHSPlasH's default;
// at the default 0.1 % the case measured 0.33 % and 0.94e-3 (docs/VALIDATION-RESULTS.md).
TEST_F(Validation, HydrostaticWithDfsphPassesAtCiResolution) {
  const CaseResult r =
      run_validation(cl(), "hydrostatic", 20,
                     {"solver.pressure=dfsph", "solver.density_tolerance=0.0005",
                      "solver.divergence_tolerance=0.0005"});  // sampling by the solver: every step, 0.5 s
  print(r);
  EXPECT_TRUE(r.passed());
  for (const auto& [key, m] : r.metrics) EXPECT_LE(m.error, m.gate) << key;
}

// The reference is computed from the parameters: its bottom pressure is the column's weight per area
// whatever the gravity, density or stiffness, and it tends to rho0 g (H - z) as the fluid stiffens.
TEST(HydrostaticReference, WeighsTheColumnAndTendsToTheIncompressibleProfile) {
  for (double g : {1.62, 9.81, 24.8})
    for (double B : {1e4, 1e5, 1e7}) {
      const HydrostaticProfile p{1000.0, g, 0.3, B, 7.0, true};
      EXPECT_NEAR(p.pressure_at(0.0), 1000.0 * g * 0.3, 1e-9 * 1000.0 * g * 0.3);
      EXPECT_LE(p.top(), 0.3);
      EXPECT_EQ(p.pressure_at(p.top() + 1e-9), 0.0);
      const HydrostaticProfile lin{1000.0, g, 0.3, B * 7.0, 7.0, false};
      EXPECT_NEAR(lin.pressure_at(0.0), 1000.0 * g * 0.3, 1e-9 * 1000.0 * g * 0.3);
    }
  const HydrostaticProfile stiff{1000.0, 9.81, 0.3, 1e12, 7.0, true};
  for (double z : {0.0, 0.1, 0.2}) EXPECT_NEAR(stiff.pressure_at(z), 1000.0 * 9.81 * (0.3 - z), 1e-3);
  // A particle whose column above weighs rho0 g (H - z) sits where the profile gives that pressure.
  const HydrostaticProfile soft{1000.0, 9.81, 0.3, 2e4, 7.0, true};
  for (double z : {0.01, 0.15, 0.29})
    EXPECT_NEAR(soft.pressure_at(soft.height_of(z)), 1000.0 * 9.81 * (0.3 - z), 1e-6 * 1000.0 * 9.81 * 0.3);
}

TEST_F(Validation, HydrostaticReferenceFollowsOverriddenParameters) {
  // A shorter, lighter column on the Moon: the case still compares against its own exact profile.
  const CaseResult r = run_validation(cl(), "hydrostatic", 12,
                                      {"height=0.12", "width=0.1", "gravity=1.62", "density=900", "settle_time=0.6",
                                       "free_time=0.05", "pressure_gate=1"});
  print(r);
  const auto& profile = r.metrics.front().second;
  // The bottom of the interior sees close to rho0 g H of the overridden parameters.
  EXPECT_LT(profile.reference, 900.0 * 1.62 * 0.12);
  EXPECT_GT(profile.reference, 0.0);
  EXPECT_EQ(r.metrics.back().first, "mass");
  EXPECT_EQ(r.metrics.back().second.error, 0.0);
}

// The front leads Martin & Moyce's from T* ~ 0.8 in every run here (free-slip or frictional walls,
// resolutions 10 to 30: see docs/VALIDATION-RESULTS.md), by about 0.2-0.3 in T*; the experiment's gate
// took time to open. What is asserted is what holds: the front advances, never strays 20 % from the
// data, is inside the gate at T* = 3, and runs at the data's speed over the window.
// The dam break against Martin & Moyce with both pressure solvers at the case's resolution, 20 particles
// across the column (issue 17's gate; at 16, WCSPH's front at T* = 1.219 is 5.9 % off, 0.09 a, within the
// digitized data's 0.1-0.15 a): the front leads the
// data by a start-time shift dT* in [0, 0.3] (their gate took time to open), and after that shift every
// compared position is within 5 % and the front only advances; its speed over the window within 10 %. A
// window that leaves the measured shift out fails on the shift alone.
TEST_F(Validation, DamBreakFrontFollowsMartinMoyceAfterTheGatesOpeningTime) {
  for (const char* pressure : {"solver.pressure=wcsph", "solver.pressure=dfsph"}) {
    const CaseResult r = run_validation(cl(), "dam-break", 20, {pressure});
    print(r);
    EXPECT_TRUE(r.passed()) << pressure;
    ASSERT_GE(r.metrics.size(), 4u);
    EXPECT_EQ(r.metrics.front().first, "front_time_shift_dT*");
    const double shift = r.metrics.front().second.value;
    EXPECT_GE(shift, 0.0) << pressure;
    EXPECT_LE(shift, 0.3) << pressure;
    double previous = 1.0;
    for (auto it = r.metrics.begin() + 1; it + 1 != r.metrics.end(); ++it) {
      const auto& [key, m] = *it;
      EXPECT_EQ(key.rfind("front_Z/a_at_T*=", 0), 0u) << key;
      EXPECT_NE(key.find("_shifted"), std::string::npos) << key;
      EXPECT_TRUE(std::isfinite(m.value)) << key;
      EXPECT_GT(m.value, previous) << key << ": the front only advances";
      previous = m.value;
      EXPECT_LE(m.error, 0.05) << pressure << " " << key;
    }
    const auto& [speed_key, speed] = r.metrics.back();
    EXPECT_EQ(speed_key, "front_speed_dZ/dT*");
    EXPECT_LE(speed.error, speed.gate) << speed.value << " against " << speed.reference;
  }
  const CaseResult narrow = run_validation(cl(), "dam-break", 20, {"solver.pressure=dfsph", "shift_max=0.1"});
  EXPECT_FALSE(narrow.passed());
  EXPECT_FALSE(narrow.metrics.front().second.passed()) << narrow.metrics.front().second.value;
  // A no-slip bed (the walls take the fluid's viscosity) holds the front back: slower over the window
  // than the free-slip run above (the narrow window changes the gates, not the run).
  const double free_slip_speed = narrow.metrics.back().second.value;
  const CaseResult bed = run_validation(cl(), "dam-break", 20, {"solver.pressure=dfsph", "bed=no-slip"});
  print(bed);
  EXPECT_LT(bed.metrics.back().second.value, 0.95 * free_slip_speed);
}

TEST_F(Validation, ConductionPassesOnOrderedAndJitteredParticles) {
  for (const char* jitter : {"jitter=0", "jitter=0.1"}) {
    const CaseResult r = run_validation(cl(), "conduction", 3, {jitter});
    print(r);
    EXPECT_TRUE(r.passed()) << jitter;
    ASSERT_EQ(r.metrics.size(), 3u);
    EXPECT_EQ(r.metrics[0].second.gate, std::string(jitter) == "jitter=0" ? 0.01 : 0.03);
  }
}

// Melting and freezing at 20 particles across the front, one-phase (the slab at the melting point) so
// that CI stays short; the default two-phase case is in docs/VALIDATION-RESULTS.md.
TEST_F(Validation, StefanMeltingAndFreezingPass) {
  for (const std::vector<std::string>& set : {std::vector<std::string>{"wall_temperature=30", "initial_temperature=0"},
                                              std::vector<std::string>{"wall_temperature=-20", "initial_temperature=0"}}) {
    const CaseResult r = run_validation(cl(), "stefan", 20, set);
    print(r);
    EXPECT_TRUE(r.passed()) << set[0];
    ASSERT_EQ(r.metrics.size(), 2u);
    EXPECT_EQ(r.metrics[0].first, "front");
    // The reference follows the parameters: a hotter wall melts faster than the table's +10 °C.
    if (set[0] == "wall_temperature=30") {
      EXPECT_GT(r.metrics[0].second.reference, 4.395e-3 * 1.2);
    }
  }
}

TEST_F(Validation, StefanRefusesParametersThatNeitherMeltNorFreeze) {
  EXPECT_THROW(run_validation(cl(), "stefan", 5, {"wall_temperature=10", "initial_temperature=5"}), SceneError);
  EXPECT_THROW(run_validation(cl(), "stefan", 5, {"wall_temperature=0"}), SceneError);
}

TEST(ValidateCli, JsonReportHasTheDocumentedShape) {
  TempDir dir("validate-json");
  const auto r = run_thaw(
      "validate hydrostatic --res 8 --set width=0.2 --set interior_margin=1 --set settle_time=0.05 --set free_time=0.01 --json", dir);
  ASSERT_TRUE(r.exited);
  const Json j = Json::parse(r.out);
  EXPECT_EQ(j["case"], "hydrostatic");
  for (const char* key : {"passed", "particles", "steps", "wall_s", "metrics"}) EXPECT_TRUE(j.contains(key)) << key;
  for (const auto& [name, m] : j["metrics"].items())
    for (const char* key : {"value", "reference", "error", "gate"}) EXPECT_TRUE(m.contains(key)) << name << "." << key;
  EXPECT_EQ(r.exit_code, j["passed"].get<bool>() ? 0 : 1);
}

TEST(ValidateCli, BadCaseParameterNamesItsPath) {
  TempDir dir("validate-bad");
  const auto r = run_thaw("validate hydrostatic --res 8 --set heigth=0.1", dir);
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("heigth"), std::string::npos) << r.err;
}

// Rigid-body dynamics alone (no device work): each axis for the default 20 revolutions at a CI size.
TEST_F(Validation, RigidSpinKeepsItsInvariantsAndFlipsOnlyTheIntermediateAxis) {
  for (const std::string axis : {"min", "intermediate", "max"}) {
    const CaseResult r = run_validation(cl(), "rigid-spin", 10, {"axis=" + axis});
    print(r);
    EXPECT_TRUE(r.passed()) << axis;
    ASSERT_EQ(r.metrics.size(), 7u);
    EXPECT_EQ(r.metrics.back().first, axis == "intermediate" ? "axis_flip" : "axis_wander");
  }
  // The references follow the parameters: a faster spin of another box still passes against its own.
  const CaseResult r = run_validation(cl(), "rigid-spin", 12,
                                      {"a=0.05", "b=0.02", "c=0.035", "spin=3", "dt=1e-4", "revolutions=10"});
  print(r);
  EXPECT_TRUE(r.passed());
  EXPECT_THROW(run_validation(cl(), "rigid-spin", 10, {"b=0.04"}), SceneError);
}

// A wide prism (breadth = height) let go at 10 degrees rights itself and floats at Archimedes' draft,
// below the surface one sees and below the level the water's mass makes.
TEST_F(Validation, FloatingWidePrismRightsItselfAtArchimedesDraft) {
  const CaseResult r = run_validation(cl(), "floating", 10, {"breadth_ratio=1.0", "run_time=1"});
  print(r);
  EXPECT_TRUE(r.passed());
  ASSERT_EQ(r.metrics.size(), 3u);
  EXPECT_EQ(r.metrics[0].first, "heel_degrees");
  EXPECT_EQ(r.metrics[0].second.reference, 0.0);
  EXPECT_EQ(r.metrics[1].first, "draft_over_height");
  EXPECT_NEAR(r.metrics[1].second.reference, 917.0 / 1000.0, 1e-12);
  EXPECT_EQ(r.metrics[2].first, "draft_below_mass_level_over_height");
}

// A narrow prism (breadth = height / 2) is unstable upright: let go at 10 degrees it capsizes and comes to
// rest on its side (reference 90 degrees, from the righting arm). A smaller tank than the case's default
// keeps it to 18,734 particles; at 12 particles across the height it reached 85.1 degrees after 2.5 s
// (at 8 across, in the default tank, water perched on the nearly level upper face held it at 37 degrees
// after 3 s; docs/VALIDATION-RESULTS.md).
TEST_F(Validation, FloatingNarrowPrismCapsizesOntoItsSide) {
  const CaseResult r = run_validation(cl(), "floating", 12,
                                      {"breadth_ratio=0.5", "margin=0.35", "depth=1.1", "run_time=2.5"});
  print(r);
  EXPECT_TRUE(r.passed());
  ASSERT_EQ(r.metrics.size(), 1u);
  EXPECT_EQ(r.metrics[0].second.reference, 90.0);
}

// Free ice under DFSPH (issue 17): the same prism at the default step and tolerances. Its draft below the
// water's mass level (Archimedes' level: the pressure under the prism is g times the mass above) comes out
// short of 0.917 by 0.112 spacings at res 10, 0.085 at 12, 0.031 at 14 and 0.076 at 16
// (docs/VALIDATION-RESULTS.md): within the 1 % of the height from res 12 on, which is gated here
// (measured 0.0060 of the height, 48 s; 0.0071 with the divergence solve warm-started). The visible surface
// lies 0.40-0.42 spacings below the mass level (as WCSPH's), which puts the surface draft at the edge of the
// case's half-spacing gate (0.97 of it at res 12, 1.04 at res 10), so it is printed, not asserted.
TEST_F(Validation, FloatingWidePrismUnderDfsphFloatsWithinOnePercentOfItsHeight) {
  const CaseResult r =
      run_validation(cl(), "floating", 12, {"breadth_ratio=1.0", "run_time=1", "solver.pressure=dfsph"});
  print(r);
  ASSERT_EQ(r.metrics.size(), 3u);
  EXPECT_EQ(r.metrics[0].first, "heel_degrees");
  EXPECT_LE(r.metrics[0].second.error, r.metrics[0].second.gate);
  const auto& [name, draft] = r.metrics[2];
  EXPECT_EQ(name, "draft_below_mass_level_over_height");
  EXPECT_NEAR(draft.reference, 0.917, 1e-12);
  EXPECT_LE(draft.error, draft.gate);
  EXPECT_LT(draft.error, 0.01);
}

// The narrow prism of FloatingNarrowPrismCapsizesOntoItsSide, under DFSPH: it capsizes onto its side too.
// At 14 particles across the height: 89.70 degrees after 2 s (60 s of wall time), 89.74 after 2.5 s, 89.76
// with the divergence solve warm-started. At 12 the resting angle depends on that choice (89.4
// warm-started, 99.6 from zero: it rolls past its side and stays there), at 10 it does not capsize (22-24
// degrees after 2.5 s) with either.
TEST_F(Validation, FloatingNarrowPrismCapsizesUnderDfsph) {
  const CaseResult r = run_validation(
      cl(), "floating", 14,
      {"breadth_ratio=0.5", "margin=0.35", "depth=1.1", "run_time=2", "solver.pressure=dfsph"});
  print(r);
  EXPECT_TRUE(r.passed());
  ASSERT_EQ(r.metrics.size(), 1u);
  EXPECT_EQ(r.metrics[0].second.reference, 90.0);
}

}  // namespace
}  // namespace thaw
