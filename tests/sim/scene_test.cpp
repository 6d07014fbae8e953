#include "sim/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "sim/error.h"
#include "sim/geometry/voxelize.h"
#include "sim/solver.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = THAW_SOURCE_DIR;

Json base_scene() {
  return Json::parse(R"({
    "name": "test",
    "domain": {"min": [0, 0, 0], "max": [0.4, 0.2, 0.3], "walls": ["-x", "+x", "-z"], "wall_material": "glass"},
    "spacing": 0.01,
    "materials": {
      "water": {"kind": "fluid", "density": 1000, "viscosity": 1e-3, "conductivity": 0.56, "specific_heat": 4217},
      "glass": {"kind": "solid", "density": 2500, "conductivity": 1.0, "specific_heat": 840}
    },
    "fluids": [
      {"material": "water", "box": {"min": [0, 0, 0], "max": [0.1, 0.1, 0.1]}},
      {"material": "water", "box": {"min": [0.2, 0, 0], "max": [0.3, 0.1, 0.1]}, "velocity": [1, 0, 0]}
    ],
    "solids": [
      {"shape": "box", "material": "glass", "box": {"min": [0.15, 0, 0], "max": [0.18, 0.2, 0.05]}},
      {"shape": "plane", "material": "glass", "point": [0, 0, 0], "normal": [0, 0, 2]}
    ]
  })");
}

// The SceneError a broken scene gives; fails the test when it loads.
SceneError scene_error(Json doc, const std::vector<std::string>& overrides = {}) {
  try {
    scene_from_json(std::move(doc), overrides);
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "scene loaded without error";
  return SceneError("", "no error");
}

// The SceneError one `--set` assignment gives on the base scene.
SceneError override_error(const std::string& assignment) { return scene_error(base_scene(), {assignment}); }

std::string message(const std::exception& e) { return e.what(); }

fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p;
}

// Writes `text` to a temporary scene file named `name`, loads it and returns the error's message (a failure
// when it loads), with the file's path in `path`.
std::string file_error(const std::string& name, const std::string& text, std::string& path) {
  const fs::path p = write_temp(name, text);
  path = p.string();
  std::string error;
  try {
    load_scene(path);
    ADD_FAILURE() << name << " loaded without error";
  } catch (const Error& e) {
    error = e.what();
  }
  fs::remove(p);
  return error;
}

// ---- shipped scenes --------------------------------------------------------------------------------

// The shipped scenes, and the benchmark scenes that docs/ tells users to run (bench/scenes/).
TEST(Scene, EveryShippedConfigLoads) {
  int count = 0;
  for (const char* dir : {"configs", "bench/scenes"})
    for (const auto& entry : fs::directory_iterator(kSource / dir)) {
      if (entry.path().extension() != ".json") continue;
      SCOPED_TRACE(entry.path().string());
      EXPECT_NO_THROW({
        const Scene s = load_scene(entry.path().string());
        EXPECT_FALSE(s.name.empty());
        EXPECT_FALSE(s.fluids.empty() && s.ice.empty() && !s.has_air());
      });
      ++count;
    }
  EXPECT_GE(count, 5);
}

TEST(Scene, DefaultSceneResolvesByName) {
  const Scene s = load_scene("default");
  EXPECT_EQ(s.name, "default");
  // The default is a melt: water, ice and a hair dryer aimed at the ice.
  ASSERT_EQ(s.fluids.size(), 1u);
  EXPECT_FALSE(s.ice.empty());
  ASSERT_EQ(s.dryers.size(), 1u);
  EXPECT_TRUE(s.dryers[0].on);
  EXPECT_LT(s.dryers[0].direction.z(), 0.0);
  EXPECT_TRUE(s.heat.enabled);
  EXPECT_NO_THROW(load_scene("dam-break.json"));
  EXPECT_NO_THROW(load_scene((kSource / "configs" / "water-drop.json").string()));
}

TEST(Scene, DocumentedExampleLoads) {
  const Scene s = scene_from_json(Json::parse(scene_example_json()));
  EXPECT_EQ(s.solver.kernel, KernelFunction::WendlandC2);
}

TEST(Scene, DocsAreGeneratedFromTheSchema) {
  const fs::path doc = kSource / "docs" / "SCENES.md";
  const std::string generated = scene_reference_markdown();
  const char* update = std::getenv("THAW_UPDATE_DOCS");
  if (update != nullptr && std::string(update) == "1") {
    std::ofstream(doc, std::ios::binary) << generated;
  }
  std::ifstream in(doc, std::ios::binary);
  std::stringstream current;
  current << in.rdbuf();
  EXPECT_EQ(current.str(), generated)
      << doc.string()
      << " is out of date with the scene schema; regenerate it with\n"
         "  THAW_UPDATE_DOCS=1 ./thaw_tests --gtest_filter=Scene.DocsAreGeneratedFromTheSchema";
}

// ---- conversion and defaults -----------------------------------------------------------------------

TEST(Scene, DefaultsAreFilledIn) {
  const Scene s = scene_from_json(base_scene());
  EXPECT_EQ(s.solver.cfl, 0.4);
  EXPECT_EQ(s.solver.kernel, KernelFunction::CubicSpline);
  EXPECT_EQ(s.wall_layers, 0);
  EXPECT_EQ(s.solver.boundary_volume, BoundaryVolume::Lattice);
  EXPECT_EQ(s.gravity, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_EQ(s.wall_layers, 0);
  EXPECT_EQ(s.fluids[0].velocity, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(s.source["solver"]["cfl"], 0.4);
  EXPECT_EQ(s.source["description"], "");
  EXPECT_EQ(s.source["materials"]["glass"]["viscosity"], 0.0);
}

TEST(Scene, ConvertsEveryField) {
  const Scene s = scene_from_json(base_scene());
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].name, "water");  // document order
  EXPECT_EQ(s.materials[1].kind, MaterialKind::Solid);
  EXPECT_EQ(s.materials[1].density, 2500.0);
  EXPECT_EQ(s.wall_material, 1);
  EXPECT_EQ(s.walls, (std::vector<std::string>{"-x", "+x", "-z"}));
  EXPECT_EQ(s.fluids[1].material, 0);
  EXPECT_EQ(s.fluids[1].velocity, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(s.fluids[1].box.min, Eigen::Vector3d(0.2, 0, 0));
  ASSERT_EQ(s.solids.size(), 2u);
  EXPECT_FALSE(s.solids[0].plane);
  EXPECT_TRUE(s.solids[0].shape.axis_aligned_box());
  EXPECT_EQ(s.solids[0].box.max, Eigen::Vector3d(0.18, 0.2, 0.05));
  EXPECT_TRUE(s.solids[1].plane);
  EXPECT_EQ(s.solids[1].normal, Eigen::Vector3d(0, 0, 1));  // normalised
  EXPECT_EQ(s.domain.max, Eigen::Vector3d(0.4, 0.2, 0.3));
}

// A fluid body may be any shape ice can be: a sphere of water (a drop) holds its volume in particles, a
// box written without a shape is still a box, and a sphere without a radius is refused at its path.
TEST(Scene, FluidBodiesTakeShapes) {
  Json doc = base_scene();
  doc["fluids"][1] = {
      {"material", "water"}, {"shape", "sphere"}, {"centre", {0.3, 0.1, 0.15}}, {"radius", 0.05}};
  const Scene scene = scene_from_json(doc);
  ASSERT_EQ(scene.fluids.size(), 2u);
  EXPECT_TRUE(scene.fluids[0].shape.axis_aligned_box());
  const HostParticles p = initial_state(scene).particles;
  std::size_t drop = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.phase[i] == std::uint8_t(Phase::Water) && p.position[i][0] > 0.24) ++drop;
  // 552 lattice points at R = 5 spacings: the sphere's volume within the lattice's rounding.
  EXPECT_NEAR(double(drop) * 1e-6, 4.0 / 3.0 * M_PI * 0.05 * 0.05 * 0.05, 0.08 * 5.24e-4);
  doc["fluids"][1].erase("radius");
  EXPECT_EQ(scene_error(doc).path(), "fluids[1].radius");
}

TEST(Scene, NoWallsNeedNoWallMaterial) {
  Json doc = base_scene();
  doc["domain"].erase("wall_material");
  doc["domain"]["walls"] = Json::array();
  EXPECT_EQ(scene_from_json(doc).wall_material, -1);
}

// Walls stand on the lattice from the domain's lower corner: an axis walled on its upper side must span a
// whole number of spacings (else that wall stands off its face and water runs into the gap). Others need not.
TEST(Scene, WalledExtentMustBeAWholeNumberOfSpacings) {
  const SceneError e = scene_error(base_scene(), {"domain.max=[0.405,0.2,0.3]"});
  EXPECT_EQ(e.path(), "domain.max");
  EXPECT_NE(message(e).find("the extent along x, 0.405 m, is 40.5 spacings of 0.01 m"), std::string::npos)
      << e.what();
  EXPECT_NE(message(e).find("set its x to 0.4 or 0.41"), std::string::npos) << e.what();
  EXPECT_EQ(scene_error(base_scene(), {"spacing=0.003"}).path(), "domain.max");    // 0.4 m is 133.3 spacings
  EXPECT_NO_THROW(scene_from_json(base_scene(), {"domain.max=[0.4,0.205,0.3]"}));  // y has no wall
  EXPECT_NO_THROW(scene_from_json(base_scene(), {"domain.max=[0.4,0.2,0.305]"}));  // -z only: open top
}

TEST(Scene, WholeNumberAcceptedAsInteger) {
  const Scene s = scene_from_json(base_scene(), {"domain.wall_layers=4.0"});
  EXPECT_EQ(s.wall_layers, 4);
  EXPECT_TRUE(s.source["domain"]["wall_layers"].is_number_integer());
}

// ---- overrides -----------------------------------------------------------------------------------------

TEST(SceneOverride, SetsNumbersArraysAndBareStrings) {
  const Scene s = scene_from_json(
      base_scene(), {"solver.cfl=0.3", "fluids[0].box.max=[0.05, 0.05, 0.05]", "fluids.1.velocity=[0,0,-1]",
                     "gravity[2]=-1.62", "solver.kernel=wendland_c2", "solver.support_ratio=3"});
  EXPECT_EQ(s.solver.cfl, 0.3);
  EXPECT_EQ(s.fluids[0].box.max, Eigen::Vector3d(0.05, 0.05, 0.05));
  EXPECT_EQ(s.fluids[1].velocity, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(s.gravity.z(), -1.62);
  EXPECT_EQ(s.solver.kernel, KernelFunction::WendlandC2);
}

TEST(SceneOverride, CreatesMissingSectionsThenValidates) {
  Json doc = base_scene();
  doc.erase("solids");
  const Scene s = scene_from_json(doc, {"solver.max_dt=0.002"});
  EXPECT_EQ(s.solver.max_dt, 0.002);
}

TEST(SceneOverride, UnknownPathIsReportedAtItsPath) {
  const SceneError e = override_error("nope.x=1");
  EXPECT_EQ(e.path(), "nope");
  EXPECT_NE(message(e).find("unknown key"), std::string::npos) << e.what();
  EXPECT_EQ(override_error("solver.cfll=0.3").path(), "solver.cfll");
}

TEST(SceneOverride, IndexPastTheEnd) {
  const SceneError e = override_error("fluids[5].box.max=[1,1,1]");
  EXPECT_EQ(e.path(), "fluids[5]");
  EXPECT_NE(message(e).find("past the end"), std::string::npos) << e.what();
  // Its own type, which the service answers as not_found; other path errors stay plain SceneErrors.
  Json doc = base_scene();
  EXPECT_THROW(apply_override(doc, "fluids[5].box.max=[1,1,1]"), IndexPastEndError);
  try {
    apply_override(doc, "spacing[0]=1");
    ADD_FAILURE() << "indexing into a number was accepted";
  } catch (const IndexPastEndError&) {
    ADD_FAILURE() << "indexing into a number is not an index past the end";
  } catch (const SceneError&) {
  }
}

TEST(SceneOverride, IndexIntoAScalar) {
  const SceneError e = override_error("spacing.x=1");
  EXPECT_EQ(e.path(), "spacing");
  EXPECT_NE(message(e).find("is a number"), std::string::npos) << e.what();
  EXPECT_EQ(override_error("solver[0]=1").path(), "solver");
}

TEST(SceneOverride, MissingEqualsIsAnError) {
  Json doc = base_scene();
  try {
    apply_override(doc, "solver.cfl");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(message(e).find("PATH=VALUE"), std::string::npos) << e.what();
  }
}

TEST(SceneOverride, BadPathSyntax) {
  for (const char* path : {"solver..cfl=1", "fluids[x]=1", "fluids[0=1", "[0]=1", "solver.=1"}) {
    EXPECT_THROW(scene_from_json(base_scene(), {path}), SceneError) << path;
  }
}

TEST(SceneOverride, HugeNumberIsOutOfRange) {
  const SceneError e = override_error("spacing=1e400");
  EXPECT_EQ(e.path(), "spacing");
  EXPECT_NE(message(e).find("out of range"), std::string::npos) << e.what();
}

// ---- errors with paths -------------------------------------------------------------------------------

TEST(SceneError, UnknownTopLevelKeySuggestsTheClosest) {
  Json doc = base_scene();
  doc["spacng"] = 0.01;
  const SceneError e = scene_error(doc);
  EXPECT_EQ(e.path(), "spacng");
  EXPECT_NE(message(e).find("did you mean 'spacing'?"), std::string::npos) << e.what();
  EXPECT_NE(message(e).find("allowed keys: name, description, domain"), std::string::npos) << e.what();
}

TEST(SceneError, UnknownNestedKeys) {
  Json doc = base_scene();
  doc["solver"] = {{"cfll", 0.3}};
  SceneError e = scene_error(doc);
  EXPECT_EQ(e.path(), "solver.cfll");
  EXPECT_NE(message(e).find("did you mean 'cfl'?"), std::string::npos) << e.what();

  doc = base_scene();
  doc["fluids"][0]["bx"] = doc["fluids"][0]["box"];
  doc["fluids"][0].erase("box");
  e = scene_error(doc);
  EXPECT_EQ(e.path(), "fluids[0].bx");
  EXPECT_NE(message(e).find("did you mean 'box'?"), std::string::npos) << e.what();
}

TEST(SceneError, NoSuggestionForAFarOffKey) {
  const SceneError e = override_error("solver.zebra=1");
  EXPECT_EQ(message(e).find("did you mean"), std::string::npos) << e.what();
}

TEST(SceneError, WrongType) {
  const SceneError e = override_error("spacing=abc");
  EXPECT_EQ(e.path(), "spacing");
  EXPECT_NE(message(e).find("expected number, got string \"abc\""), std::string::npos) << e.what();
  EXPECT_EQ(override_error("gravity=[0, 0]").path(), "gravity");
  EXPECT_EQ(override_error("gravity=[0, \"a\", 0]").path(), "gravity[1]");
  EXPECT_EQ(override_error("materials=[]").path(), "materials");
  EXPECT_EQ(override_error("domain.wall_layers=2.5").path(), "domain.wall_layers");
}

TEST(SceneError, NegativeSpacing) {
  const SceneError e = override_error("spacing=-0.01");
  EXPECT_EQ(e.path(), "spacing");
  EXPECT_NE(message(e).find("-0.01 m is out of range: must be > 0 m"), std::string::npos) << e.what();
}

TEST(SceneError, CflOutOfRange) {
  const SceneError e = override_error("solver.cfl=1.5");
  EXPECT_EQ(e.path(), "solver.cfl");
  EXPECT_NE(message(e).find("1.5 is out of range: must be in (0, 1]"), std::string::npos) << e.what();
  EXPECT_EQ(override_error("solver.cfl=0").path(), "solver.cfl");
  EXPECT_NO_THROW(scene_from_json(base_scene(), {"solver.cfl=1"}));
}

TEST(SceneError, NonFiniteNumber) {
  Json doc = base_scene();
  doc["spacing"] = std::nan("");
  SceneError e = scene_error(doc);
  EXPECT_EQ(e.path(), "spacing");
  EXPECT_NE(message(e).find("finite"), std::string::npos) << e.what();
  doc = base_scene();
  doc["gravity"] = {0.0, 0.0, INFINITY};
  EXPECT_EQ(scene_error(doc).path(), "gravity[2]");
}

TEST(SceneError, MissingRequiredKey) {
  Json doc = base_scene();
  doc.erase("spacing");
  EXPECT_EQ(scene_error(doc).path(), "spacing");
  doc = base_scene();
  doc["domain"].erase("max");
  EXPECT_EQ(scene_error(doc).path(), "domain.max");
  doc = base_scene();
  doc.erase("domain");
  EXPECT_EQ(scene_error(doc).path(), "domain");
}

TEST(SceneError, EmptyArraysAndBadNames) {
  EXPECT_EQ(override_error("fluids=[]").path(), "fluids");
  EXPECT_EQ(override_error("materials={}").path(), "materials");
  Json doc = base_scene();
  doc["materials"]["wa ter"] = doc["materials"]["water"];
  EXPECT_EQ(scene_error(doc).path(), "materials.wa ter");
}

TEST(SceneError, EnumWithTypo) {
  const SceneError e = override_error("solver.kernel=cubic_splin");
  EXPECT_EQ(e.path(), "solver.kernel");
  EXPECT_NE(message(e).find("did you mean 'cubic_spline'?"), std::string::npos) << e.what();
  EXPECT_EQ(override_error("domain.walls=[\"-x\", \"x\"]").path(), "domain.walls[1]");
  EXPECT_EQ(override_error("domain.walls=[\"-x\", \"-x\"]").path(), "domain.walls[1]");
}

TEST(SceneError, EmptyDomain) {
  const SceneError e = override_error("domain.max=[0.4, 0, 0.3]");
  EXPECT_EQ(e.path(), "domain");
  EXPECT_NE(message(e).find("empty domain"), std::string::npos) << e.what();
}

TEST(SceneError, EmptyBox) {
  const SceneError e = override_error("solids[0].box.max=[0.1, 0.2, 0.05]");
  EXPECT_EQ(e.path(), "solids[0].box");
  EXPECT_NE(message(e).find("x runs from 0.15 m to 0.1 m"), std::string::npos) << e.what();
}

TEST(SceneError, UnknownMaterial) {
  const SceneError e = override_error("fluids[1].material=lava");
  EXPECT_EQ(e.path(), "fluids[1].material");
  EXPECT_NE(message(e).find("unknown material 'lava'; defined: water, glass"), std::string::npos) << e.what();
}

TEST(SceneError, SolidMaterialForAFluid) {
  const SceneError e = override_error("fluids[0].material=glass");
  EXPECT_EQ(e.path(), "fluids[0].material");
  EXPECT_NE(message(e).find("'glass' is a solid"), std::string::npos) << e.what();
  EXPECT_EQ(override_error("solids[1].material=water").path(), "solids[1].material");
  EXPECT_EQ(override_error("domain.wall_material=water").path(), "domain.wall_material");
}

TEST(SceneError, WallsNeedAMaterial) {
  Json doc = base_scene();
  doc["domain"].erase("wall_material");
  EXPECT_EQ(scene_error(doc).path(), "domain.wall_material");
}

TEST(SceneError, ShapeDecidesWhichFieldsBelong) {
  Json doc = base_scene();
  doc["solids"][1]["box"] = doc["solids"][0]["box"];
  SceneError e = scene_error(doc);
  EXPECT_EQ(e.path(), "solids[1].box");
  EXPECT_NE(message(e).find("only allowed when shape is 'box'"), std::string::npos) << e.what();
  doc = base_scene();
  doc["solids"][1].erase("normal");
  e = scene_error(doc);
  EXPECT_EQ(e.path(), "solids[1].normal");
  EXPECT_NE(message(e).find("required when shape is 'plane'"), std::string::npos) << e.what();
  EXPECT_EQ(override_error("solids[1].normal=[0,0,0]").path(), "solids[1].normal");
}

TEST(SceneError, FluidOutsideTheDomain) {
  const SceneError e = override_error("fluids[1].box.max=[0.5, 0.1, 0.1]");
  EXPECT_EQ(e.path(), "fluids[1].box");
  EXPECT_NE(message(e).find("outside the domain along x"), std::string::npos) << e.what();
}

TEST(SceneError, SpacingAgainstTheDomain) {
  EXPECT_EQ(override_error("spacing=0.2").path(), "spacing");
  const SceneError e = override_error("spacing=0.0001");
  EXPECT_EQ(e.path(), "spacing");
  EXPECT_NE(message(e).find("more than the limit of 20,000,000"), std::string::npos) << e.what();
}

TEST(SceneError, AScenePastTheMachinesMemoryIsRefusedBeforeAllocating) {
  // 18.2 million particles took 6 GB and 24 s for two steps; a scene past the available memory is now
  // refused at load, naming the estimate, the limit and the override.
  const testing::RestoreEnv restore("THAW_MEMORY_LIMIT");
  ::unsetenv("THAW_MEMORY_LIMIT");
  EXPECT_GT(memory_limit_bytes(), 1e8) << "MemAvailable of this machine";
  // About 2.5 million particles: 300 MB + 360 B each.
  const std::string fine = "spacing=0.001";
  ::setenv("THAW_MEMORY_LIMIT", "500M", 1);
  const SceneError e = override_error(fine);
  EXPECT_EQ(e.path(), "spacing");
  for (const char* part : {"need about 1.", "GB of memory, more than the 0.50 GB THAW_MEMORY_LIMIT allows",
                           "THAW_MEMORY_LIMIT=32G, or off"})
    EXPECT_NE(message(e).find(part), std::string::npos) << e.what();
  ::setenv("THAW_MEMORY_LIMIT", "off", 1);
  EXPECT_NO_THROW(scene_from_json(base_scene(), {fine}));
  ::setenv("THAW_MEMORY_LIMIT", "2x", 1);
  EXPECT_THROW(memory_limit_bytes(), Error);
  ::setenv("THAW_MEMORY_LIMIT", "16G", 1);
  EXPECT_EQ(memory_limit_bytes(), 16e9);
  EXPECT_EQ(estimated_memory_bytes(1e6), 300e6 + 360e6);
}

TEST(SceneError, TimeStepLimitsInOrder) {
  EXPECT_EQ(override_error("solver.min_dt=0.01").path(), "solver.min_dt");
}

// ---- shapes ------------------------------------------------------------------------------------------

// The base scene at 5 mm with an ice material and the given ice entries.
Json scene_with_ice(const std::string& ice) {
  Json doc = base_scene();
  doc["spacing"] = 0.005;
  doc["materials"]["ice"] = Json::parse(
      R"({"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050, "melts_into": "water"})");
  doc["ice"] = Json::parse(ice);
  return doc;
}

// One of each shape, clear of each other, the solids and the fluids; the last (the bunny) free.
const char* kEveryShape = R"([
  {"material": "ice", "box": {"min": [0.02, 0.02, 0.15], "max": [0.06, 0.06, 0.19]}},
  {"material": "ice", "box": {"min": [0.02, 0.1, 0.15], "max": [0.06, 0.14, 0.19]}, "rotation": [0, 0, 45]},
  {"material": "ice", "shape": "sphere", "centre": [0.1, 0.05, 0.2], "radius": 0.02},
  {"material": "ice", "shape": "cylinder", "from": [0.2, 0.05, 0.15], "to": [0.2, 0.05, 0.25], "radius": 0.01},
  {"material": "ice", "shape": "cone", "from": [0.25, 0.05, 0.25], "to": [0.25, 0.05, 0.15], "radius": 0.01},
  {"material": "ice", "shape": "capsule", "from": [0.3, 0.05, 0.15], "to": [0.35, 0.05, 0.15], "radius": 0.01},
  {"material": "ice", "shape": "mesh", "mesh": "meshes/bunny.obj", "centre": [0.3, 0.14, 0.2], "size": 0.06,
   "rotation": [90, 0, 0], "motion": "free"}
])";

TEST(SceneShapes, IceOfEveryShapeIsSampledAndOnlyFixedIceIsAnchored) {
  const Scene s = scene_from_json(scene_with_ice(kEveryShape));
  ASSERT_EQ(s.ice.size(), 7u);
  EXPECT_TRUE(s.ice[0].shape.axis_aligned_box());
  EXPECT_FALSE(s.ice[1].shape.axis_aligned_box());
  EXPECT_EQ(s.ice[2].shape.kind(), Shape::Kind::Sphere);
  EXPECT_EQ(s.ice[4].shape.kind(), Shape::Kind::Cone);
  EXPECT_EQ(s.ice[6].shape.kind(), Shape::Kind::Mesh);
  EXPECT_EQ(s.ice[0].motion, IceBlock::Motion::Fixed);
  EXPECT_EQ(s.ice[6].motion, IceBlock::Motion::Free);
  EXPECT_NEAR(s.ice[2].box.min.z(), 0.18, 1e-15);  // the bounding box
  EXPECT_NEAR(s.ice[6].box.max.x() - s.ice[6].box.min.x(), 0.06, 1e-12);
  // The mesh was found in configs/, and the source says where.
  EXPECT_EQ(s.source["ice"][6]["mesh"],
            (kSource / "configs" / "meshes" / "bunny.obj").lexically_normal().string());
  EXPECT_EQ(s.source["ice"][0]["shape"], "box");
  EXPECT_EQ(s.source["ice"][0]["motion"], "fixed");

  const HostParticles p = sample_scene(s);
  ASSERT_EQ(p.anchored.size(), p.size());
  std::size_t fixed = 0;
  for (std::size_t b = 0; b + 1 < s.ice.size(); ++b) {
    const std::size_t n = voxelize(s.ice[b].shape, s.spacing, &s.domain.min).size();
    EXPECT_GT(n, 10u) << "ice[" << b << "]";
    fixed += n;
  }
  const std::size_t bunny = voxelize(s.ice[6].shape, s.spacing, &s.domain.min).size();
  EXPECT_GT(bunny, 300u);
  ASSERT_EQ(p.count(Phase::Ice), fixed + bunny);
  // Ice comes after the boundary particles, in the order of its entries.
  std::size_t first = 0;
  while (p.phase[first] != std::uint8_t(Phase::Ice)) ++first;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool fixed_ice = i >= first && i < first + fixed;
    ASSERT_EQ(p.anchored[i], fixed_ice ? 1 : 0) << "particle " << i;
    if (fixed_ice) {
      ASSERT_EQ(p.phase[i], std::uint8_t(Phase::Ice));
    }
  }
}

TEST(SceneShapes, LaterIceAndFluidsSkipWhatIsAlreadyFilled) {
  Json doc = scene_with_ice(R"([
    {"material": "ice", "shape": "sphere", "centre": [0.05, 0.05, 0.05], "radius": 0.03},
    {"material": "ice", "shape": "sphere", "centre": [0.08, 0.05, 0.05], "radius": 0.02}
  ])");
  doc["solids"][0] = Json::parse(
      R"({"shape": "capsule", "material": "glass", "from": [0.25, 0.05, 0.05], "to": [0.25, 0.05, 0.09], "radius": 0.02})");
  const Scene s = scene_from_json(doc);
  const HostParticles p = sample_scene(s);
  // All lattices here line up (every bounding box starts on a multiple of 5 mm), so an overlap would
  // put two particles on one point.
  std::set<std::array<long, 3>> seen;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.phase[i] == std::uint8_t(Phase::Solid)) continue;  // the base scene's plane and -z wall coincide
    const Float4& x = p.position[i];
    ASSERT_TRUE(
        seen.insert({std::lround(x[0] / 1e-4), std::lround(x[1] / 1e-4), std::lround(x[2] / 1e-4)}).second)
        << x[0] << " " << x[1] << " " << x[2];
  }
  const std::vector<Eigen::Vector3d> first = voxelize(s.ice[0].shape, s.spacing);
  const std::vector<Eigen::Vector3d> second = voxelize(s.ice[1].shape, s.spacing);
  const auto second_only = std::size_t(std::count_if(
      second.begin(), second.end(), [&](const Eigen::Vector3d& x) { return !s.ice[0].shape.contains(x); }));
  EXPECT_LT(second_only, second.size());
  EXPECT_EQ(p.count(Phase::Ice), first.size() + second_only);
  // The capsule's boundary particles are a shell, and no water sits inside it.
  const std::size_t shell = voxelize_shell(s.solids[0].shape, s.spacing, wall_layer_count(s)).size();
  EXPECT_LT(shell, voxelize(s.solids[0].shape, s.spacing).size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.phase[i] != std::uint8_t(Phase::Water)) continue;
    const Eigen::Vector3d x(p.position[i][0], p.position[i][1], p.position[i][2]);
    ASSERT_FALSE(s.solids[0].shape.contains(x)) << x.transpose();
    ASSERT_FALSE(s.ice[0].shape.contains(x)) << x.transpose();
  }
}

TEST(SceneShapes, ExistingIceBlocksKeepTheirMeaning) {
  const Scene s = load_scene("glass-ice-cubes");  // ice entries written before shapes and motion existed
  const Json& ice = s.source["ice"];
  ASSERT_EQ(s.ice.size(), ice.size());
  for (std::size_t i = 0; i < s.ice.size(); ++i) {
    EXPECT_TRUE(s.ice[i].shape.axis_aligned_box());
    EXPECT_EQ(s.ice[i].motion, IceBlock::Motion::Fixed);
    const Json& min = ice[i]["box"]["min"];
    EXPECT_EQ(s.ice[i].box.min,
              Eigen::Vector3d(min[0].get<double>(), min[1].get<double>(), min[2].get<double>()));
  }
}

TEST(SceneShapes, MeshPathIsRelativeToTheSceneFile) {
  testing::TempDir dir("scene-mesh");
  fs::create_directories(dir.path() / "shapes");
  testing::write_text(dir.path() / "shapes" / "cube.obj",
                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                      "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
                      "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  Json doc = scene_with_ice(
      R"([{"material": "ice", "shape": "mesh", "mesh": "shapes/cube.obj", "centre": [0.05, 0.05, 0.2], "size": 0.04}])");
  testing::write_text(dir.path() / "scene.json", doc.dump(2));
  const Scene s = load_scene(dir / "scene.json");
  EXPECT_EQ(s.source["ice"][0]["mesh"], (dir.path() / "shapes" / "cube.obj").string());
  EXPECT_NEAR(s.ice[0].shape.volume(), 0.04 * 0.04 * 0.04, 1e-12);
  // The source reloads from anywhere: its path is absolute.
  EXPECT_NO_THROW(scene_from_json(s.source));
  // The same document read from elsewhere does not find the mesh, and says where it looked.
  const SceneError e = scene_error(doc);
  EXPECT_EQ(e.path(), "ice[0].mesh");
  EXPECT_NE(message(e).find("'shapes/cube.obj' not found; looked for"), std::string::npos) << e.what();
  EXPECT_NE(message(e).find((kSource / "configs" / "shapes" / "cube.obj").string()), std::string::npos)
      << e.what();
}

TEST(SceneError, BrokenMeshNamesTheFieldAndTheFile) {
  testing::TempDir dir("scene-broken-mesh");
  testing::write_text(dir.path() / "broken.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n");
  const std::string file = dir / "broken.stl";
  const SceneError e =
      scene_error(scene_with_ice(R"([{"material": "ice", "shape": "mesh", "mesh": ")" + file +
                                 R"(", "centre": [0.05, 0.05, 0.2], "size": 0.04}])"));
  EXPECT_EQ(e.path(), "ice[0].mesh");
  EXPECT_NE(message(e).find(file), std::string::npos) << e.what();
}

TEST(SceneError, IceThatBecomesNoParticlesIsRefused) {
  // A one-triangle OBJ or STL as ice ran a scene without ice, exit 0 and no word.
  testing::TempDir dir("scene-flat-mesh");
  testing::write_text(dir.path() / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  testing::write_text(dir.path() / "tri.stl",
                      "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                      "endloop\nendfacet\nendsolid t\n");
  for (const char* name : {"tri.obj", "tri.stl"}) {
    SCOPED_TRACE(name);
    const Scene s =
        scene_from_json(scene_with_ice(R"([{"material": "ice", "shape": "mesh", "mesh": ")" + (dir / name) +
                                       R"(", "centre": [0.05, 0.05, 0.2], "size": 0.04}])"));
    try {
      initial_state(s);
      ADD_FAILURE() << "no error";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.path(), "ice[0]");
      EXPECT_NE(message(e).find("closed around a volume"), std::string::npos) << e.what();
    }
  }
  // Ice placed wholly inside earlier ice.
  const Scene inside = scene_from_json(scene_with_ice(
      R"([{"material": "ice", "shape": "sphere", "centre": [0.05, 0.05, 0.2], "radius": 0.03},
          {"material": "ice", "shape": "sphere", "centre": [0.05, 0.05, 0.2], "radius": 0.01}])"));
  try {
    initial_state(inside);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "ice[1]");
    EXPECT_NE(message(e).find("inside earlier ice"), std::string::npos) << e.what();
  }
}

TEST(SceneError, ImpossibleMagnitudesNameTheirField) {
  // A rest density of 1e-300 gave particles no mass and failed as "particle 0 has mass -nan".
  const SceneError density = override_error("materials.water.density=1e-300");
  EXPECT_EQ(density.path(), "materials.water.density");
  // A spacing of 1e-9 m was "about -9,223,372,036,854,775,808 particles".
  const SceneError tiny = override_error("spacing=1e-9");
  EXPECT_EQ(tiny.path(), "spacing");
  EXPECT_EQ(message(tiny).find("-9,223"), std::string::npos) << tiny.what();
  EXPECT_NE(message(tiny).find("e+"), std::string::npos) << tiny.what();
  // A dryer direction of [1e308, 1e308, 1e308] normalised to zeros and delivered 0 J; the protocol
  // refused it. A scene file now refuses it as the protocol does, and so are the tiny ones.
  Json doc = base_scene();
  doc["dryers"] = Json::parse(R"([{"position": [0.1, 0.1, 0.25], "direction": [1e308, 1e308, 1e308]}])");
  const SceneError huge = scene_error(doc);
  EXPECT_EQ(huge.path(), "dryers[0].direction");
  EXPECT_NE(message(huge).find("moderate size"), std::string::npos) << huge.what();
  doc["dryers"][0]["direction"] = Json::parse("[1e-320, 0, 0]");
  EXPECT_EQ(scene_error(doc).path(), "dryers[0].direction");
  doc["dryers"][0]["direction"] = Json::parse("[0, 1e150, 1e150]");
  EXPECT_NEAR(scene_from_json(doc).dryers[0].direction.y(), std::sqrt(0.5), 1e-12);
}

TEST(SceneError, ShapeFieldsAreCheckedAtTheirPaths) {
  struct Case {
    const char* ice;
    const char* path;
    const char* says;
  };
  const Case cases[] = {
      {R"({"material": "ice", "shape": "sphear", "centre": [0.1, 0.1, 0.2], "radius": 0.01})", "ice[1].shape",
       "did you mean 'sphere'"},
      {R"({"material": "ice", "shape": "sphere", "centre": [0.1, 0.1, 0.2]})", "ice[1].radius",
       "missing: required when shape is 'sphere'"},
      {R"({"material": "ice", "shape": "sphere", "centre": [0.1, 0.1, 0.2], "radius": -0.01})",
       "ice[1].radius", "out of range"},
      {R"({"material": "ice", "box": {"min": [0.1, 0.1, 0.2], "max": [0.12, 0.12, 0.22]}, "radius": 0.01})",
       "ice[1].radius", "only allowed when shape is 'sphere', 'cylinder', 'cone' or 'capsule'"},
      {R"({"material": "ice", "shape": "sphere", "centre": [0.1, 0.1, 0.2], "radius": 0.01, "rotation": [0, 0, 1]})",
       "ice[1].rotation", "only allowed when shape is 'box' or 'mesh'"},
      {R"({"material": "ice", "shape": "cone", "from": [0.1, 0.1, 0.2], "to": [0.1, 0.1, 0.2], "radius": 0.01})",
       "ice[1].to", "no length"},
      {R"({"material": "ice", "shape": "capsule", "from": [0.1, 0.1, 0.2], "radius": 0.01})", "ice[1].to",
       "missing: required when shape is 'capsule'"},
      {R"({"material": "ice", "shape": "mesh", "mesh": "meshes/bunny.obj", "centre": [0.1, 0.1, 0.2]})",
       "ice[1].size", "required when shape is 'mesh'"},
      {R"({"material": "ice", "shape": "mesh", "mesh": "meshes/nowhere.obj", "centre": [0.1, 0.1, 0.2], "size": 0.02})",
       "ice[1].mesh", "'meshes/nowhere.obj' not found"},
      {R"({"material": "ice", "shape": "sphere", "centre": [0.1, 0.1, 0.29], "radius": 0.02})", "ice[1]",
       "outside the domain along z"},
      {R"({"material": "ice", "shape": "sphere", "centre": [0.1, 0.1, 0.2], "radius": 0.01, "motion": "loose"})",
       "ice[1].motion", "not one of 'fixed', 'free'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.ice);
    const std::string ice =
        std::string(R"([{"material": "ice", "box": {"min": [0.3, 0.1, 0.2], "max": [0.32, 0.12, 0.22]}}, )") +
        c.ice + "]";
    const SceneError e = scene_error(scene_with_ice(ice));
    EXPECT_EQ(e.path(), c.path) << e.what();
    EXPECT_NE(message(e).find(c.says), std::string::npos) << e.what();
  }
  // Solids take the same shapes, and planes none of their fields.
  Json doc = base_scene();
  doc["solids"].push_back(Json::parse(R"({"shape": "sphere", "material": "glass", "radius": 0.01})"));
  EXPECT_EQ(scene_error(doc).path(), "solids[2].centre");
  doc = base_scene();
  doc["solids"][1]["radius"] = 0.01;
  EXPECT_EQ(scene_error(doc).path(), "solids[1].radius");
}

// ---- files -------------------------------------------------------------------------------------------

TEST(SceneFile, MissingFileNamesItAndWhereItLooked) {
  try {
    load_scene("no-such-scene");
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    ADD_FAILURE() << "a missing file has no JSON path: " << e.what();
  } catch (const Error& e) {
    EXPECT_NE(message(e).find("'no-such-scene' not found"), std::string::npos) << e.what();
    EXPECT_NE(message(e).find("configs/no-such-scene.json"), std::string::npos) << e.what();
  }
}

TEST(SceneFile, InvalidJsonGivesLineAndColumn) {
  std::string p;
  const std::string e = file_error("thaw-bad-scene.json", "{\n  \"spacing\": 0.01,\n  \"domain\": }\n", p);
  EXPECT_NE(e.find(p + ":3:13: invalid JSON"), std::string::npos) << e;
}

TEST(SceneFile, HugeNumberInAFile) {
  std::string p;
  const std::string e = file_error("thaw-huge-scene.json", "{\n  \"spacing\": 1e400\n}\n", p);
  EXPECT_NE(e.find(p + ":2:14: invalid JSON: number 1e400 is out of range"), std::string::npos) << e;
}

TEST(SceneFile, DeepNestingIsRefusedWithoutOverflowingTheStack) {
  // 100,000 nested objects crashed `thaw run` (a stack overflow while the document was copied).
  std::string deep = "{\"name\": \"deep\", \"spacing\": 0.01, \"x\": ";
  for (int i = 0; i < 100000; ++i) deep += "{\"a\": ";
  deep += "1" + std::string(100000, '}') + "}";
  std::string p;
  const std::string e = file_error("thaw-deep-scene.json", deep, p);
  EXPECT_NE(e.find(p + ": x.a.a."), std::string::npos) << e.substr(0, 300);
  EXPECT_NE(e.find("nested deeper than 64 levels"), std::string::npos) << e.substr(0, 300);
  // The same limit holds for a --set value.
  const std::string value = "x=" + std::string(1000, '[') + std::string(1000, ']');
  EXPECT_NE(message(override_error(value)).find("nested deeper"), std::string::npos);
}

TEST(SceneFile, ARepeatedKeyIsRefusedNamingItsPath) {
  std::string p;
  const std::string e =
      file_error("thaw-dup-scene.json", "{\"name\": \"d\", \"solver\": {\"cfl\": 0.2, \"cfl\": 0.4}}", p);
  EXPECT_NE(e.find(p + ": solver.cfl: key appears twice"), std::string::npos) << e;
  // Inside arrays the path carries the index.
  const std::string in_array =
      file_error("thaw-dup-array.json", "{\"fluids\": [{}, {\"box\": 1, \"box\": 2}]}", p);
  EXPECT_NE(in_array.find("fluids[1].box: key appears twice"), std::string::npos) << in_array;
}

TEST(SceneFile, CommentsAndFileNameAsDefaultName) {
  Json doc = base_scene();
  doc.erase("name");
  const fs::path p = write_temp("thaw-commented.json", "// a comment\n" + doc.dump(2));
  const Scene s = load_scene(p.string(), {"solver.cfl=0.2"});
  EXPECT_EQ(s.name, "thaw-commented");
  EXPECT_EQ(s.solver.cfl, 0.2);
  fs::remove(p);
}

// ---- the schema as building blocks for validation cases -------------------------------------------

TEST(Schema, ACaseDeclaresItsOwnParametersAndEmbedsTheSolver) {
  const Field params = object("", {
                                      number("length", "Bar length").in("m").def(1.0).above(0),
                                      integer("samples", "Probe count").at_least(2),
                                      solver_schema(),
                                  });
  Json doc = {{"samples", 8}, {"solver", {{"cfl", 0.2}}}};
  validate(doc, params);
  EXPECT_EQ(doc["length"], 1.0);
  EXPECT_EQ(solver_settings_from_json(doc["solver"]).cfl, 0.2);
  EXPECT_EQ(solver_settings_from_json(doc["solver"]).eos, Eos::Tait);

  Json bad = {{"samples", 1}};
  try {
    validate(bad, params, "case");
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "case.samples");
  }
  EXPECT_NE(schema_markdown(params, "Parameters").find("| `length` | number | m | `1` | > 0 |"),
            std::string::npos);
}

TEST(Schema, VariantDefaultsOnlyForTheirVariant) {
  const Field params =
      object("", {
                     choice("source", {"lamp", "dryer"}, "Heat source"),
                     number("power", "Lamp power").in("W").def(60.0).when("source", "lamp"),
                     number("flow", "Dryer air flow").in("m^3/s").def(0.01).when("source", "dryer"),
                 });
  Json lamp = {{"source", "lamp"}};
  validate(lamp, params);
  EXPECT_EQ(lamp, (Json{{"source", "lamp"}, {"power", 60.0}}));
  Json dryer = {{"source", "dryer"}, {"power", 100}};
  try {
    validate(dryer, params);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "power");
  }
}

TEST(Schema, FindsDeclarationsAndLiveParameters) {
  const Field* cfl = find_field(scene_schema(), "solver.cfl");
  ASSERT_NE(cfl, nullptr);
  EXPECT_TRUE(cfl->settable);
  EXPECT_EQ(range_text(*cfl), "(0, 1]");
  const Field* density = find_field(scene_schema(), "materials.water.density");
  ASSERT_NE(density, nullptr);
  EXPECT_EQ(density->unit, "kg/m^3");
  ASSERT_NE(find_field(scene_schema(), "fluids[0].box.min"), nullptr);
  EXPECT_EQ(find_field(scene_schema(), "solver.nope"), nullptr);
  const std::vector<std::string> live = settable_paths(scene_schema());
  EXPECT_NE(std::find(live.begin(), live.end(), "solver.cfl"), live.end());
  EXPECT_NE(std::find(live.begin(), live.end(), "gravity"), live.end());
}

TEST(Schema, ValidatesASingleValueAgainstItsField) {
  const Field& cfl = *find_field(scene_schema(), "solver.cfl");
  Json ok = 0.5;
  EXPECT_NO_THROW(validate(ok, cfl, "solver.cfl"));
  Json too_big = 2.0;
  EXPECT_THROW(validate(too_big, cfl, "solver.cfl"), SceneError);
}

}  // namespace
}  // namespace thaw

namespace thaw {
TEST(Scene, WendlandNeedsAWideEnoughSupport) {
  try {
    scene_from_json(Json::parse(scene_example_json()), {"solver.support_ratio=2"});
    FAIL() << "expected a SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "solver.support_ratio");
    EXPECT_NE(std::string(e.what()).find("wendland_c2"), std::string::npos) << e.what();
  }
}
}  // namespace thaw
