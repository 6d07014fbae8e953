// Heat and phase change: energy accounting, the sources, runtime controls, stress, scene errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim/error.h"
#include "sim/kernels/dryer_model.h"
#include "sim/metrics.h"
#include "sim/solver.h"
#include "sim/thermal.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;

// Materials of the validation cases (docs/VALIDATION-RESULTS.md): ice 917 kg/m^3, water 1000, and steel.
Json materials() {
  return Json::parse(R"({
    "water": {"kind": "fluid", "density": 1000, "viscosity": 1e-3, "conductivity": 0.56, "specific_heat": 4217},
    "ice": {"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050, "melts_into": "water"},
    "steel": {"kind": "solid", "density": 7850, "conductivity": 45, "specific_heat": 490}
  })");
}

Json box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return {{"min", {x0, y0, z0}}, {"max", {x1, y1, z1}}};
}

// A 4 cm box of space at 5 mm spacing with no air exchange: what happens inside stays inside.
Json isolated_scene() {
  return {{"name", "heat-test"},
          {"domain", box(0, 0, 0, 0.08, 0.04, 0.04)},
          {"spacing", 0.004},
          {"solver", {{"flow", false}, {"max_dt", 100.0}}},
          {"ambient", {{"heat_transfer_coefficient", 0.0}}},
          {"materials", materials()}};
}

double closure_relative(const Solver& s) {
  const Metrics m = measure(s);
  return std::abs(m.closure()) / m.enthalpy_scale;
}

class HeatTest : public ClSuite {};

// Two pairs far apart: cold ice freezes a thin layer of water at 1 °C; hot water melts a small cube of
// ice at 0 °C. The total enthalpy is conserved to round-off while particles change phase both ways.
TEST_F(HeatTest, EnergyIsConservedThroughPhaseChangeBothWays) {
  Json doc = isolated_scene();
  doc["ice"] = {
      {{"material", "ice"}, {"box", box(0, 0, 0, 0.024, 0.04, 0.04)}, {"temperature", -60}},
      {{"material", "ice"}, {"box", box(0.064, 0.012, 0.012, 0.072, 0.028, 0.028)}, {"temperature", 0}}};
  doc["fluids"] = {{{"material", "water"}, {"box", box(0.024, 0, 0, 0.032, 0.04, 0.04)}, {"temperature", 1}},
                   {{"material", "water"}, {"box", box(0.048, 0, 0, 0.08, 0.04, 0.04)}, {"temperature", 80}}};
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  auto ice_in = [&](double x0, double x1) {
    const HostParticles p = s.particles();
    int n = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.phase[i] == static_cast<std::uint8_t>(Phase::Ice) && p.position[i][0] > x0 &&
          p.position[i][0] < x1)
        ++n;
    return n;
  };
  const int frozen0 = ice_in(0, 0.04), melting0 = ice_in(0.04, 0.08);
  const double e0 = s.total_enthalpy();
  EXPECT_EQ(e0, s.energy_budget().initial);
  for (int k = 0; k < 400; ++k) s.step();
  EXPECT_GT(ice_in(0, 0.04), frozen0) << "water next to the cold ice froze";
  EXPECT_LT(ice_in(0.04, 0.08), melting0) << "ice in the hot water melted";
  EXPECT_EQ(s.energy_budget().heat_in(), 0.0);
  EXPECT_LT(closure_relative(s), 1e-6) << "closure " << measure(s).closure() << " J";
  const Metrics m = measure(s), m0 = measure(initial_state(scene).particles, scene, 1000.0);
  EXPECT_GT(m0.ice_mass, 0.0);
  EXPECT_NEAR(m.water_mass + m.ice_mass, m0.water_mass + m0.ice_mass, 1e-6 * (m0.water_mass + m0.ice_mass))
      << "phase change keeps each particle's mass";
}

Json warm_block_scene() {
  Json doc = isolated_scene();
  doc["ice"] = {
      {{"material", "ice"}, {"box", box(0.02, 0.008, 0.008, 0.06, 0.032, 0.032)}, {"temperature", -5}}};
  doc["solver"]["max_dt"] = 0.05;
  return doc;
}

TEST_F(HeatTest, AmbientAirWarmsTheExposedSurfaceOnly) {
  Json doc = warm_block_scene();
  doc["ambient"] = {{"temperature", 25}, {"heat_transfer_coefficient", 50}};
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  s.step();
  // After one step only particles with an exposed face have warmed.
  const HostParticles p = s.particles();
  const auto T = s.temperatures();
  int warmed = 0, interior_warmed = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool inner = p.position[i][0] > 0.025 && p.position[i][0] < 0.055 && p.position[i][1] > 0.013 &&
                       p.position[i][1] < 0.027 && p.position[i][2] > 0.013 && p.position[i][2] < 0.027;
    if (T[i] > -5.0f + 1e-4f) ++(inner ? interior_warmed : warmed);
  }
  EXPECT_GT(warmed, 0);
  EXPECT_EQ(interior_warmed, 0);
  for (int k = 0; k < 50; ++k) s.step();
  EXPECT_GT(s.energy_budget().ambient, 0.0);
  EXPECT_LT(closure_relative(s), 1e-6);
}

TEST_F(HeatTest, DryerSwitchedOffAddsNothingAndSwitchedOnHeats) {
  Json doc = warm_block_scene();
  doc["dryers"] = {{{"on", false},
                    {"position", {0.04, 0.02, 0.039}},
                    {"direction", {0, 0, -1}},
                    {"temperature", 80},
                    {"speed", 15},
                    {"half_angle", 30}}};
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  for (int k = 0; k < 20; ++k) s.step();
  EXPECT_EQ(s.energy_budget().dryers, 0.0);
  Dryer d = s.dryers().at(0);
  d.on = true;
  s.set_dryer(0, d);
  for (int k = 0; k < 20; ++k) s.step();
  EXPECT_GT(s.energy_budget().dryers, 0.0);
  EXPECT_LT(closure_relative(s), 1e-6);
  // Aimed away, nothing is in its cone.
  d.direction = {0, 0, 1};
  s.set_dryer(0, d);
  const double before = s.energy_budget().dryers;
  for (int k = 0; k < 5; ++k) s.step();
  EXPECT_EQ(s.energy_budget().dryers, before);
}

TEST_F(HeatTest, DryerControlsAreCheckedLikeTheScene) {
  Json doc = warm_block_scene();
  doc["dryers"] = {{{"position", {0.04, 0.02, 0.039}}, {"direction", {0, 0, -1}}}};
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  Dryer d = s.dryers().at(0);
  d.half_angle = 75;
  try {
    s.set_dryer(0, d);
    FAIL() << "a half-angle of 75 degrees was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "dryers[0].half_angle");
  }
  d = s.dryers().at(0);
  d.direction = {0, 0, 0};
  EXPECT_THROW(s.set_dryer(0, d), SceneError);
  EXPECT_THROW(s.set_dryer(3, d), Error);
}

Json lamp_scene(const Eigen::Vector3d& normal) {
  Json doc = warm_block_scene();
  doc["lamps"] = {{{"centre", {0.04, 0.02, 0.038}},
                   {"normal", {normal.x(), normal.y(), normal.z()}},
                   {"width", 0.02},
                   {"height", 0.02},
                   {"temperature", 500},
                   {"emissivity", 0.9},
                   {"photons", 20000}}};
  return doc;
}

TEST_F(HeatTest, LampPhotonEnergyCloses) {
  const Scene scene = scene_from_json(lamp_scene({0, 0, -1}));
  Solver s(cl(), scene, initial_state(scene));
  for (int k = 0; k < 10; ++k) s.step();
  const EnergyBudget& b = s.energy_budget();
  EXPECT_GT(b.lamps, 0.0);
  EXPECT_GT(b.lamp_escaped, 0.0);  // the emitter is larger than the view it has of the block's top
  // Emitted = absorbed + escaped; absorbed is summed per particle in float.
  EXPECT_NEAR(b.lamp_emitted, b.lamps + b.lamp_escaped, 1e-5 * b.lamp_emitted);
  // Emitted is eps sigma T^4 A over the steps' time.
  const double expected = 0.9 * 5.670374419e-8 * std::pow(773.15, 4) * 0.02 * 0.02 * s.time();
  EXPECT_NEAR(b.lamp_emitted, expected, 1e-5 * expected);
  EXPECT_LT(closure_relative(s), 1e-6);
}

TEST_F(HeatTest, LampPointedAwayHeatsNothing) {
  const Scene scene = scene_from_json(lamp_scene({0, 0, 1}));
  Solver s(cl(), scene, initial_state(scene));
  for (int k = 0; k < 10; ++k) s.step();
  EXPECT_EQ(s.energy_budget().lamps, 0.0);
  EXPECT_GT(s.energy_budget().lamp_emitted, 0.0);
  EXPECT_EQ(s.energy_budget().lamp_escaped, s.energy_budget().lamp_emitted);
}

TEST_F(HeatTest, LampSwitchedOffEmitsNothingAndCanBeTurnedAround) {
  const Scene scene = scene_from_json(lamp_scene({0, 0, -1}));
  Solver s(cl(), scene, initial_state(scene));
  Lamp lamp = s.lamps().at(0);
  lamp.on = false;
  s.set_lamp(0, lamp);
  for (int k = 0; k < 5; ++k) s.step();
  EXPECT_EQ(s.energy_budget().lamp_emitted, 0.0);
  EXPECT_EQ(s.energy_budget().lamps, 0.0);
  lamp.on = true;
  lamp.normal = {0, 0, 1};  // facing away from the ice
  s.set_lamp(0, lamp);
  for (int k = 0; k < 5; ++k) s.step();
  EXPECT_GT(s.energy_budget().lamp_emitted, 0.0);
  EXPECT_EQ(s.energy_budget().lamps, 0.0);
  lamp.normal = {0, 0, -2};  // back towards it; need not be unit length
  s.set_lamp(0, lamp);
  for (int k = 0; k < 5; ++k) s.step();
  EXPECT_GT(s.energy_budget().lamps, 0.0);
  lamp.emissivity = 1.5;
  EXPECT_THROW(s.set_lamp(0, lamp), SceneError);
}

TEST_F(HeatTest, HeldSolidAndTankWallsAccountTheirHeat) {
  Json doc = warm_block_scene();
  doc["domain"]["walls"] = {"-z"};
  doc["domain"]["wall_material"] = "steel";
  doc["domain"]["wall_heat"] = {{"coefficient", 200}, {"temperature", 10}};
  doc["solids"] = {{{"shape", "box"},
                    {"material", "steel"},
                    {"box", box(0.0, 0.0, 0.0, 0.02, 0.04, 0.012)},
                    {"temperature", 60},
                    {"hold_temperature", true}}};
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  for (int k = 0; k < 30; ++k) s.step();
  EXPECT_GT(s.energy_budget().held, 0.0);
  // The walls start at the outside's 10 °C; the plate warms the floor, which then loses heat outside.
  EXPECT_LT(s.energy_budget().walls, 0.0);
  EXPECT_LT(closure_relative(s), 1e-6);
}

// Stress: very cold ice, a 500 °C lamp and a dryer at its limits in a flowing scene stay finite and
// keep the books closed.
TEST_F(HeatTest, ExtremeSourcesStayFiniteAndAccounted) {
  Json doc = lamp_scene({0, 0, -1});
  doc["solver"] = {{"max_dt", 1e-3}};
  doc["domain"]["walls"] = {"-x", "+x", "-y", "+y", "-z"};
  doc["domain"]["wall_material"] = "steel";
  doc["ice"][0]["temperature"] = -100;
  doc["fluids"] = {
      {{"material", "water"}, {"box", box(0.0, 0.0, 0.0, 0.016, 0.04, 0.02)}, {"temperature", 99}}};
  doc["heat"] = {{"time_scale", 1000}};
  doc["dryers"] = {{{"position", {0.04, 0.02, 0.039}},
                    {"direction", {0, 0, -1}},
                    {"temperature", 500},
                    {"speed", 100},
                    {"half_angle", 60},
                    {"reach", 10}}};
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  for (int k = 0; k < 300; ++k) s.step();
  const Metrics m = measure(s);
  EXPECT_TRUE(std::isfinite(m.max_temperature));
  EXPECT_LE(m.max_temperature, 500.0 + 1e-3) << "nothing outruns its hottest source";
  EXPECT_GE(m.min_temperature, -100.0 - 1e-3);
  EXPECT_LT(closure_relative(s), 1e-5);
}

// The time step respects the heat limits: a faster heat clock shortens it.
TEST_F(HeatTest, TimeStepRespectsTheDiffusionLimit) {
  Json doc = warm_block_scene();
  doc["solver"]["max_dt"] = 3600.0;
  // Air warmer than the block, so heat is built at all (an isothermal block builds none: plan_heat);
  // its exchange limit (0.5 rho c dx / 6 h = 63 s) is far above the diffusion limit tested here.
  doc["ambient"] = {{"temperature", 25}, {"heat_transfer_coefficient", 10}};
  const Scene slow = scene_from_json(doc);
  doc["heat"] = {{"time_scale", 10}};
  const Scene fast = scene_from_json(doc);
  Solver a(cl(), slow, initial_state(slow)), b(cl(), fast, initial_state(fast));
  a.step();
  b.step();
  const double alpha = 2.22 / (917.0 * 2050.0), h = 0.004;
  EXPECT_LE(a.dt(), 0.1 * h * h / alpha * (1 + 1e-6));
  EXPECT_NEAR(b.dt(), a.dt() / 10, 1e-6 * a.dt());
}

bool has_stage(const Solver& s, const std::string& prefix) {
  for (const std::string& stage : s.stages())
    if (stage.starts_with(prefix)) return true;
  return false;
}

// A block of water falling in a box, everything at 20 °C in 20 °C air: nothing can heat or cool it.
Json isothermal_flow_scene() {
  Json doc = isolated_scene();
  doc["solver"] = {{"max_dt", 1e-3}};
  doc["domain"]["walls"] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  doc["domain"]["wall_material"] = "steel";
  doc["fluids"] = {{{"material", "water"}, {"box", box(0, 0, 0, 0.04, 0.04, 0.02)}, {"temperature", 20}}};
  doc["ambient"] = {{"temperature", 20}, {"heat_transfer_coefficient", 10}};
  return doc;
}

TEST_F(HeatTest, AnIsothermalSceneBuildsNoHeatStageAndKeepsItsEnthalpy) {
  const Scene scene = scene_from_json(isothermal_flow_scene());
  Solver s(cl(), scene, initial_state(scene));
  EXPECT_FALSE(has_stage(s, "heat"));
  EXPECT_NE(s.heat_reason().find("no heat"), std::string::npos) << s.heat_reason();
  const HostParticles before = s.particles();
  for (int k = 0; k < 20; ++k) s.step();
  // The particles were sorted and moved; each keeps the enthalpy it started with, by id.
  const HostParticles after = s.particles();
  std::vector<Float2> start(before.size());
  for (std::size_t i = 0; i < before.size(); ++i) start[before.id[i]] = before.enthalpy[i];
  for (std::size_t i = 0; i < after.size(); ++i) ASSERT_EQ(after.enthalpy[i], start[after.id[i]]) << i;
  for (float T : s.temperatures()) ASSERT_NEAR(T, 20.0f, 1e-4f);
  // Summed in another order after the sort: equal to double rounding.
  EXPECT_NEAR(s.total_enthalpy(), s.energy_budget().initial, 1e-12 * std::abs(s.energy_budget().initial));
  EXPECT_LT(closure_relative(s), 1e-12);
  // The state file carries the enthalpy and the budget as a heated run's does.
  const SimState st = s.state();
  EXPECT_EQ(st.particles.enthalpy, after.enthalpy);
  EXPECT_EQ(EnergyBudget::from_vector(st.energy_budget).initial, s.energy_budget().initial);
}

TEST_F(HeatTest, HeatIsBuiltForWhatCanChangeATemperature) {
  Json warm_air = isothermal_flow_scene();
  warm_air["ambient"]["temperature"] = 25;
  Json no_air = isothermal_flow_scene();  // the air exchanges nothing
  no_air["ambient"]["heat_transfer_coefficient"] = 0;
  Json warm_water = isothermal_flow_scene();
  warm_water["fluids"][0]["temperature"] = 30;
  Json heat_off = warm_water;
  heat_off["heat"] = {{"enabled", false}};
  Json dryer_off = isothermal_flow_scene();
  dryer_off["dryers"] = {{{"position", {0.02, 0.02, 0.06}}, {"direction", {0, 0, -1}}, {"on", false}}};
  Json lamp_off = isothermal_flow_scene();
  lamp_off["lamps"] = {{{"centre", {0.02, 0.02, 0.038}},
                        {"normal", {0, 0, -1}},
                        {"width", 0.02},
                        {"height", 0.02},
                        {"temperature", 500},
                        {"on", false}}};
  const std::vector<std::pair<Json, bool>> cases = {{warm_air, true},  {no_air, false},   {warm_water, true},
                                                    {heat_off, false}, {dryer_off, true}, {lamp_off, true}};
  for (const auto& [doc, heat] : cases) {
    const Scene scene = scene_from_json(doc);
    Solver s(cl(), scene, initial_state(scene));
    EXPECT_EQ(has_stage(s, "heat"), heat) << doc.dump() << ": " << s.heat_reason();
    s.step();
  }
  // Lamps that are all off build no photon grid until one is switched on.
  const Scene scene = scene_from_json(lamp_off);
  Solver s(cl(), scene, initial_state(scene));
  const auto tracing = [&s] {
    const std::vector<std::string> st = s.stages();
    return std::find(st.begin(), st.end(), "photons") != st.end();
  };
  EXPECT_FALSE(tracing());
  EXPECT_TRUE(has_stage(s, "photons (when a lamp is on)"));
  s.step();
  EXPECT_EQ(s.energy_budget().lamp_emitted, 0.0);
  Lamp lamp = s.lamps().at(0);
  lamp.on = true;
  s.set_lamp(0, lamp);
  EXPECT_TRUE(tracing());
  for (int k = 0; k < 3; ++k) s.step();
  EXPECT_GT(s.energy_budget().lamp_emitted, 0.0);
  EXPECT_LT(closure_relative(s), 1e-6);
}

TEST(DryerModel, ConeSpeedDistanceAndAngle) {
  dryer::DryerJet j{0,
                    0,
                    0,
                    0,
                    0,
                    -1,
                    static_cast<float>(20 * M_PI / 180),
                    0.5f,
                    60.0f,
                    10.0f,
                    0.04f,
                    dryer::dryer_coefficient(0.04f)};
  const auto on_axis = dryer::dryer_air(j, 0, 0, -0.1f, 20.0f);
  EXPECT_GT(on_axis.x, 0.0f);
  EXPECT_GT(on_axis.y, 20.0f);
  EXPECT_LE(on_axis.y, 60.0f);
  EXPECT_LT(dryer::dryer_air(j, 0, 0, -0.3f, 20.0f).x, on_axis.x) << "falls off with distance";
  EXPECT_LT(dryer::dryer_air(j, 0.02f, 0, -0.1f, 20.0f).x, on_axis.x) << "falls off with angle";
  EXPECT_EQ(dryer::dryer_air(j, 0.1f, 0, -0.1f, 20.0f).x, 0.0f) << "outside the cone";
  EXPECT_EQ(dryer::dryer_air(j, 0, 0, 0.1f, 20.0f).x, 0.0f) << "behind the nozzle";
  EXPECT_EQ(dryer::dryer_air(j, 0, 0, -0.6f, 20.0f).x, 0.0f) << "beyond its reach";
  dryer::DryerJet faster = j;
  faster.speed = 20.0f;
  EXPECT_GT(dryer::dryer_air(faster, 0, 0, -0.1f, 20.0f).x, on_axis.x) << "grows with air speed";
  dryer::DryerJet off = j;
  off.speed = 0.0f;
  EXPECT_EQ(dryer::dryer_air(off, 0, 0, -0.1f, 20.0f).x, 0.0f);
}

TEST(ThermalLaw, EnthalpyAndTemperatureInvertAcrossTheMeltingPoint) {
  Json doc = isolated_scene();
  doc["ice"] = {{{"material", "ice"}, {"box", box(0, 0, 0, 0.01, 0.01, 0.01)}}};
  const Scene scene = scene_from_json(doc);
  const auto table = material_thermal_table(scene, 1000);
  const int water = 0, ice = 1;
  for (double T : {-40.0, -1.0, 0.0})
    EXPECT_NEAR(temperature_at(table[ice], enthalpy_at(scene, ice, T)), T, 1e-9);
  for (double T : {0.0, 1.0, 90.0})
    EXPECT_NEAR(temperature_at(table[water], enthalpy_at(scene, water, T)), T, 1e-9);
  // The pair shares one reference: water at 0 °C holds exactly the latent heat more than ice at 0 °C.
  EXPECT_DOUBLE_EQ(enthalpy_at(scene, water, 0.0) - enthalpy_at(scene, ice, 0.0), 334000.0);
  EXPECT_DOUBLE_EQ(liquid_fraction_at(table[ice], 167000.0), 0.5);
  EXPECT_EQ(temperature_at(table[ice], 167000.0), 0.0);
}

// ---- scene errors ------------------------------------------------------------------------------

std::string error_path(Json doc) { return testing::scene_error_path(std::move(doc)); }

TEST(HeatScene, ErrorsNameTheirPath) {
  Json base = isolated_scene();
  base["ice"] = {{{"material", "ice"}, {"box", box(0, 0, 0, 0.01, 0.01, 0.01)}}};
  Json doc = base;
  doc["materials"]["ice"]["conductivity"] = -1;
  EXPECT_EQ(error_path(doc), "materials.ice.conductivity");
  doc = base;
  doc["ice"][0]["material"] = "snow";
  EXPECT_EQ(error_path(doc), "ice[0].material");
  doc = base;
  doc["ice"][0]["material"] = "water";
  EXPECT_EQ(error_path(doc), "ice[0].material");
  doc = base;
  doc["materials"]["ice"]["melts_into"] = "steel";
  EXPECT_EQ(error_path(doc), "materials.ice.melts_into");
  doc = base;
  doc["materials"]["steel"]["melts_into"] = "water";
  EXPECT_EQ(error_path(doc), "materials.steel.melts_into");
  doc = base;
  doc["ice"][0]["temperature"] = 5;
  EXPECT_EQ(error_path(doc), "ice[0].temperature");
  doc = base;
  doc["materials"]["water"].erase("specific_heat");
  EXPECT_EQ(error_path(doc), "materials.water.specific_heat");
  doc = base;
  doc["solver"]["flow"] = true;
  doc["solver"]["periodic"] = {"x"};  // flowing particles wrap along y and z only
  EXPECT_EQ(error_path(doc), "solver.periodic");
  doc = base;
  doc["domain"]["wall_heat"] = {{"coefficient", 10}};
  EXPECT_EQ(error_path(doc), "domain.wall_heat.coefficient");
  doc = base;
  doc["dryers"] = {{{"position", {0, 0, 0}}, {"direction", {0, 0, 0}}}};
  EXPECT_EQ(error_path(doc), "dryers[0].direction");
  doc = base;
  doc["lamps"] = {
      {{"centre", {0, 0, 0}}, {"normal", {0, 0, 1}}, {"width", 0.1}, {"height", 0.1}, {"temperature", -300}}};
  EXPECT_EQ(error_path(doc), "lamps[0].temperature");
  doc = base;
  doc["heat"] = {{"time_scale", 0}};
  EXPECT_EQ(error_path(doc), "heat.time_scale");
}

}  // namespace
}  // namespace thaw
