// The one list of a step's passes (sim/step_plan.h): what each scene builds, the two pressure solvers' lists,
// and docs/ARCHITECTURE.md's table of it.
#include "sim/step_plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace thaw {

// Failures name the passes.
void PrintTo(Pass p, std::ostream* os) { *os << pass_name(p); }

namespace {

namespace fs = std::filesystem;

std::vector<Pass> without(std::vector<Pass> plan, std::initializer_list<Pass> passes) {
  for (const Pass p : passes) plan.erase(std::remove(plan.begin(), plan.end(), p), plan.end());
  return plan;
}

bool has(const std::vector<Pass>& plan, Pass p) {
  return std::find(plan.begin(), plan.end(), p) != plan.end();
}

TEST(StepPlan, TheTwoSolversDifferOnlyInTheirSolvesAndWhereIceTakesItsForces) {
  const std::vector<Pass> wcsph = step_plan(every_stage(false)), dfsph = step_plan(every_stage(true));
  EXPECT_FALSE(has(wcsph, Pass::DivergenceSolve));
  EXPECT_FALSE(has(wcsph, Pass::DensitySolve));
  EXPECT_EQ(without(dfsph, {Pass::DivergenceSolve, Pass::DensitySolve, Pass::IceForces}),
            without(wcsph, {Pass::IceForces}));
  // DFSPH's ice takes its forces after the density solve has set the pressure.
  const auto at = [&](Pass p) { return std::find(dfsph.begin(), dfsph.end(), p) - dfsph.begin(); };
  EXPECT_LT(at(Pass::DensitySolve), at(Pass::IceForces));
  EXPECT_LT(at(Pass::IceForces), at(Pass::Bodies));
}

TEST(StepPlan, AStageNotBuiltHasNoPass) {
  // A heat-only scene without lamps: the sort, the time step, heat and the clock.
  BuiltStages heat_only;
  heat_only.heat = true;
  EXPECT_EQ(step_plan(heat_only), (std::vector<Pass>{Pass::Grid, Pass::TimeStep, Pass::Heat, Pass::Advance}));
  // With lamps (on or off: they may be switched on live), their photons before heat.
  heat_only.photons = true;
  EXPECT_EQ(step_plan(heat_only),
            (std::vector<Pass>{Pass::Grid, Pass::TimeStep, Pass::Photons, Pass::Heat, Pass::Advance}));
  // Water alone.
  BuiltStages water;
  water.flow = true;
  EXPECT_EQ(step_plan(water), (std::vector<Pass>{Pass::Grid, Pass::Density, Pass::Forces, Pass::TimeStep,
                                                 Pass::Integrate, Pass::Advance}));
}

TEST(StepPlan, EveryTimedPassAddsToItsStagesTimer) {
  for (const Pass p : step_plan(every_stage(true))) {
    Stage t = Stage::Count;
    if (p == Pass::Advance) {
      EXPECT_FALSE(pass_timer(p, t));
      continue;
    }
    ASSERT_TRUE(pass_timer(p, t)) << pass_name(p);
    EXPECT_NE(std::string(pass_stage(p)), "") << pass_name(p);
  }
}

TEST(StepPlan, TheArchitectureDocShowsThePlan) {
  const fs::path doc = fs::path(THAW_SOURCE_DIR) / "docs" / "ARCHITECTURE.md";
  const std::string begin = "<!-- step table: generated from step_plan() -->\n";
  const std::string end = "<!-- end of step table -->\n";
  std::stringstream text;
  text << std::ifstream(doc, std::ios::binary).rdbuf();
  std::string s = text.str();
  const std::size_t a = s.find(begin), b = s.find(end);
  ASSERT_NE(a, std::string::npos) << doc << " has lost the marker " << begin;
  ASSERT_NE(b, std::string::npos) << doc << " has lost the marker " << end;
  const std::string table = step_table();
  const char* update = std::getenv("THAW_UPDATE_DOCS");
  if (update != nullptr && std::string(update) == "1") {
    s = s.substr(0, a + begin.size()) + table + s.substr(b);
    std::ofstream(doc, std::ios::binary) << s;
    return;
  }
  EXPECT_EQ(s.substr(a + begin.size(), b - a - begin.size()), table)
      << doc.string()
      << "'s step table differs from the solver's list; regenerate it with\n"
         "  THAW_UPDATE_DOCS=1 ./thaw_tests --gtest_filter=StepPlan.TheArchitectureDocShowsThePlan";
}

}  // namespace
}  // namespace thaw
