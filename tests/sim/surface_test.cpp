// The surface stage (sim/surface_stage.h): the flat-face scale of brackbill1992, the heat stage's exchange
// through the stage's areas, and the surface-area case's sphere and sheets at CI resolution.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/kernels/sph_kernel.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "sim/validation/case.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;

class SurfaceTest : public ClSuite {};

// The continuum's colour falls from 1 to 1/2 inside a flat face, so sum v |grad c| under a face is half its
// area; the lattice sums come near it (what brackbill1992 divides by).
TEST(SurfaceScale, AFlatFacesColourGradientSumsNearHalfItsArea) {
  EXPECT_NEAR(sph::flat_face_colour_gradient(sph::cubic_spline_grad_factor, 1.0, 2.0), 0.510, 0.002);
  EXPECT_NEAR(sph::flat_face_colour_gradient(sph::wendland_c2_grad_factor, 1.0, 3.0), 0.5, 0.01);
  // It scales with nothing but the ratio H / dx.
  EXPECT_NEAR(sph::flat_face_colour_gradient(sph::cubic_spline_grad_factor, 0.004, 0.008),
              sph::flat_face_colour_gradient(sph::cubic_spline_grad_factor, 1.0, 2.0), 1e-5);
  // A sheet's rim: one layer of particles sees less of the kernel than a half-space does.
  const double rim = sph::flat_edge_colour_gradient(sph::cubic_spline_grad_factor, 1.0, 2.0);
  EXPECT_GT(rim, 0.05);
  EXPECT_LT(rim, sph::flat_face_colour_gradient(sph::cubic_spline_grad_factor, 1.0, 2.0));
  EXPECT_NEAR(sph::flat_edge_colour_gradient(sph::cubic_spline_grad_factor, 0.004, 0.008), rim, 1e-5);
}

// A 4 x 2.4 x 2.4 cm block of ice at -5 °C in 25 °C air: the ambient's heat in the first step is h (T_a - T)
// times the stage's summed area times dt, and that area is the block's within the rounding of its edges.
TEST_F(SurfaceTest, AmbientHeatEntersThroughTheStagesAreas) {
  const Json base = Json::parse(R"({
    "name": "surface-test", "domain": {"min": [0, 0, 0], "max": [0.08, 0.04, 0.04]}, "spacing": 0.002,
    "solver": {"flow": false, "max_dt": 0.05},
    "ambient": {"temperature": 25, "heat_transfer_coefficient": 50},
    "materials": {
      "water": {"kind": "fluid", "density": 1000, "conductivity": 0.56, "specific_heat": 4217},
      "ice": {"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050, "melts_into": "water"}},
    "ice": [{"material": "ice", "box": {"min": [0.02, 0.008, 0.008], "max": [0.06, 0.032, 0.032]}, "temperature": -5}]
  })");
  const double faces = 2 * (0.04 * 0.024 * 2 + 0.024 * 0.024);
  double heat[2] = {0, 0};
  for (int model = 0; model < 2; ++model) {
    Json doc = base;
    doc["heat"]["exposed_area"] = model == 0 ? "brackbill1992" : "iwasaki2010";
    const Scene scene = scene_from_json(doc);
    Solver s(cl(), scene, initial_state(scene));
    s.warm_up();
    s.step();
    heat[model] = s.energy_budget().ambient;
    if (model == 0) {
      double area = 0;
      for (float a : s.surface_areas()) area += a;
      // 0.892 measured: a particle surface rounds a box's edges over about a kernel support (the surface-area
      // case's box error falls as 1 / R).
      EXPECT_NEAR(area / faces, 0.89, 0.03) << "summed area " << area << " m^2";
      EXPECT_NEAR(heat[0], 50.0 * 30.0 * area * s.dt(), 1e-4 * heat[0]);
    } else {
      EXPECT_TRUE(s.surface_areas().empty()) << "iwasaki2010 builds no surface stage";
    }
  }
  // On a box on its own lattice iwasaki2010's voxel faces are the faces themselves: the stage's rounded
  // edges take less.
  EXPECT_NEAR(heat[1] / heat[0], 1.12, 0.05);
}

// A slab of ice periodic along x and y has two faces and no edges: the wrapped walk sees no rim where the
// domain wraps, so the areas sum to 2 L^2 (both models of a flat face on its own lattice: exact to rounding).
TEST_F(SurfaceTest, APeriodicSlabHasItsTwoFacesAndNoEdges) {
  const Json doc = Json::parse(R"({
    "name": "periodic-slab", "domain": {"min": [0, 0, 0], "max": [0.02, 0.02, 0.03]}, "spacing": 0.002,
    "solver": {"flow": false, "max_dt": 0.05, "periodic": ["x", "y"]},
    "ambient": {"temperature": 25, "heat_transfer_coefficient": 50},
    "heat": {"exposed_area": "brackbill1992"},
    "materials": {
      "water": {"kind": "fluid", "density": 1000, "conductivity": 0.56, "specific_heat": 4217},
      "ice": {"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050, "melts_into": "water"}},
    "ice": [{"material": "ice", "box": {"min": [0, 0, 0], "max": [0.02, 0.02, 0.01]}, "temperature": -5}]
  })");
  const Scene scene = scene_from_json(doc);
  Solver s(cl(), scene, initial_state(scene));
  s.warm_up();
  double area = 0;
  for (float a : s.surface_areas()) area += a;
  EXPECT_NEAR(area / (2 * 0.02 * 0.02), 1.0, 1e-4);
}

// The default scene 0.09 s in: the cubes have splashed into the glass and its water is off its lattice, so
// inside it the colour gradient is noise, not surface. brackbill1992 counts only the outer layer's
// neighbourhood, projected on its normal: particles with less than 0.1 dx^2 carry a sliver of the water's
// area (1.3 % measured; 22.5 % before the gate and the projection), and the water's area stays below its
// starting top face (0.78 of it measured, the cubes floating in it; 2.25 before).
TEST_F(SurfaceTest, DisorderedWaterInsideTheGlassIsNotSurface) {
  const Scene scene = load_scene("default", {"heat.exposed_area=brackbill1992"});
  Solver s(cl(), scene, initial_state(scene));
  s.warm_up();
  const auto water_area = [&](double* small) {
    const HostParticles p = s.particles();
    const std::vector<float> a = s.surface_areas();
    const double dx2 = scene.spacing * scene.spacing;
    double sum = 0;
    *small = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (p.phase[i] != static_cast<std::uint8_t>(Phase::Water)) continue;
      sum += a[i];
      if (a[i] < 0.1 * dx2) *small += a[i];
    }
    return sum;
  };
  double small = 0;
  const double start = water_area(&small);
  while (s.time() < 0.09) s.step();
  const double now = water_area(&small);
  EXPECT_LT(small / now, 0.05) << small << " of " << now << " m^2";
  EXPECT_LT(now / start, 1.0);
  EXPECT_GT(now / start, 0.5);
}

// heat.area_interval (4 in `default`): the areas are updated at steps 0, 4, 8, ... and each particle keeps
// its own in between, whatever the sort does; a run resumed at step 6 reads the areas of step 4 from its
// state and goes on bit for bit.
TEST_F(SurfaceTest, AreasAreUpdatedEveryIntervalAndAResumedRunGoesOnBitwise) {
  const Scene scene = load_scene("default", {});
  ASSERT_EQ(scene.heat.exposed_area, ExposedArea::Brackbill1992);
  ASSERT_EQ(scene.heat.area_interval, 4);
  testing::TempDir dir("surface-interval");
  Solver straight(cl(), scene, initial_state(scene));
  straight.warm_up();
  const auto areas_by_id = [&] {
    const HostParticles p = straight.particles();
    const std::vector<float> a = straight.surface_areas();
    std::vector<float> out(a.size(), 0.0f);
    for (std::size_t i = 0; i < a.size(); ++i) out.at(p.id[i]) = a[i];
    return out;
  };
  straight.step();  // step 0: updated
  const std::vector<float> first = areas_by_id();
  for (int i = 0; i < 3; ++i) straight.step();  // steps 1-3: kept
  EXPECT_TRUE(areas_by_id() == first);
  straight.step();  // step 4: updated where the particles are now
  EXPECT_FALSE(areas_by_id() == first);
  straight.step();
  write_state_file(dir / "mid.state", straight.state());
  for (int i = 0; i < 6; ++i) straight.step();
  const std::string expected = testing::state_file_bytes(straight.state(), dir, "straight.state");
  Solver resumed(cl(), scene, read_state_file(dir / "mid.state"));
  resumed.warm_up();
  while (resumed.steps() < straight.steps()) resumed.step();
  EXPECT_TRUE(testing::state_file_bytes(resumed.state(), dir, "resumed.state") == expected);
}

TEST_F(SurfaceTest, TheSurfaceAreaCasesSphereAndSheetsHoldAtResolution20) {
  const CaseResult r = run_validation(cl(), "surface-area", 20, {});
  for (const auto& [key, m] : r.metrics) {
    if (key == "sphere_area" || key == "sphere_spread" || key == "sheet1_area" || key == "sheet1_spread" ||
        key == "sheet2_spread") {
      EXPECT_TRUE(m.passed()) << key << " " << m.value << " error " << m.error;
    }
    // A sheet one particle thick: 2 dx^2 a particle for both faces, and its rim (4 L dx of 2 L^2 + 4 L dx)
    // from the colour gradient along it (-0.1 % measured; 40 / 42 without the rim).
    if (key == "sheet1_area") {
      EXPECT_NEAR(m.value, 1.0, 0.005);
    }
  }
}

// The melting sphere with its meltwater drained, over the first half spacing of melt (res 10): the stage's
// area carries the air's heat within 5 % (3.4 % measured), Iwasaki's neighbour count half again too much.
TEST_F(SurfaceTest, AnIceSphereInWarmAirMeltsAtTheRateItsAreaSets) {
  double error[2] = {0, 0};
  const char* models[2] = {"model=brackbill1992", "model=iwasaki2010"};
  for (int k = 0; k < 2; ++k) {
    const CaseResult r = run_validation(cl(), "ambient-sphere", 10, {models[k], "radius_loss=0.05"});
    for (const auto& [key, m] : r.metrics)
      if (key == "melted_mass") error[k] = (m.value - m.reference) / m.reference;
  }
  EXPECT_LT(std::abs(error[0]), 0.05) << "brackbill1992";
  EXPECT_GT(error[1], 0.3) << "iwasaki2010";
}

// The case drains the meltwater by hand between solvers; the areas its state carried were the old surface's,
// and held particles keep a state's areas for the whole run, so the uncovered ice took no heat and the melt
// stalled (-38.6 % at a 20 % loss of radius, res 10). With them dropped it is the rough sphere's +4.8 %.
TEST_F(SurfaceTest, AnIceSphereKeepsMeltingAsItsMeltwaterIsDrained) {
  const CaseResult r = run_validation(cl(), "ambient-sphere", 10, {"radius_loss=0.2"});
  ASSERT_FALSE(r.metrics.empty());
  const MetricResult& m = r.metrics.front().second;
  ASSERT_EQ(r.metrics.front().first, "melted_mass");
  EXPECT_LT(std::abs(m.value - m.reference) / m.reference, 0.06) << m.value << " against " << m.reference;
}

}  // namespace
}  // namespace thaw
