// Coatings (sim/substance_stage.h, issue 20, Orthmann et al. 2013 sec. 6.3-6.4): only a coating builds the
// deposit field; a dirty solid starts with its deposit on its outer layer alone; the kind's fields, its
// cleanser and a solid's deposits are refused at their path when wrong; in flowing water, coating and
// cleansing keep every kilogram and clean a dirty plate; the capacity caps what sticks; stained ice that
// melts gives its deposit to its own water; a resumed run goes on bitwise; the export carries the deposits;
// the coating and cleansing cases at CI resolution.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/particle_export.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "sim/substance_stage.h"
#include "sim/validation/case.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;
using testing::TempDir;

class DepositTest : public ClSuite {};

// A 3 x 3 cm tray without heat: soapy water sloshes over a greasy plate (12 x 12 x 6 mm, 4 layers deep).
Json greasy_plate() {
  return Json::parse(R"({
    "name": "deposit-test",
    "domain": {"min": [0, 0, 0], "max": [0.03, 0.03, 0.03], "walls": ["-z", "+x", "-x", "+y", "-y"],
               "wall_material": "glass"},
    "spacing": 0.0015,
    "heat": {"enabled": false},
    "materials": {"water": {"kind": "fluid", "density": 1000, "viscosity": 0.001, "conductivity": 0.6,
                            "specific_heat": 4186},
                  "glass": {"kind": "solid", "density": 2500, "conductivity": 1, "specific_heat": 800},
                  "china": {"kind": "solid", "density": 2400, "conductivity": 1.5, "specific_heat": 850}},
    "substances": {"soap": {"diffusivity": 1e-6},
                   "grease": {"kind": "coating", "diffusivity": 1e-6, "coating_rate": 1e-5,
                              "coating_capacity": 2e-4, "cleansed_by": "soap", "cleansing_rate": 0.5}},
    "solids": [{"shape": "box", "material": "china", "box": {"min": [0.009, 0.009, 0], "max": [0.021, 0.021, 0.006]},
                "deposits": {"grease": {"deposit": 1e-4}}}],
    "fluids": [{"material": "water", "box": {"min": [0, 0, 0.006], "max": [0.012, 0.03, 0.02]},
                "substances": {"soap": {"concentration": 10}}}]
  })");
}

double field_sum(const HostParticles& p, const std::string& field, int phase = -1) {
  const HostColumn* c = p.column(field);
  double total = 0;
  for (std::size_t i = 0; c && i < p.size(); ++i)
    if (phase < 0 || p.phase[i] == phase) total += double(c->as<Float2>()[i][0]) + c->as<Float2>()[i][1];
  return total;
}

std::string scene_error(const Json& doc) {
  try {
    scene_from_json(doc);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST_F(DepositTest, OnlyACoatingBuildsItsDepositField) {
  Json doc = greasy_plate();
  {
    const Scene scene = scene_from_json(doc);
    Solver s(cl(), scene, initial_state(scene));
    const HostParticles p = s.particles();
    EXPECT_NE(p.column(deposited_field("grease").name), nullptr);
    EXPECT_EQ(p.column(deposited_field("soap").name), nullptr);
  }
  doc["substances"]["grease"] = {{"diffusivity", 1e-6}};
  doc["solids"][0].erase("deposits");
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  EXPECT_EQ(s.particles().column(deposited_field("grease").name), nullptr);
}

// The plate is 8 x 8 x 4 lattice points: its outer layer holds Gamma0 dx^2 each, its core none.
TEST_F(DepositTest, ADirtySolidStartsWithItsDepositOnItsOuterLayer) {
  const Scene scene = scene_from_json(greasy_plate());
  const HostParticles p = initial_state(scene).particles;
  const HostColumn* c = p.column(deposited_field("grease").name);
  ASSERT_NE(c, nullptr);
  const double dx = scene.spacing, each = 1e-4 * dx * dx;
  std::size_t dirty = 0, clean_china = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double d = double(c->as<Float2>()[i][0]) + c->as<Float2>()[i][1];
    if (d > 0) {
      EXPECT_NEAR(d, each, 1e-6 * each);
      EXPECT_EQ(scene.materials[p.material[i]].name, "china");
      ++dirty;
    } else if (scene.materials[p.material[i]].name == "china") {
      ++clean_china;
    }
  }
  // The shell sampler rounds at the faces: its outer layer here has the 184 lattice points at the faces and
  // some next to them (206); the core stays clean.
  EXPECT_GE(dirty, 8u * 8u * 4u - 6u * 6u * 2u);
  EXPECT_GT(clean_china, 0u);
  EXPECT_EQ(dirty + clean_china, 8u * 8u * 4u);
}

TEST(DepositScene, WrongCoatingFieldsNameTheirPath) {
  Json doc = greasy_plate();
  doc["substances"]["grease"]["cleansed_by"] = "bleach";
  EXPECT_NE(scene_error(doc).find("substances.grease.cleansed_by"), std::string::npos) << scene_error(doc);
  doc["substances"]["grease"]["cleansed_by"] = "grease";
  EXPECT_NE(scene_error(doc).find("cannot cleanse itself"), std::string::npos) << scene_error(doc);
  doc = greasy_plate();
  doc["substances"]["grease"].erase("cleansed_by");
  EXPECT_NE(scene_error(doc).find("substances.grease.cleansing_rate"), std::string::npos) << scene_error(doc);
  doc = greasy_plate();
  doc["solids"][0]["deposits"] = {{"soap", {{"deposit", 1e-4}}}};
  EXPECT_NE(scene_error(doc).find("solids[0].deposits.soap"), std::string::npos) << scene_error(doc);
  EXPECT_NE(scene_error(doc).find("only a coating"), std::string::npos) << scene_error(doc);
  doc["solids"][0]["deposits"] = {{"wax", {{"deposit", 1e-4}}}};
  EXPECT_NE(scene_error(doc).find("solids[0].deposits.wax"), std::string::npos) << scene_error(doc);
  doc = greasy_plate();
  doc["substances"]["soap"]["coating_rate"] = 1e-4;
  EXPECT_NE(scene_error(doc).find("substances.soap.coating_rate"), std::string::npos) << scene_error(doc);
  doc = greasy_plate();
  doc["solids"][0]["deposits"]["grease"]["deposit"] = -1;
  EXPECT_NE(scene_error(doc).find("solids[0].deposits.grease.deposit"), std::string::npos)
      << scene_error(doc);
}

// The soapy column collapses over the plate: the soap takes grease off the plate into the water, and the
// grease in the water sticks to the walls and the plate again. Every kilogram stays accounted for.
TEST_F(DepositTest, WashingAPlateKeepsEveryKilogramAndCleansIt) {
  const Scene scene = scene_from_json(greasy_plate());
  Solver s(cl(), scene, initial_state(scene));
  const std::string stuck = deposited_field("grease").name, dissolved = substance_field("grease").name;
  const double start = s.substance_books().initial[1];
  ASSERT_GT(start, 0.0);
  EXPECT_NEAR(field_sum(s.particles(), stuck), start, 1e-12 * start);
  while (s.time() < 0.15) s.step();
  const HostParticles p = s.particles();
  const double on_solids = field_sum(p, stuck), in_water = field_sum(p, dissolved);
  EXPECT_LT(on_solids, 0.99 * start) << "the soap took no grease off";
  EXPECT_GT(in_water, 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const HostColumn* c = p.column(stuck);
    const double d = double(c->as<Float2>()[i][0]) + c->as<Float2>()[i][1];
    ASSERT_TRUE(std::isfinite(d));
    EXPECT_GE(d, -1e-20) << "particle " << p.id[i];
    if (p.phase[i] == std::uint8_t(Phase::Water)) {
      EXPECT_EQ(d, 0.0) << "water particle " << p.id[i] << " holds a deposit";
    }
  }
  const std::vector<double> total = s.substance_totals();
  EXPECT_LT(std::abs(total[1] - start), 1e-12 * start) << total[1] << " against " << start;
  EXPECT_LT(std::abs(total[0] - s.substance_books().initial[0]), 1e-12 * s.substance_books().initial[0]);
}

// Water rich in a coating over a clean floor: k_c c / Gamma_max = 100 / s fills each wet face to its capacity
// within 0.1 s, and no face takes more.
TEST_F(DepositTest, TheCapacityCapsWhatSticks) {
  Json doc = greasy_plate();
  doc["solver"] = {{"flow", false}, {"max_dt", 3600.0}};
  doc["substances"] = Json::parse(R"({"paint": {"kind": "coating", "diffusivity": 1e-6, "coating_rate": 1e-3,
                                               "coating_capacity": 1e-4}})");
  doc["solids"] = Json::array();
  doc["fluids"][0]["box"] = {{"min", {0.0, 0.0, 0.0}}, {"max", {0.03, 0.03, 0.006}}};
  doc["fluids"][0]["substances"] = {{"paint", {{"concentration", 10.0}}}};
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  while (s.time() < 0.1) s.step();
  const HostParticles p = s.particles();
  const HostColumn* c = p.column(deposited_field("paint").name);
  ASSERT_NE(c, nullptr);
  const double face = scene.spacing * scene.spacing;
  std::size_t full = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double gamma = (double(c->as<Float2>()[i][0]) + c->as<Float2>()[i][1]) / face;
    EXPECT_LE(gamma, 1e-4 * (1 + 1e-4)) << "particle " << p.id[i];
    full += gamma > 0.99e-4;
  }
  // The floor under the water: 20 x 20 faces wholly wet.
  EXPECT_GE(full, 20u * 20u);
}

// A dyed bath at 30 °C stains a cube of ice, which melts: its stain goes into its own meltwater, and once
// the ice is gone no water holds a deposit; the dye is conserved throughout.
TEST_F(DepositTest, StainedIceThatMeltsGivesItsDepositToItsWater) {
  Json doc = Json::parse(R"({
    "name": "stained-ice-test",
    "domain": {"min": [0, 0, 0], "max": [0.024, 0.024, 0.024], "walls": ["-z", "+x", "-x", "+y", "-y"],
               "wall_material": "glass"},
    "spacing": 0.0015,
    "heat": {"time_scale": 2000},
    "ambient": {"temperature": 30, "heat_transfer_coefficient": 0},
    "materials": {"water": {"kind": "fluid", "density": 1000, "viscosity": 0.001, "conductivity": 0.6,
                            "specific_heat": 4186},
                  "ice": {"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050,
                          "melts_into": "water"},
                  "glass": {"kind": "solid", "density": 2500, "conductivity": 1, "specific_heat": 800}},
    "substances": {"dye": {"kind": "coating", "diffusivity": 1e-6, "coating_rate": 1e-3,
                           "coating_capacity": 1e-4}},
    "ice": [{"material": "ice", "box": {"min": [0.009, 0.009, 0], "max": [0.015, 0.015, 0.006]}, "temperature": 0}],
    "fluids": [{"material": "water", "box": {"min": [0, 0, 0], "max": [0.024, 0.024, 0.009]}, "temperature": 30,
                "substances": {"dye": {"concentration": 5}}}]
  })");
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  const std::string stuck = deposited_field("dye").name;
  const double start = s.substance_books().initial[0];
  double most_on_ice = 0;
  std::size_t ice = s.particles().count(Phase::Ice);
  ASSERT_GT(ice, 0u);
  while (ice > 0 && s.time() < 1.0) {
    for (int k = 0; k < 20; ++k) s.step();
    const HostParticles p = s.particles();
    ice = p.count(Phase::Ice);
    most_on_ice = std::max(most_on_ice, field_sum(p, stuck, int(Phase::Ice)));
    EXPECT_EQ(field_sum(p, stuck, int(Phase::Water)), 0.0);
    EXPECT_LT(std::abs(s.substance_totals()[0] - start), 1e-12 * start);
  }
  EXPECT_GT(most_on_ice, 0.0) << "the dye never stained the ice";
  EXPECT_EQ(ice, 0u) << "the ice did not melt within 1 s";
}

TEST_F(DepositTest, AResumedRunGoesOnBitwise) {
  const Scene scene = scene_from_json(greasy_plate());
  EXPECT_TRUE(testing::resumes_bitwise(cl(), scene, initial_state(scene), 30, 20, "deposit-resume"));
}

TEST_F(DepositTest, TheExportCarriesTheDeposits) {
  const Scene scene = scene_from_json(greasy_plate());
  Solver s(cl(), scene, initial_state(scene));
  s.step();
  TempDir dir("deposit-export");
  ParticleExporter out(dir.path().string());
  out.write(s.particles(), s.time());
  const std::string vtu = testing::read_file_bytes(dir.path() / "frame_000000.vtu");
  EXPECT_NE(vtu.find("Name=\"deposited_grease\""), std::string::npos);
}

TEST_F(DepositTest, CoatingCasePassesAtCiResolution) {
  testing::expect_case_passes(run_validation(cl(), "coating", 6, {}));
}

TEST_F(DepositTest, CleansingCasePassesAtCiResolution) {
  testing::expect_case_passes(run_validation(cl(), "cleansing", 4, {}));
}

}  // namespace
}  // namespace thaw
