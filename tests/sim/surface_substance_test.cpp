// Surface-active substances (sim/substance_stage.h, issue 20, Orthmann et al. 2013 sec. 5-6.2): such a
// substance builds the surface stage even without heat, and only it builds the adsorbed field; its kind's
// fields are refused on a bulk substance at their path; in flowing water, adsorption, desorption, surface
// diffusion and the hand-back of particles drawn under keep every kilogram, through an open side too; a
// resumed run goes on bit for bit; the export shows the surface excess; the adsorption and
// surface-diffusion cases at CI resolution.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/particle_export.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "sim/validation/case.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;
using testing::TempDir;

class SurfaceSubstanceTest : public ClSuite {};

// A 4 x 2 x 4 cm tank without heat: a column of water with a detergent in it collapses onto a clear layer.
// `open`: the +x side is open and the water runs out through it.
Json detergent_tank(bool open) {
  Json doc = Json::parse(R"({
    "name": "surface-substance-test",
    "domain": {"min": [0, 0, 0], "max": [0.04, 0.02, 0.04], "walls": ["-x", "+x", "-y", "+y", "-z"],
               "wall_material": "glass"},
    "spacing": 0.002,
    "heat": {"enabled": false},
    "materials": {"water": {"kind": "fluid", "density": 1000, "viscosity": 0.001, "conductivity": 0.6,
                            "specific_heat": 4186},
                  "glass": {"kind": "solid", "density": 2500, "conductivity": 1, "specific_heat": 800}},
    "substances": {"soap": {"kind": "surface_active", "diffusivity": 1e-6, "surface_diffusivity": 1e-6,
                            "adsorption_rate": 1e-3, "desorption_rate": 1, "surface_capacity": 1e-6},
                   "dye": {"diffusivity": 1e-6}},
    "fluids": [{"material": "water", "box": {"min": [0, 0, 0], "max": [0.014, 0.02, 0.03]},
                "substances": {"soap": {"concentration": 1}, "dye": {"concentration": 2}}},
               {"material": "water", "box": {"min": [0.014, 0, 0], "max": [0.04, 0.02, 0.008]}}]
  })");
  if (open) {
    doc["domain"]["walls"] = Json::array({"-x", "-y", "+y", "-z"});
    doc["domain"]["open"] = Json::array({"+x"});
  }
  return doc;
}

double on_surface(const HostParticles& p, const std::string& name) {
  const HostColumn* c = p.column(adsorbed_field(name).name);
  double total = 0;
  for (std::size_t i = 0; c && i < p.size(); ++i)
    total += double(c->as<Float2>()[i][0]) + c->as<Float2>()[i][1];
  return total;
}

bool has_stage(const Solver& s, const std::string& name) {
  for (const std::string& stage : s.stages())
    if (stage == name) return true;
  return false;
}

TEST_F(SurfaceSubstanceTest, OnlyASurfaceActiveSubstanceBuildsTheSurfaceAndItsField) {
  Json doc = detergent_tank(false);
  {
    const Scene scene = scene_from_json(doc);
    Solver s(cl(), scene, initial_state(scene));
    EXPECT_TRUE(has_stage(s, "surface (brackbill1992)"));
    const HostParticles p = s.particles();
    EXPECT_NE(p.column(adsorbed_field("soap").name), nullptr);
    EXPECT_EQ(p.column(adsorbed_field("dye").name), nullptr);
  }
  doc["substances"]["soap"] = {{"diffusivity", 1e-6}};
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  for (const std::string& stage : s.stages()) EXPECT_EQ(stage.find("surface"), std::string::npos) << stage;
  EXPECT_EQ(s.particles().column(adsorbed_field("soap").name), nullptr);
}

TEST(SurfaceSubstanceScene, SurfaceFieldsOnABulkSubstanceNameTheirPath) {
  Json doc = detergent_tank(false);
  doc["substances"]["dye"]["adsorption_rate"] = 1e-4;
  try {
    scene_from_json(doc);
    FAIL() << "an adsorption rate on a bulk substance was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("substances.dye.adsorption_rate"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("surface_active"), std::string::npos) << e.what();
  }
  doc = detergent_tank(false);
  doc["substances"]["soap"]["kind"] = "coated";
  EXPECT_THROW(scene_from_json(doc), SceneError);
  doc = detergent_tank(false);
  doc["substances"]["soap"]["desorption_rate"] = -1;
  EXPECT_THROW(scene_from_json(doc), SceneError);
}

// The column collapses and splashes: particles come to the surface and are drawn under it, the areas are
// renewed every heat.area_interval steps, the surface takes detergent and gives it back, and it diffuses
// along the surface. Every kilogram stays accounted for.
TEST_F(SurfaceSubstanceTest, FlowingDetergentIsConservedOnTheSurfaceAndInTheBulk) {
  const Scene scene = scene_from_json(detergent_tank(false));
  Solver s(cl(), scene, initial_state(scene));
  const double start = s.substance_books().initial[0];
  ASSERT_GT(start, 0.0);
  EXPECT_EQ(on_surface(s.particles(), "soap"), 0.0);
  double most = 0;
  while (s.time() < 0.1) {
    s.step();
    if (s.steps() % 20 == 0) most = std::max(most, on_surface(s.particles(), "soap"));
  }
  // The column's free surface, about 2e-3 m^2, holds 2e-9 kg at its capacity; k_a c / Gamma_max = 1000 / s
  // fills it within milliseconds.
  EXPECT_GT(most, 5e-10) << "the surface took no detergent";
  const HostParticles p = s.particles();
  const HostColumn* a = p.column("surface_area");
  const HostColumn* q = p.column(adsorbed_field("soap").name);
  ASSERT_NE(a, nullptr);
  double held = 0, area = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double own = double(q->as<Float2>()[i][0]) + q->as<Float2>()[i][1];
    ASSERT_TRUE(std::isfinite(own));
    EXPECT_GE(own, -1e-18) << "particle " << p.id[i];
    held += own;
    if (a->as<float>()[i] > kSurfaceMinArea * 0.002 * 0.002) area += a->as<float>()[i];
  }
  // The Langmuir term stops uptake at the capacity. A particle's excess rises above it where its area shrank
  // since it took up (the surface compressed), until it desorbs, so only the mean is bounded.
  EXPECT_LT(held, 1.5e-6 * area) << held << " kg on " << area << " m^2";
  const std::vector<double> total = s.substance_totals();
  EXPECT_LT(std::abs(total[0] - start), 1e-12 * start) << total[0] << " against " << start;
  EXPECT_LT(std::abs(total[1] - s.substance_books().initial[1]), 1e-12 * s.substance_books().initial[1]);
}

TEST_F(SurfaceSubstanceTest, DetergentThatLeavesThroughAnOpenSideIsBookedWithWhatItsSurfaceHeld) {
  const Scene scene = scene_from_json(detergent_tank(true));
  Solver s(cl(), scene, initial_state(scene));
  while (s.substance_books().outflow[0] == 0.0 && s.time() < 0.6) s.step();
  for (int i = 0; i < 50; ++i) s.step();
  ASSERT_GT(s.outflow().particles, 0u);
  const SubstanceBooks& b = s.substance_books();
  ASSERT_GT(b.outflow[0], 0.0);
  EXPECT_GT(on_surface(s.particles(), "soap"), 0.0);
  EXPECT_LT(std::abs(s.substance_totals()[0] + b.outflow[0] - b.initial[0]), 1e-12 * b.initial[0]);
}

TEST_F(SurfaceSubstanceTest, AResumedRunGoesOnBitwise) {
  const Scene scene = scene_from_json(detergent_tank(false));
  // 22 steps: not a multiple of heat.area_interval, so stale areas are saved
  EXPECT_TRUE(
      testing::resumes_bitwise(cl(), scene, initial_state(scene), 22, 20, "surface-substance-resume"));
}

// The VTU export shows what the surface holds as the surface excess [kg/m^2].
TEST_F(SurfaceSubstanceTest, TheExportCarriesTheSurfaceExcess) {
  const Scene scene = scene_from_json(detergent_tank(false));
  Solver s(cl(), scene, initial_state(scene));
  for (int i = 0; i < 10; ++i) s.step();
  TempDir dir("surface-substance-export");
  ParticleExporter out(dir.path().string());
  out.write(s.particles(), s.time());
  const std::string vtu = testing::read_file_bytes(dir.path() / "frame_000000.vtu");
  EXPECT_NE(vtu.find("Name=\"adsorbed_soap\""), std::string::npos);
}

TEST_F(SurfaceSubstanceTest, AdsorptionCasePassesAtCiResolution) {
  testing::expect_case_passes(run_validation(cl(), "adsorption", 4, {}));
}

TEST_F(SurfaceSubstanceTest, SurfaceDiffusionCasePassesAtCiResolution) {
  testing::expect_case_passes(run_validation(cl(), "surface-diffusion", 8, {}));
}

}  // namespace
}  // namespace thaw
