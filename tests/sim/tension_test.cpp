// The tension stage (sim/tension_stage.h): its calibration from sigma and the contact angles, that it is
// built only when a scene asks for it, that its pair forces move no momentum, and that tension pulls a long
// block of water round with WCSPH and with DFSPH while without it the block keeps its shape.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <numbers>

#include "sim/error.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "sim/substance_stage.h"
#include "sim/tension_stage.h"
#include "sim/validation/case.h"
#include "sim/validation/substance_cases.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;

class TensionTest : public ClSuite {};

// A block of water 2 cm long and 1 cm across without gravity, at 1 mm; `tension` is the scene's block.
Json block_scene(const Json& tension, const std::string& pressure = "wcsph") {
  Json doc = Json::parse(R"({
    "name": "tension-test", "domain": {"min": [-0.02, -0.02, -0.02], "max": [0.02, 0.02, 0.02]},
    "gravity": [0, 0, 0], "spacing": 0.001, "heat": {"enabled": false},
    "solver": {"reference_speed": 0.2, "max_dt": 2e-4},
    "materials": {"water": {"kind": "fluid", "density": 1000, "viscosity": 0.0018, "conductivity": 0.56,
                            "specific_heat": 4200}},
    "fluids": [{"material": "water", "box": {"min": [-0.005, -0.005, -0.01], "max": [0.005, 0.005, 0.01]}}]
  })");
  doc["tension"] = tension;
  doc["solver"]["pressure"] = pressure;
  return doc;
}

// mean (z^2 - (x^2 + y^2) / 2) about the centre of mass: 0 for a sphere, positive for a block long in z.
double elongation(const HostParticles& p) {
  double c[3] = {0, 0, 0};
  for (const auto& x : p.position)
    for (int a = 0; a < 3; ++a) c[a] += x[a];
  for (double& v : c) v /= double(p.size());
  double q = 0;
  for (const auto& x : p.position) {
    const double dx = x[0] - c[0], dy = x[1] - c[1], dz = x[2] - c[2];
    q += dz * dz - 0.5 * (dx * dx + dy * dy);
  }
  return q / double(p.size());
}

TEST(TensionCalibration, FollowsKirkwoodBuffAndYoungDupre) {
  Json doc = block_scene({{"model", "iwasaki2010"}, {"coefficient", 0.07}});
  doc["materials"]["steel"] = {
      {"kind", "solid"}, {"density", 7800}, {"conductivity", 16}, {"specific_heat", 500}};
  doc["materials"]["ice"] = {{"kind", "ice"},
                             {"density", 917},
                             {"conductivity", 2.22},
                             {"specific_heat", 2050},
                             {"melts_into", "water"}};
  doc["solids"] = {{{"shape", "box"},
                    {"material", "steel"},
                    {"box", {{"min", {-0.02, -0.02, -0.02}}, {"max", {0.02, 0.02, -0.018}}}}}};
  auto coefficients = [&](const Json& d) {
    const Scene s = scene_from_json(d);
    return std::pair{s, tension_coefficients(s, derive_constants(s))};
  };
  auto index = [](const Scene& s, const std::string& name) {
    for (std::size_t m = 0; m < s.materials.size(); ++m)
      if (s.materials[m].name == name) return m;
    return s.materials.size();
  };
  // Iwasaki's k / r between particles of number density n = 1 / dx^3: sigma = pi n^2 k H^4 / 32.
  const auto [scene, c] = coefficients(doc);
  const double n = 1e9, H = 0.002, pi = std::numbers::pi;
  EXPECT_NEAR(c.cohesion, 32 * 0.07 / (pi * n * n * std::pow(H, 4)), 1e-6 * c.cohesion);
  // The water against a solid: W = sigma (1 + cos theta) = pi n^2 k_s H^4 / 16, at the defaults 90° (steel)
  // and 12° (ice); fluids have none.
  EXPECT_NEAR(c.adhesion[index(scene, "steel")], 16 * 0.07 / (pi * n * n * std::pow(H, 4)),
              1e-5 * c.cohesion);
  EXPECT_NEAR(c.adhesion[index(scene, "ice")] / c.adhesion[index(scene, "steel")],
              1 + std::cos(12 * pi / 180), 1e-5);
  EXPECT_EQ(c.adhesion[index(scene, "water")], 0.0f);
  // No adhesion at 180°.
  Json dry = doc;
  dry["tension"]["solid_contact_angle"] = 180;
  EXPECT_NEAR(coefficients(dry).second.adhesion[index(scene, "steel")], 0.0f, 1e-6 * c.cohesion);
  // Akinci's gamma: sigma = (pi / 8) rho0^2 gamma int r^4 C, with C scaling as 1 / H^3: gamma goes as
  // sigma / H^2 and is the same for adhesion at the same angle whatever the resolution in H units.
  Json a = doc;
  a["tension"]["model"] = "akinci2013";
  const TensionCoefficients fine = coefficients(a).second;
  a["spacing"] = 0.002;
  a["tension"]["coefficient"] = 0.14;
  const TensionCoefficients coarse = coefficients(a).second;
  EXPECT_NEAR(coarse.cohesion / fine.cohesion, 2.0 / 4.0, 1e-6);
  EXPECT_GT(fine.adhesion[index(scene, "steel")], 0.0f);
}

TEST_F(TensionTest, TheStageIsBuiltOnlyWhenTheSceneHasTension) {
  auto stages = [&](const Json& doc) {
    const Scene scene = scene_from_json(doc);
    Solver s(cl(), scene, initial_state(scene));
    std::string all;
    for (const std::string& x : s.stages()) all += x + ",";
    return all;
  };
  EXPECT_EQ(stages(block_scene({{"model", "none"}})).find("tension"), std::string::npos);
  EXPECT_NE(stages(block_scene({{"model", "akinci2013"}})).find("tension (akinci2013)"), std::string::npos);
  EXPECT_NE(stages(block_scene({{"model", "iwasaki2010"}}, "dfsph")).find("tension (iwasaki2010)"),
            std::string::npos);
  EXPECT_NE(stages(block_scene({{"model", "brackbill1992"}})).find("tension (brackbill1992)"),
            std::string::npos);
  // Without flow nothing moves: no tension pass.
  Json still = block_scene({{"model", "akinci2013"}});
  still["solver"]["flow"] = false;
  still["heat"]["enabled"] = true;
  still["fluids"][0]["temperature"] = 30;
  EXPECT_EQ(stages(still).find("tension"), std::string::npos);
}

// Pairwise and antisymmetric between particles of one mass: the water's total momentum stays at its start
// (0) while the block pulls itself in.
TEST_F(TensionTest, ThePairForcesMoveNoMomentum) {
  for (const char* model : {"akinci2013", "iwasaki2010"}) {
    const Scene scene = scene_from_json(block_scene({{"model", model}}, "dfsph"));
    Solver s(cl(), scene, initial_state(scene));
    for (int k = 0; k < 60; ++k) s.step();
    const HostParticles p = s.particles();
    double momentum[3] = {0, 0, 0}, scale = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double m = p.position[i][3];
      for (int a = 0; a < 3; ++a) momentum[a] += m * p.velocity[i][a];
      scale += m * std::sqrt(p.velocity[i][0] * p.velocity[i][0] + p.velocity[i][1] * p.velocity[i][1] +
                             p.velocity[i][2] * p.velocity[i][2]);
    }
    ASSERT_GT(scale, 0) << model << ": the tension moved nothing";
    EXPECT_LT(std::hypot(momentum[0], momentum[1], momentum[2]) / scale, 1e-4) << model;
  }
}

// A block twice as long as it is wide, without gravity: tension pulls it towards a sphere (its elongation
// falls by more than half in 0.1 s, about a capillary time) with either pressure solver, and without
// tension it keeps its shape.
TEST_F(TensionTest, TensionPullsALongBlockRound) {
  for (const char* pressure : {"wcsph", "dfsph"})
    for (const char* model : {"none", "akinci2013", "brackbill1992"}) {
      const Scene scene = scene_from_json(block_scene({{"model", model}}, pressure));
      SimState st = initial_state(scene);
      const double start = elongation(st.particles);
      ASSERT_GT(start, 0);
      Solver s(cl(), scene, st);
      while (s.time() < 0.1) s.step();
      const double end = elongation(s.particles());
      if (std::string(model) == "none")
        EXPECT_NEAR(end / start, 1.0, 0.05) << pressure;
      else
        EXPECT_LT(end / start, 0.5) << pressure;
    }
}

// brackbill1992's fits walk 5 x 5 x 5 cells at H = 2 spacings: a periodic axis shorter than that is refused
// by name, and one long enough is taken.
TEST(TensionScene, TheSurfaceFitNeedsRoomAroundAPeriodicAxis) {
  Json doc = block_scene({{"model", "brackbill1992"}});
  doc["solver"]["periodic"] = {"y"};
  doc["domain"] = Json::parse(R"({"min": [-0.02, -0.004, -0.02], "max": [0.02, 0.004, 0.02]})");
  doc["fluids"][0]["box"] = Json::parse(R"({"min": [-0.005, -0.004, -0.01], "max": [0.005, 0.004, 0.01]})");
  try {
    scene_from_json(doc);
    ADD_FAILURE() << "an 8 mm periodic axis (4 supports) was taken";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "tension.model");
    EXPECT_NE(std::string(e.what()).find("0.01 m"), std::string::npos) << e.what();
  }
  doc["domain"]["min"][1] = -0.005;
  doc["domain"]["max"][1] = 0.005;
  EXPECT_NO_THROW(scene_from_json(doc));
  doc["tension"]["model"] = "akinci2013";
  doc["domain"]["min"][1] = -0.004;
  doc["domain"]["max"][1] = 0.004;
  EXPECT_NO_THROW(scene_from_json(doc));
}

// brackbill1992 on a still drop of R = 8 spacings cut from the lattice: the first step's velocities are the
// tension's alone (the pressure is clamped at zero, and nothing moves yet), and their pull towards the centre
// adds up to Laplace's jump times the area, 2 sigma / R * 4 pi R^2, R from the drop's volume N dx^3.
TEST_F(TensionTest, TheSurfaceForceOnAStillDropAddsUpToLaplaces) {
  Json doc = block_scene({{"model", "brackbill1992"}});
  doc["fluids"] = Json::parse(R"([{"material": "water", "shape": "sphere", "centre": [0, 0, 0],
                                   "radius": 0.008}])");
  doc["domain"] = Json::parse(R"({"min": [-0.012, -0.012, -0.012], "max": [0.012, 0.012, 0.012]})");
  doc["solver"]["max_dt"] = 1e-6;
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  s.step();
  const double dt = s.time();
  const HostParticles p = s.particles();
  double inward = 0, net[3] = {0, 0, 0};
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto& x = p.position[i];  // moved by 1e-6 s of the pull only
    const double r = std::hypot(x[0], x[1], x[2]), m = x[3];
    for (int a = 0; a < 3; ++a) net[a] += m * p.velocity[i][a] / dt;
    if (r > 0)
      inward -= m * (p.velocity[i][0] * x[0] + p.velocity[i][1] * x[1] + p.velocity[i][2] * x[2]) / (r * dt);
  }
  const double R = std::cbrt(3.0 * double(p.size()) / (4.0 * std::numbers::pi)) * 0.001;
  const double laplace = 2.0 * 0.0756 / R * 4.0 * std::numbers::pi * R * R;
  EXPECT_NEAR(inward / laplace, 1.0, 0.1);
  EXPECT_LT(std::hypot(net[0], net[1], net[2]) / laplace, 0.01);
}

Json detergent(double tension_scale, const std::string& law) { return still_detergent(law, tension_scale); }

// Szyszkowski's law with E = sigma0 / (2 ln 2) at half coverage halves the tension: the drop's pull towards
// its centre over the second step falls by half of Laplace's (the first step is the same in both runs, so
// everything but the tension cancels in the difference).
TEST_F(TensionTest, ADetergentLowersTheLaplacePullBySzyszkowskisLaw) {
  Json doc = block_scene({{"model", "brackbill1992"}});
  doc["fluids"] = Json::parse(R"([{"material": "water", "shape": "sphere", "centre": [0, 0, 0],
                                   "radius": 0.008}])");
  doc["domain"] = Json::parse(R"({"min": [-0.012, -0.012, -0.012], "max": [0.012, 0.012, 0.012]})");
  doc["solver"]["max_dt"] = 1e-6;
  const double sigma0 = 0.0756, E = sigma0 / (2.0 * std::log(2.0));
  doc["substances"] = detergent(0.0, "szyszkowski");
  const Scene plain = scene_from_json(doc);
  doc["substances"] = detergent(E, "szyszkowski");
  const Scene lowered = scene_from_json(doc);
  const SimState st = with_surface_coverage(cl(), plain, 0.5, [](double, double, double) { return 1.0; });
  const auto fp = second_step_forces(cl(), plain, st), fl = second_step_forces(cl(), lowered, st);
  double less = 0;  // how much weaker the pull towards the centre is
  for (const auto& [id, l] : fl) {
    const double r = l.x.norm();
    if (r > 0) less += (l.f - fp.at(id).f).dot(l.x) / r;
  }
  const double R = std::cbrt(3.0 * double(fl.size()) / (4.0 * std::numbers::pi)) * 0.001;
  const double laplace = 2.0 * sigma0 / R * 4.0 * std::numbers::pi * R * R;
  std::printf("[ info ] the pull fell by %.4g N against half of Laplace's %.4g N\n", less, 0.5 * laplace);
  EXPECT_NEAR(less / (0.5 * laplace), 1.0, 0.12);
}

// Marangoni's stress (sim/validation/marangoni.cpp): the force's first mode along a layer whose surface holds
// a detergent at theta (1 + eps sin k y), against L int dsigma/dy cos(k y) dy from the law, with each law.
TEST_F(TensionTest, MarangoniCasePassesAtCiResolutionWithEachLaw) {
  testing::expect_case_passes(run_validation(cl(), "marangoni", 12, {}));
  testing::expect_case_passes(run_validation(cl(), "marangoni", 12, {"law=szyszkowski", "coverage=0.6"}));
}

// The pair models scale a pair's cohesion by the mean of its two tensions, so a detergent spread unevenly
// over the block (Gamma rising along z) lowers the tension where it sits and still moves no momentum.
TEST_F(TensionTest, PairForcesUnderAnUnevenDetergentMoveNoMomentum) {
  for (const char* model : {"akinci2013", "iwasaki2010"}) {
    Json doc = block_scene({{"model", model}}, "dfsph");
    doc["substances"] = detergent(0.03, "szyszkowski");
    const Scene scene = scene_from_json(doc);
    const SimState st =
        with_surface_coverage(cl(), scene, 0.45, [](double, double, double z) { return 1.0 + 80.0 * z; });
    Solver s(cl(), scene, st);
    for (int k = 0; k < 60; ++k) s.step();
    const HostParticles p = s.particles();
    const float* ratio = p.column(kTensionRatioField)->as<float>();
    double momentum[3] = {0, 0, 0}, scale = 0, lowest = 1;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double m = p.position[i][3];
      lowest = std::min(lowest, double(ratio[i]));
      for (int a = 0; a < 3; ++a) momentum[a] += m * p.velocity[i][a];
      scale += m * std::sqrt(p.velocity[i][0] * p.velocity[i][0] + p.velocity[i][1] * p.velocity[i][1] +
                             p.velocity[i][2] * p.velocity[i][2]);
    }
    ASSERT_GT(scale, 0) << model << ": the tension moved nothing";
    EXPECT_LT(lowest, 0.9) << model << ": the detergent lowered no particle's tension";
    EXPECT_LT(std::hypot(momentum[0], momentum[1], momentum[2]) / scale, 1e-4) << model;
  }
}

// Szyszkowski's and the linear law are written in Gamma / Gamma_max: with tension on, a detergent without a
// capacity is refused at its law's path; without tension, or with the law off, it is taken.
TEST(TensionScene, ATensionLawNeedsASurfaceCapacity) {
  Json doc = block_scene({{"model", "brackbill1992"}});
  doc["substances"] = detergent(0.01, "linear");
  doc["substances"]["soap"]["surface_capacity"] = 0.0;
  try {
    scene_from_json(doc);
    ADD_FAILURE() << "a tension law without a capacity was taken";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "substances.soap.tension_law");
  }
  doc["substances"]["soap"]["tension_law"] = "none";
  EXPECT_NO_THROW(scene_from_json(doc));
  doc["substances"]["soap"]["tension_law"] = "linear";
  doc["tension"]["model"] = "none";
  EXPECT_NO_THROW(scene_from_json(doc));
  doc["substances"]["soap"]["tension_law"] = "langmuir";
  EXPECT_THROW(scene_from_json(doc), SceneError);
}

// The tension ratios are saved: a run resumed mid-way with a detergent lowering the tension goes on bit for
// bit (the first step's tension pass reads the ratios the straight run's last step left).
TEST_F(TensionTest, ARunWithALoweredTensionResumesBitwise) {
  Json doc = block_scene({{"model", "brackbill1992"}});
  doc["substances"] = detergent(0.03, "szyszkowski");
  doc["substances"]["soap"]["adsorption_rate"] = 1e-4;
  doc["substances"]["soap"]["desorption_rate"] = 1.0;
  const Scene scene = scene_from_json(doc);
  const SimState start =
      with_surface_coverage(cl(), scene, 0.4, [](double, double, double z) { return 1.0 + 60.0 * z; });
  EXPECT_TRUE(testing::resumes_bitwise(cl(), scene, start, 12, 10, "tension-resume"));
}

}  // namespace
}  // namespace thaw
