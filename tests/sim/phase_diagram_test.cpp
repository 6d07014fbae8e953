// Salt's phase diagram with water (issue 44; sim/kernels/liquidus.h, docs/SUBSTANCES.md): the measured NaCl
// liquidus through its points to the eutectic, Blagden's dilute law kept by name, solubility that leaves the
// rest undissolved, scenes that start past solubility refused at their path, the brine cases at several
// concentrations (one past the eutectic's) and the freezing-through case, and salt dropped on ice that never
// makes a melt colder than the eutectic or a brine stronger than water dissolves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "render/snapshot.h"
#include "sim/error.h"
#include "sim/metrics.h"
#include "sim/solver.h"
#include "sim/thermal.h"
#include "sim/validation/case.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;

// A scene with one substance "salt" of the given entry, for its liquidus.
Scene salt_scene(const Json& salt) {
  Json doc = Json::parse(R"({
    "name": "liquidus-test", "domain": {"min": [0, 0, 0], "max": [0.008, 0.008, 0.008]}, "spacing": 0.001,
    "materials": {"water": {"kind": "fluid", "density": 1000, "conductivity": 0.56, "specific_heat": 4217}},
    "fluids": [{"material": "water", "box": {"min": [0, 0, 0], "max": [0.008, 0.008, 0.004]}}]
  })");
  doc["substances"]["salt"] = salt;
  return scene_from_json(doc);
}

// The drop of a melt of 1 kg holding w kg of the scene's first substance.
double drop_at(const Scene& s, double w, double melt = 1.0) {
  const std::vector<thermal::Liquidus> table = liquidus_table(s);
  const double q[4] = {w, 0, 0, 0};
  return thermal::liquidus_drop(table.data(), 4, q, melt, 1.86);
}

TEST(Liquidus, TheMeasuredNaClTableGoesThroughItsPoints) {
  const Scene s = salt_scene({{"liquidus", "crc_nacl"}});
  for (const auto& [w, d] : kCrcNaCl) EXPECT_NEAR(drop_at(s, w), d, 1e-5 * d) << "at " << w;
  EXPECT_DOUBLE_EQ(s.substances[0].solubility, kCrcNaClSolubility);
  EXPECT_NEAR(s.substances[0].eutectic_depression(), 21.1, 1e-12);
}

TEST(Liquidus, RisesToTheEutecticAndStaysThere) {
  const Scene s = salt_scene({{"liquidus", "crc_nacl"}});
  double before = 0;
  for (int k = 1; k <= 400; ++k) {
    const double w = 0.3 * k / 400.0, d = drop_at(s, w);
    if (w <= 0.233) {
      EXPECT_GT(d, before) << "at " << w;
    } else {
      EXPECT_NEAR(d, 21.1, 1e-5) << "past the eutectic at " << w;
    }
    before = d;
  }
}

// Blagden's law, kept by name: K_f i b with b the molality, capped at 40 K; it overestimates NaCl's measured
// depression at 10 % (7.07 K against 6.56).
TEST(Liquidus, BlagdenIsTheDiluteLaw) {
  const Scene s = salt_scene({{"molar_mass", 0.05844}, {"dissociation", 2}});
  EXPECT_EQ(s.substances[0].liquidus, LiquidusLaw::Blagden);
  for (double w : {0.01, 0.035, 0.1}) {
    const double b = (w / 0.05844) / (1.0 - w);
    EXPECT_NEAR(drop_at(s, w), 1.86 * 2.0 * b, 1e-5 * b);
  }
  EXPECT_GT(drop_at(s, 0.1), 7.0);
  EXPECT_NEAR(drop_at(s, 0.9), kMaxMeltingPointDrop, 1e-6);
}

// A melt dissolves up to the solubility, the rest staying undissolved; a melt of nothing is at the eutectic.
TEST(Liquidus, AMeltDissolvesUpToItsSolubility) {
  const Scene s = salt_scene({{"liquidus", "crc_nacl"}});
  const std::vector<thermal::Liquidus> t = liquidus_table(s);
  EXPECT_NEAR(thermal::liquidus_dissolved(&t[0], 0.5, 1.0), 0.263, 1e-7);
  EXPECT_NEAR(thermal::liquidus_dissolved(&t[0], 0.1, 1.0), 0.1, 1e-12);
  EXPECT_EQ(thermal::liquidus_dissolved(&t[0], 0.1, 0.0), 0.0);
  EXPECT_NEAR(drop_at(s, 0.5), 21.1, 1e-5);
  EXPECT_NEAR(drop_at(s, 1e-3, 0.0), 21.1, 1e-5);
  // A dye lowers nothing and dissolves whatever it is given.
  const Scene dye = salt_scene(Json::object());
  EXPECT_EQ(drop_at(dye, 0.2), 0.0);
}

TEST(SubstanceScene, SaltPastWhatWaterDissolvesIsRefusedAtItsPath) {
  Json doc = Json::parse(R"({
    "name": "solubility-test", "domain": {"min": [0, 0, 0], "max": [0.008, 0.008, 0.008]}, "spacing": 0.001,
    "materials": {"water": {"kind": "fluid", "density": 1000, "conductivity": 0.56, "specific_heat": 4217}},
    "substances": {"salt": {"liquidus": "crc_nacl"}},
    "fluids": [{"material": "water", "box": {"min": [0, 0, 0], "max": [0.008, 0.008, 0.004]},
                "substances": {"salt": {"concentration": 300}}}]
  })");
  try {
    scene_from_json(doc);
    FAIL() << "300 g/L of NaCl was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "fluids[0].substances.salt.concentration");
    EXPECT_NE(std::string(e.what()).find("263"), std::string::npos) << e.what();
  }
  doc["fluids"][0]["substances"]["salt"]["concentration"] = 260;
  EXPECT_NO_THROW(scene_from_json(doc));
  // With no solubility, still no more than the fluid's own mass.
  Json heavy = doc;
  heavy["substances"]["grease"] = Json::object();
  heavy["fluids"][0]["substances"] = {{"grease", {{"concentration", 1000}}}};
  try {
    scene_from_json(heavy);
    FAIL() << "1000 kg/m^3 of grease in water of 1000 kg/m^3 was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "fluids[0].substances");
  }
  // A table must rise in both.
  doc["fluids"][0]["substances"]["salt"]["concentration"] = 10;
  doc["substances"]["salt"] = {
      {"liquidus", "table"},
      {"liquidus_table",
       {{{"mass_fraction", 0.1}, {"depression", 6}}, {{"mass_fraction", 0.2}, {"depression", 5}}}}};
  try {
    scene_from_json(doc);
    FAIL() << "a falling liquidus was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "substances.salt.liquidus_table[1]");
  }
  doc["substances"]["salt"]["liquidus_table"][1]["depression"] = 14;
  const Scene s = scene_from_json(doc);
  EXPECT_NEAR(s.substances[0].eutectic_depression(), 14.0, 1e-12);
  doc["substances"]["salt"].erase("liquidus_table");
  EXPECT_THROW(scene_from_json(doc), SceneError);
}

class PhaseDiagramTest : public ClSuite {};

// The column settles on the measured liquidus at several salinities: dilute, strong, and 25 %, past the
// eutectic's 23.3 % (its ice melts at the eutectic at first, and its meltwater brings it back under); and on
// Blagden's, by name.
TEST_F(PhaseDiagramTest, BrineMeltingPassesAtSeveralConcentrations) {
  // 5 % brine freezes at -3.05 °C: it starts at -2.
  testing::expect_case_passes(run_validation(cl(), "brine-melting", 3, {"salinity=0.05", "temperature=-2"}));
  for (double salinity : {0.2, 0.25})
    testing::expect_case_passes(
        run_validation(cl(), "brine-melting", 3, {"salinity=" + std::to_string(salinity)}));
  testing::expect_case_passes(run_validation(cl(), "brine-melting", 3, {"liquidus=blagden"}));
}

// With less of the cold ice (12 mm at -100 °C under 6 mm of 10 % brine) the column ends at the eutectic, part
// frozen through there: the solid by the lever rule at T_e.
TEST_F(PhaseDiagramTest, BrineAtItsEutecticFreezesByTheLeverRule) {
  testing::expect_case_passes(run_validation(cl(), "brine-freezing", 6, {"ice_height=0.012"}));
}

TEST_F(PhaseDiagramTest, BrineFreezingCasePassesAtCiResolution) {
  testing::expect_case_passes(run_validation(cl(), "brine-freezing", 6, {}));
}

// Salt dropped on dry ice at -5 °C, three times what the ice's melt can dissolve: ice and salt make a
// freezing mixture that cools towards the eutectic, never below it; a dose more than the ice within a
// kernel's reach can hold spreads farther, no particle holding more than its mass; no melt holds more than
// NaCl's solubility and the view shows none stronger; the rest is reported undissolved; salt and energy
// close; a dose more than the particles it lands on can hold is refused, saying how much they take.
TEST_F(PhaseDiagramTest, SaltOnIceStaysWithinItsPhaseDiagram) {
  const Scene scene = scene_from_json(
      testing::held_ice_cube("salt-on-ice-test", {{"diffusivity", 1.5e-7}, {"liquidus", "crc_nacl"}}));
  Solver s(cl(), scene, initial_state(scene));
  s.warm_up();
  const Eigen::Vector3d at(0.004, 0.004, 0.0075);
  for (int k = 0; k < 3; ++k) s.drop_substance(0, 5e-6, at);
  // 60 mg is more than the ice within a kernel's reach can hold (0.92 mg a particle): it spreads farther.
  {
    auto salt_of = [](const HostParticles& p) {
      std::vector<double> out;
      const Float2* q = p.column(substance_field("salt").name)->as<Float2>();
      for (std::size_t i = 0; i < p.size(); ++i) out.push_back(double(q[i][0]) + double(q[i][1]));
      return out;
    };
    const std::vector<double> before = salt_of(s.particles());
    s.drop_substance(0, 6e-5, at);
    const HostParticles p = s.particles();
    const std::vector<double> after = salt_of(p);
    double farthest = 0, added = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (after[i] == before[i]) continue;
      added += after[i] - before[i];
      farthest = std::max(
          farthest, (Eigen::Vector3d(p.position[i][0], p.position[i][1], p.position[i][2]) - at).norm());
      EXPECT_LE(after[i], 0.917e-6 * (1 + 1e-6))
          << "particle " << p.id[i] << " holds more salt than its mass";
    }
    EXPECT_NEAR(added, 6e-5, 1e-15);
    EXPECT_GT(farthest, s.constants().support) << "the dose stayed within one kernel's reach";
  }
  EXPECT_THROW(
      {
        try {
          s.drop_substance(0, 18.3, at);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("at most"), std::string::npos) << e.what();
          throw;
        }
      },
      Error);
  const double Te = -21.1, wsat = kCrcNaClSolubility;
  const std::vector<thermal::MaterialThermal> law = material_thermal_table(scene, 1000.0);
  double coldest = 0, undissolved_first = -1;
  for (int look = 0; look < 20; ++look) {
    for (int k = 0; k < 50; ++k) s.step();
    const HostParticles p = s.particles();
    const std::vector<float> T = s.temperatures(), shift = s.melt_shifts();
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double h = double(p.enthalpy[i][0]) + double(p.enthalpy[i][1]);
      if (liquid_fraction_at(law[p.material[i]], h, shift[i]) > 0) coldest = std::min(coldest, double(T[i]));
      ASSERT_GE(T[i], Te - 1e-3) << "particle " << p.id[i] << " colder than NaCl's eutectic, look " << look;
    }
    const Json books = substances_json(s)["salt"];
    ASSERT_TRUE(books.contains("undissolved")) << books.dump();
    EXPECT_LE(books["most_mass_fraction"].get<double>(), wsat * (1 + 1e-6));
    EXPECT_GE(books["undissolved"].get<double>(), 0.0);
    if (undissolved_first < 0) undissolved_first = books["undissolved"].get<double>();
    const RenderSnapshot snap = make_snapshot(p, T, scene, s.time(), s.steps());
    ASSERT_EQ(snap.substances.size(), 1u);
    for (float c : snap.substances[0].second) ASSERT_LE(c, wsat * 1000.0 * (1 + 1e-6));
  }
  EXPECT_GT(undissolved_first, 0.0) << "15 mg on a few mg of ice's melt should not all dissolve";
  EXPECT_LT(coldest, -10.0) << "ice and salt did not cool as a freezing mixture";
  const SubstanceBooks& b = s.substance_books();
  EXPECT_LT(std::abs(s.substance_totals()[0] - b.initial[0] - b.inflow[0]), 1e-9 * b.inflow[0]);
  const EnergyBudget& e = s.energy_budget();
  EXPECT_LT(std::abs(s.total_enthalpy() - e.initial - e.heat_in()), 1e-6 * std::abs(e.initial));
}

}  // namespace
}  // namespace thaw
