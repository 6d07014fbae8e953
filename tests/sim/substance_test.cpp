// Substances dissolved in the water (sim/substance_stage.h, issue 20): the stage is built only where a scene
// declares substances; a dyed block spreads its dye into clear water under both pressure solvers with every
// kilogram accounted for, including what leaves through an open side; a resumed run goes on bit for bit;
// scene mistakes name their path; the export carries the mass fraction; the bulk-diffusion case at CI
// resolution.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "sim/metrics.h"
#include "sim/particle_export.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "sim/thermal.h"
#include "sim/validation/case.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;
using testing::TempDir;

class SubstanceTest : public ClSuite {};

// A 4 x 2 x 4 cm tank: a dyed column of water beside a clear layer, which it collapses onto. `open` opens
// the +x side (no wall there), so the water runs out through it.
Json dyed_tank(bool open, const std::string& pressure = "wcsph") {
  Json doc = Json::parse(R"({
    "name": "substance-test",
    "domain": {"min": [0, 0, 0], "max": [0.04, 0.02, 0.04], "walls": ["-x", "+x", "-y", "+y", "-z"],
               "wall_material": "glass"},
    "spacing": 0.002,
    "materials": {"water": {"kind": "fluid", "density": 1000, "viscosity": 0.001, "conductivity": 0.6,
                            "specific_heat": 4186},
                  "glass": {"kind": "solid", "density": 2500, "conductivity": 1, "specific_heat": 800}},
    "substances": {"dye": {"diffusivity": 1e-6}, "salt": {"diffusivity": 1.5e-9}},
    "fluids": [{"material": "water", "box": {"min": [0, 0, 0], "max": [0.014, 0.02, 0.03]},
                "substances": {"dye": {"concentration": 2}, "salt": {"concentration": 35}}},
               {"material": "water", "box": {"min": [0.014, 0, 0], "max": [0.04, 0.02, 0.008]}}]
  })");
  doc["solver"]["pressure"] = pressure;
  if (open) {
    doc["domain"]["walls"] = Json::array({"-x", "-y", "+y", "-z"});
    doc["domain"]["open"] = Json::array({"+x"});
  }
  return doc;
}

// Each particle's amount of `name` [kg], hi + lo, by particle index.
std::vector<double> amounts(const HostParticles& p, const std::string& name) {
  const HostColumn* c = p.column(substance_field(name).name);
  std::vector<double> out;
  if (!c) return out;
  for (std::size_t i = 0; i < p.size(); ++i)
    out.push_back(double(c->as<Float2>()[i][0]) + c->as<Float2>()[i][1]);
  return out;
}

TEST_F(SubstanceTest, OnlyAScenesWithSubstancesBuildsTheStage) {
  Json doc = dyed_tank(false);
  {
    const Scene scene = scene_from_json(doc);
    Solver s(cl(), scene, initial_state(scene));
    bool built = false;
    for (const std::string& stage : s.stages()) built = built || stage == "substances (2)";
    EXPECT_TRUE(built);
    EXPECT_EQ(s.substance_totals().size(), 2u);
  }
  doc.erase("substances");
  for (Json& f : doc["fluids"]) f.erase("substances");
  const Scene scene = scene_from_json(doc);
  const SimState st = initial_state(scene);
  EXPECT_EQ(st.particles.column(substance_field("dye").name), nullptr);
  Solver s(cl(), scene, st);
  for (const std::string& stage : s.stages()) EXPECT_EQ(stage.find("substances"), std::string::npos) << stage;
  EXPECT_TRUE(s.substance_totals().empty());
  EXPECT_TRUE(s.state().substances.empty());
}

// The dyed column falls onto the clear layer: after 0.15 s dye has reached clear water, and each
// substance's total is the start's to round-off (the pairs' transfers cancel to the bit) under both
// solvers. The start's total is the concentration times the dyed block's particles' volume.
TEST_F(SubstanceTest, ADyedColumnSpreadsIntoClearWaterAndEveryKilogramIsAccountedFor) {
  for (const std::string pressure : {"wcsph", "dfsph"}) {
    const Scene scene = scene_from_json(dyed_tank(false, pressure));
    const SimState st = initial_state(scene);
    const std::vector<double> dye0 = amounts(st.particles, "dye");
    std::size_t dyed = 0;
    for (double a : dye0) dyed += a > 0;
    ASSERT_GT(dyed, 0u);
    const double particle_volume = 0.002 * 0.002 * 0.002;
    Solver s(cl(), scene, st);
    EXPECT_NEAR(s.substance_books().initial[0], 2.0 * particle_volume * double(dyed), 1e-12) << pressure;
    EXPECT_NEAR(s.substance_books().initial[1], 35.0 * particle_volume * double(dyed), 1e-11) << pressure;
    while (s.time() < 0.15) s.step();
    const HostParticles p = s.particles();
    const std::vector<double> dye = amounts(p, "dye");
    std::size_t reached = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      ASSERT_TRUE(std::isfinite(dye[i])) << pressure;
      EXPECT_GE(dye[i], -1e-18) << pressure << ": particle " << p.id[i];
      if (dye0[p.id[i]] == 0.0 && dye[i] > 1e-3 * dye0[0]) ++reached;
    }
    EXPECT_GT(reached, 10u) << pressure << ": dye reached " << reached << " clear particles";
    const std::vector<double> total = s.substance_totals();
    for (std::size_t k = 0; k < 2; ++k)
      EXPECT_LT(std::abs(total[k] - s.substance_books().initial[k]), 1e-12 * s.substance_books().initial[k])
          << pressure << ", substance " << k << ": " << total[k] << " against "
          << s.substance_books().initial[k];
    const Json m = substances_json(s);
    EXPECT_LT(std::abs(m["dye"]["closure_relative"].get<double>()), 1e-12);
  }
}

// Water running out of the open +x side takes its dye with it: the books hold what left, and what is left
// plus what left is the start's.
TEST_F(SubstanceTest, DyeThatLeavesThroughAnOpenSideIsBooked) {
  const Scene scene = scene_from_json(dyed_tank(true));
  Solver s(cl(), scene, initial_state(scene));
  while (s.substance_books().outflow[0] == 0.0 && s.time() < 0.4) s.step();
  for (int i = 0; i < 50; ++i) s.step();
  ASSERT_GT(s.outflow().particles, 0u);
  const SubstanceBooks& b = s.substance_books();
  ASSERT_GT(b.outflow[0], 0.0) << "no dye left with the water";
  for (std::size_t k = 0; k < 2; ++k)
    EXPECT_LT(std::abs(s.substance_totals()[k] + b.outflow[k] - b.initial[k]), 1e-12 * b.initial[k]) << k;
  // The state carries the books: a run resumed from it reports the same account.
  Solver resumed(cl(), scene, s.state());
  EXPECT_EQ(resumed.substance_books().initial, b.initial);
  EXPECT_EQ(resumed.substance_books().outflow, b.outflow);
}

TEST_F(SubstanceTest, AResumedRunGoesOnBitwise) {
  const Scene scene = scene_from_json(dyed_tank(false));
  EXPECT_TRUE(testing::resumes_bitwise(cl(), scene, initial_state(scene), 20, 20, "substance-resume"));
}

TEST(SubstanceScene, MistakesNameTheirPath) {
  {
    Json doc = dyed_tank(false);
    doc["fluids"][1]["substances"] = {{"ink", {{"concentration", 1}}}};
    try {
      scene_from_json(doc);
      FAIL() << "an undeclared substance was accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("fluids[1].substances.ink"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("dye, salt"), std::string::npos) << e.what();
    }
  }
  {
    Json doc = dyed_tank(false);
    for (const char* name : {"a", "b", "c"}) doc["substances"][name] = {{"diffusivity", 1e-9}};
    try {
      scene_from_json(doc);
      FAIL() << "five substances were accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("substances"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("at most 4"), std::string::npos) << e.what();
    }
  }
  {
    Json doc = dyed_tank(false);
    doc["fluids"][0]["substances"]["dye"]["concentration"] = -1;
    EXPECT_THROW(scene_from_json(doc), SceneError);
    doc["fluids"][0]["substances"]["dye"]["concentration"] = 2;
    doc["substances"]["dye"]["diffusivity"] = -1e-9;
    EXPECT_THROW(scene_from_json(doc), SceneError);
  }
}

// A substance's colour: #rrggbb, or by its place among the scene's substances; anything else names its path.
TEST(SubstanceScene, AColourIsHexOrTheSubstancesPlaceInThePalette) {
  Json doc = dyed_tank(false);  // dye and salt
  doc["substances"]["ink"] = {{"colour", "#FF8000"}};
  const Scene scene = scene_from_json(doc);
  ASSERT_EQ(scene.substances.size(), 3u);
  ASSERT_EQ(scene.substances[2].name, "ink");
  EXPECT_EQ(scene.substances[2].colour, (std::array<float, 3>{1.0f, 128.0f / 255.0f, 0.0f}));
  EXPECT_NE(scene.substances[0].colour, scene.substances[1].colour) << "the palette gives each its own";
  doc["substances"].erase("ink");
  EXPECT_EQ(scene_from_json(doc).substances[0].colour, scene.substances[0].colour);
  for (const char* bad : {"red", "#12345", "#12345g", "123456"}) {
    doc["substances"]["dye"]["colour"] = bad;
    try {
      scene_from_json(doc);
      FAIL() << "the colour '" << bad << "' was accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("substances.dye.colour"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("#rrggbb"), std::string::npos) << e.what();
    }
  }
}

// The VTU export shows each substance as its mass fraction: 2 kg/m^3 in water of 1000 kg/m^3 is 0.002.
TEST_F(SubstanceTest, TheExportCarriesEachSubstancesMassFraction) {
  const Scene scene = scene_from_json(dyed_tank(false));
  Solver s(cl(), scene, initial_state(scene));
  TempDir dir("substance-export");
  ParticleExporter out(dir.path().string());
  out.write(s.particles(), s.time());
  const std::string vtu = testing::read_file_bytes(dir.path() / "frame_000000.vtu");
  EXPECT_NE(vtu.find("Name=\"substance_dye\""), std::string::npos);
  EXPECT_NE(vtu.find("Name=\"substance_salt\""), std::string::npos);
  const HostParticles p = s.particles();
  const std::vector<double> dye = amounts(p, "dye");
  for (std::size_t i = 0; i < p.size(); ++i)
    if (dye[i] > 0) {
      EXPECT_NEAR(dye[i] / p.position[i][3], 0.002, 1e-9);
      break;
    }
}

// A tap pouring dyed water into the tank: what it pours is booked as inflow, and the account closes.
TEST_F(SubstanceTest, ATapPoursDyeAndTheBooksClose) {
  Json doc = dyed_tank(false);
  doc["emitters"] = Json::parse(R"([{"material": "water", "position": [0.03, 0.01, 0.034], "radius": 0.004,
                                      "speed": 0.5, "substances": {"dye": {"concentration": 5}}}])");
  const Scene scene = scene_from_json(doc);
  ASSERT_EQ(scene.emitters[0].substances, (std::vector<double>{5.0, 0.0}));
  Solver s(cl(), scene, initial_state(scene));
  while (s.inflow().particles < 40) s.step();
  const SubstanceBooks& b = s.substance_books();
  // Every particle poured carries 5 kg/m^3 of its volume.
  const double poured = 5.0 * 0.002 * 0.002 * 0.002 * double(s.inflow().particles);
  EXPECT_NEAR(b.inflow[0], poured, 1e-6 * poured);  // (the particles' masses are floats)
  EXPECT_EQ(b.inflow[1], 0.0);
  for (std::size_t k = 0; k < 2; ++k)
    EXPECT_LT(std::abs(b.closure(k, s.substance_totals()[k])), 1e-12 * (b.initial[k] + b.inflow[k])) << k;
}

// Water over a plate held at -30 °C, held in place: with `dissolved` in it. `salt` lowers the melting point,
// `dye` does not; neither enters ice.
Json cold_plate(const std::string& dissolved) {
  Json doc = Json::parse(R"({
    "name": "cold-plate-test", "domain": {"min": [0, 0, 0], "max": [0.008, 0.008, 0.016]}, "spacing": 0.001,
    "gravity": [0, 0, 0], "solver": {"flow": false, "max_dt": 1},
    "ambient": {"heat_transfer_coefficient": 0},
    "materials": {
      "water": {"kind": "fluid", "density": 1000, "conductivity": 0.56, "specific_heat": 4217},
      "ice": {"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050, "melts_into": "water"},
      "cold": {"kind": "solid", "density": 2500, "conductivity": 50, "specific_heat": 800}},
    "substances": {"salt": {"diffusivity": 1.5e-9, "molar_mass": 0.05844, "dissociation": 2},
                   "dye": {"diffusivity": 1e-9}},
    "solids": [{"material": "cold", "shape": "box", "box": {"min": [0, 0, 0], "max": [0.008, 0.008, 0.002]},
                "temperature": -30, "hold_temperature": true}],
    "fluids": [{"material": "water", "box": {"min": [0, 0, 0.002], "max": [0.008, 0.008, 0.016]},
                "temperature": 0.5}]
  })");
  doc["fluids"][0]["substances"][dissolved] = {{"concentration", 35.0}};
  return doc;
}

// Water that freezes gives up what does not enter ice: the dyed water the plate froze holds none of its dye,
// which went to the water above, and every kilogram is still there.
TEST_F(SubstanceTest, WaterThatFreezesGivesUpItsDye) {
  const Scene scene = scene_from_json(cold_plate("dye"));
  Solver s(cl(), scene, initial_state(scene));
  for (float d : s.melt_shifts()) ASSERT_EQ(d, 0.0f) << "dye lowers no melting point";
  const double dye = s.substance_books().initial[1];
  while (s.time() < 20.0) s.step();
  const HostParticles p = s.particles();
  const std::vector<double> q = amounts(p, "dye");
  std::size_t ice = 0;
  double in_water = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.phase[i] == std::uint8_t(Phase::Ice)) {
      ++ice;
      EXPECT_LT(q[i], 1e-6 * 35.0 * 1e-9) << "ice particle " << p.id[i] << " kept its dye";
    }
    if (p.phase[i] == std::uint8_t(Phase::Water)) in_water += q[i];
  }
  EXPECT_GT(ice, 20u) << "the cold plate froze no water";
  // The frozen particles keep the round-off of their split (about 1e-7 of what they held).
  EXPECT_GT(in_water, (1.0 - 1e-6) * dye) << "the water holds the dye";
  EXPECT_LT(std::abs(s.substance_totals()[1] - dye), 1e-12 * dye);
}

// Salt lowers the melting point: 35 g of NaCl per kg of brine (b = 0.62 mol/kg) by K_f i b = 2.31 K. Where
// the plate freezes the brine part-way, the salt stays in the liquid part, so the brine there melts lower
// still and the salt is all accounted for.
TEST_F(SubstanceTest, SaltLowersTheMeltingPointOfTheBrineItIsIn) {
  const Scene scene = scene_from_json(cold_plate("salt"));
  Solver s(cl(), scene, initial_state(scene));
  s.warm_up();
  const double b = (35.0 / 1000.0 / 0.05844) / (1.0 - 35.0 / 1000.0), expected = 1.86 * 2.0 * b;
  // (to float precision: the host reads the kernels' table, sim/kernels/liquidus.h)
  EXPECT_NEAR(melting_point_drop(scene, scene.fluids[0].material, scene.fluids[0].substances), expected,
              1e-6 * expected);
  const HostParticles p0 = s.particles();
  const std::vector<float> shift0 = s.melt_shifts(), T0 = s.temperatures();
  ASSERT_EQ(shift0.size(), p0.size());
  for (std::size_t i = 0; i < p0.size(); ++i)
    if (p0.phase[i] == std::uint8_t(Phase::Water)) {
      ASSERT_NEAR(shift0[i], expected, 1e-4 * expected);
      ASSERT_NEAR(T0[i], 0.5, 1e-3);
    }
  const double salt = s.substance_books().initial[0];
  while (s.time() < 20.0) s.step();
  EXPECT_LT(std::abs(s.substance_totals()[0] - salt), 1e-12 * salt);
  const HostParticles p = s.particles();
  const std::vector<float> shift = s.melt_shifts(), T = s.temperatures();
  float most = 0, coldest = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.phase[i] == std::uint8_t(Phase::Water) && shift[i] > most) {
      most = shift[i];
      coldest = T[i];
    }
  EXPECT_GT(most, 2.0 * expected) << "the brine the plate froze part-way did not concentrate";
  EXPECT_NEAR(coldest, -most, 1e-3) << "it sits at its own lowered melting point";
}

// Salt on dry ice at -5 °C: the salted ice melts into brine at its own liquidus, taking the heat from the
// ice around it, which cools; salt and energy are all accounted for.
TEST_F(SubstanceTest, SaltOnDryIceMeltsItIntoBrine) {
  const Scene scene = scene_from_json(testing::held_ice_cube(
      "salted-ice-test", {{"diffusivity", 1.5e-9}, {"molar_mass", 0.05844}, {"dissociation", 2}}));
  SimState st = initial_state(scene);
  // 10 µg of salt on each particle of the top layer (each is 0.92 mg of ice). Brine at about -7 °C holds 10 %
  // salt, so the layer should melt by about a tenth as it and the block cool there.
  HostParticles& p0 = st.particles;
  Float2* q = p0.column(substance_field("salt").name)->as<Float2>();
  std::size_t salted = 0;
  for (std::size_t i = 0; i < p0.size(); ++i)
    if (p0.position[i][2] > 0.007f) {
      q[i] = {1e-8f, 0.0f};
      ++salted;
    }
  ASSERT_EQ(salted, 64u);
  Solver s(cl(), scene, st);
  ASSERT_NE(s.heat_reason().find("lower the melting point"), std::string::npos) << s.heat_reason();
  const double salt = s.substance_books().initial[0];
  s.warm_up();
  while (s.time() < 30.0) s.step();
  const HostParticles p = s.particles();
  const std::vector<float> T = s.temperatures(), shift = s.melt_shifts();
  const std::vector<thermal::MaterialThermal> law = material_thermal_table(scene, 1000.0);
  double melted = 0, coldest = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double h = double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]);
    melted += liquid_fraction_at(law[p.material[i]], h, shift[i]) * double(p.position[i][3]) *
              law[p.material[i]].thermal_mass_scale;
    coldest = std::min(coldest, double(T[i]));
  }
  EXPECT_GT(melted, 0.05 * 64 * 0.917e-6) << "the salted layer did not melt";
  EXPECT_LT(coldest, -5.5) << "melting took no heat from the ice";
  EXPECT_LT(std::abs(s.substance_totals()[0] - salt), 1e-12 * salt);
  const EnergyBudget& b = s.energy_budget();
  EXPECT_LT(std::abs(s.total_enthalpy() - b.initial - b.heat_in()), 1e-6 * std::abs(b.initial));
}

// A dose dropped at a point (substance.drop) goes to the water within a kernel's reach of it, shared by the
// kernel's weight, and into the books as inflow; far from any water or ice it is refused.
TEST_F(SubstanceTest, ADroppedDoseGoesToTheWaterAroundThePointAndIntoTheBooks) {
  const Scene scene = scene_from_json(dyed_tank(false));
  Solver s(cl(), scene, initial_state(scene));
  for (int i = 0; i < 5; ++i) s.step();
  const std::vector<double> before = amounts(s.particles(), "dye");
  const Eigen::Vector3d at(0.03, 0.01, 0.006);  // in the clear layer
  const std::size_t taken = s.drop_substance(0, 1e-6, at);
  EXPECT_GT(taken, 5u);
  const HostParticles p = s.particles();
  const std::vector<double> after = amounts(p, "dye");
  double added = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double d = after[i] - before[i];
    added += d;
    const Eigen::Vector3d x(p.position[i][0], p.position[i][1], p.position[i][2]);
    if (d != 0.0) {
      EXPECT_LT((x - at).norm(), s.constants().support) << "particle " << p.id[i];
    }
  }
  EXPECT_NEAR(added, 1e-6, 1e-15);
  EXPECT_NEAR(s.substance_books().inflow[0], 1e-6, 1e-15);
  for (int i = 0; i < 20; ++i) s.step();
  const SubstanceBooks& b = s.substance_books();
  EXPECT_LT(std::abs(s.substance_totals()[0] - b.initial[0] - b.inflow[0]), 1e-12 * b.initial[0]);
  EXPECT_THROW(s.drop_substance(0, 1e-6, Eigen::Vector3d(1.0, 1.0, 1.0)), Error);
  EXPECT_THROW(s.drop_substance(0, -1e-6, at), Error);
  EXPECT_THROW(s.drop_substance(5, 1e-6, at), Error);
}

TEST_F(SubstanceTest, BrineMeltingCasePassesAtCiResolution) {
  testing::expect_case_passes(run_validation(cl(), "brine-melting", 3, {}));
}

TEST_F(SubstanceTest, BulkDiffusionCasePassesAtCiResolution) {
  testing::expect_case_passes(run_validation(cl(), "diffusion-bulk", 3, {}));
}

}  // namespace
}  // namespace thaw
