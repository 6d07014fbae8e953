// The `thaw` executable end to end: bad scenes fail cleanly (exit status 2, no crash, the JSON path
// named), the subcommands' listings and errors, a short run's metrics and exports, and scene-doc.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "render/image_io.h"
#include "server/render_options.h"
#include "sim/scene.h"
#include "sim/state_file.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::run_thaw;
using testing::shell_quote;
using testing::TempDir;

// A valid scene (a few hundred particles) that each bad-scene test breaks in one place.
Json small_scene() {
  return Json::parse(R"({
    "name": "cli-test",
    "domain": {"min": [0, 0, 0], "max": [0.2, 0.1, 0.2], "walls": ["-z"], "wall_material": "glass"},
    "spacing": 0.02,
    "materials": {
      "water": {"kind": "fluid", "density": 1000, "viscosity": 1e-3, "conductivity": 0.56, "specific_heat": 4217},
      "glass": {"kind": "solid", "density": 2500, "conductivity": 1.0, "specific_heat": 840}
    },
    "fluids": [{"material": "water", "box": {"min": [0, 0, 0], "max": [0.1, 0.1, 0.1]}}]
  })");
}

std::string describe(const CommandResult& r) {
  return "exited " + std::to_string(r.exited) + " code " + std::to_string(r.exit_code) + " signal " +
         std::to_string(r.signal) + "\nstdout: " + r.out + "\nstderr: " + r.err;
}

// Runs `thaw run` on `doc` written to a file and expects a clean failure whose message names `path`.
void expect_scene_rejected(const Json& doc, const std::string& path, const std::string& extra = "") {
  TempDir dir("cli-bad-scene");
  testing::write_text(dir / "scene.json", doc.dump(2));
  const auto r = run_thaw("run " + shell_quote(dir / "scene.json") + " --steps 1 " + extra, dir);
  EXPECT_TRUE(r.exited) << "killed by signal " << r.signal << "\n" << describe(r);
  EXPECT_EQ(r.exit_code, 2) << describe(r);
  EXPECT_NE(r.err.find(path), std::string::npos) << "stderr should name '" << path << "'\n" << describe(r);
  EXPECT_EQ(r.err.find("terminate called"), std::string::npos) << describe(r);
}

TEST(ThawCli, UnknownKeyIsRejectedWithItsPath) {
  Json doc = small_scene();
  doc["solver"] = {{"cfll", 0.3}};
  expect_scene_rejected(doc, "solver.cfll");
}

TEST(ThawCli, WrongTypeIsRejectedWithItsPath) {
  Json doc = small_scene();
  doc["spacing"] = "abc";
  expect_scene_rejected(doc, "spacing");
}

TEST(ThawCli, NegativeSpacingIsRejected) {
  Json doc = small_scene();
  doc["spacing"] = -0.01;
  expect_scene_rejected(doc, "spacing");
}

TEST(ThawCli, EmptyDomainIsRejected) {
  Json doc = small_scene();
  doc["domain"]["max"] = doc["domain"]["min"];
  expect_scene_rejected(doc, "domain");
}

TEST(ThawCli, SetOverrideOutOfRangeOnShippedSceneIsRejected) {
  TempDir dir("cli-set");
  const auto r = run_thaw("run dam-break --steps 1 --set spacing=-1", dir);
  EXPECT_TRUE(r.exited && r.exit_code == 2) << describe(r);
  EXPECT_NE(r.err.find("spacing"), std::string::npos) << describe(r);
  EXPECT_TRUE(r.out.find("particles") == std::string::npos) << "the run must not start\n" << describe(r);
}

TEST(ThawCli, MissingSceneFileIsNamed) {
  TempDir dir("cli-missing");
  const std::string missing = dir / "no-such-scene.json";
  const auto r = run_thaw("run " + shell_quote(missing) + " --steps 1", dir);
  EXPECT_TRUE(r.exited && r.exit_code == 2) << describe(r);
  EXPECT_NE(r.err.find(missing), std::string::npos) << describe(r);
}

TEST(ThawCli, EverySubcommandPrintsItsUsageWithHelpAndRunsNothing) {
  TempDir dir("cli-help");
  for (const char* cmd :
       {"serve", "ctl", "run", "validate", "bench", "bench throughput", "render", "info", "scene-doc"}) {
    // `run --help` once tried to load a scene named "--help"; with a scene before it, it would run.
    const auto r = run_thaw(std::string(cmd) + " dam-break --help --steps 1000000", dir);
    EXPECT_TRUE(r.exited && r.exit_code == 0) << cmd << ": " << describe(r);
    const std::string first =
        std::string("usage: thaw ") + std::string(cmd).substr(0, std::string(cmd).find(' '));
    EXPECT_EQ(r.out.rfind(first, 0), 0u) << cmd << ": " << describe(r);
    EXPECT_EQ(r.out.find("particles (water"), std::string::npos) << cmd << " ran: " << describe(r);
  }
  const auto all = run_thaw("--help", dir);
  EXPECT_TRUE(all.exited && all.exit_code == 0) << describe(all);
  for (const char* cmd : {"serve", "ctl", "run", "validate", "bench", "render", "info", "scene-doc"})
    EXPECT_NE(all.out.find(std::string("  ") + cmd + " "), std::string::npos) << cmd;
}

TEST(ThawCli, ValidateListsTheCases) {
  TempDir dir("cli-validate");
  const auto r = run_thaw("validate --list", dir);
  EXPECT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  EXPECT_NE(r.out.find("hydrostatic"), std::string::npos) << describe(r);
  EXPECT_NE(r.out.find("dam-break"), std::string::npos) << describe(r);
}

TEST(ThawCli, UnknownValidationCaseNamesTheCases) {
  TempDir dir("cli-validate-nope");
  const auto r = run_thaw("validate nope", dir);
  EXPECT_TRUE(r.exited) << describe(r);
  EXPECT_NE(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("nope"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("hydrostatic"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("dam-break"), std::string::npos) << describe(r);
}

// The same run in two processes leaves the same state file, byte for byte (issue 44): wash-the-plate (heat, a
// dryer, a coating and its cleanser, free ice) and default at twice their spacing. And `validate --twice`
// runs a case twice in one process and says the two agree.
TEST(ThawCli, TwoProcessesGiveTheSameBits) {
  TempDir dir("cli-twice");
  for (const std::string run :
       {"run wash-the-plate --steps 80 --set spacing=0.005", "run default --steps 80 --set spacing=0.006"}) {
    SCOPED_TRACE(run);
    for (const char* out : {"a.state", "b.state"}) {
      const auto r = run_thaw(run + " --state-out " + out + " --no-progress --quiet", dir);
      ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
    }
    EXPECT_TRUE(testing::read_file_bytes(dir / "a.state") == testing::read_file_bytes(dir / "b.state"));
  }
  const auto twice = run_thaw("validate conservation --twice --steps 150", dir);
  EXPECT_TRUE(twice.exited && twice.exit_code == 0) << describe(twice);
  EXPECT_NE(twice.out.find("the same"), std::string::npos) << describe(twice);
  for (const char* bad :
       {"validate --all conservation", "validate --all --res 4", "validate conservation --steps 9"}) {
    const auto r = run_thaw(bad, dir);
    EXPECT_TRUE(r.exited && r.exit_code != 0) << bad << ": " << describe(r);
  }
}

// `thaw bench throughput` and `thaw bench accuracy` end to end, at sizes that take seconds: the
// throughput JSON has a row per size, and the accuracy sweep writes its table and plot.
TEST(ThawCli, BenchThroughputPrintsARowPerSize) {
  TempDir dir("cli-bench-throughput");
  const auto r = run_thaw("bench throughput --sizes 2000,4000 --steps 1 --json", dir);
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  const Json j = Json::parse(r.out);
  ASSERT_EQ(j["sizes"].size(), 2u) << r.out;
  for (const Json& row : j["sizes"]) {
    EXPECT_GT(row["stage_us"]["step"].get<double>(), 0.0) << row.dump();
    EXPECT_GT(row["density_ratio"].get<double>(), 0.0) << row.dump();
  }
}

// The throughput bench times its own scene: a --set it would ignore is refused, naming it.
TEST(ThawCli, BenchThroughputRefusesASetItWouldIgnore) {
  TempDir dir("cli-bench-throughput-set");
  const auto r = run_thaw("bench throughput --sizes 2000 --steps 1 --set solver.pressure=dfsph", dir);
  ASSERT_TRUE(r.exited) << describe(r);
  EXPECT_NE(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("solver.pressure=dfsph"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("thaw run dam-break"), std::string::npos) << describe(r);
}

TEST(ThawCli, BenchAccuracyWritesItsTableAndPlot) {
  TempDir dir("cli-bench-accuracy");
  const auto r = run_thaw(
      "bench accuracy rigid-spin --res 4,6 --set revolutions=1 --out " + shell_quote(dir / "out") + " --json",
      dir);
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  const Json j = Json::parse(r.out);
  ASSERT_EQ(j["runs"].size(), 2u) << r.out;
  EXPECT_EQ(j["runs"][0]["res"], 4);
  EXPECT_EQ(j["runs"][1]["res"], 6);
  for (const char* file : {"rigid-spin-accuracy.json", "rigid-spin-accuracy.csv", "rigid-spin-accuracy.png"})
    EXPECT_GT(fs::file_size(fs::path(dir / "out") / file), 100u) << file;
  std::ifstream csv(fs::path(dir / "out") / "rigid-spin-accuracy.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "case,res,particles,steps,wall_s,metric,value,reference,error,gate");
}

TEST(ThawCli, InfoNamesADevice) {
  TempDir dir("cli-info");
  const auto r = run_thaw("info", dir);
  EXPECT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  const auto at = r.out.find("would use: ");
  ASSERT_NE(at, std::string::npos) << describe(r);
  EXPECT_NE(r.out.compare(at, 16, "would use: none:"), 0) << describe(r);
}

TEST(ThawCli, RunWithoutUntilOrStepsSaysSo) {
  TempDir dir("cli-run-no-end");
  const auto r = run_thaw("run dam-break", dir);
  EXPECT_TRUE(r.exited && r.exit_code == 2) << describe(r);
  EXPECT_NE(r.err.find("--until"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("--steps"), std::string::npos) << describe(r);
}

TEST(ThawCli, ShortRunWritesMetricsAndExports) {
  TempDir dir("cli-run");
  const double interval = 0.001;
  const auto r = run_thaw(
      "run dam-break --steps 5 --set spacing=0.025 --set solver.output_interval=0.001 "
      "--metrics m.jsonl --export out --every 2 --no-progress",
      dir);
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);

  std::ifstream in(dir / "m.jsonl");
  std::vector<Json> lines;
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    ASSERT_NO_THROW(lines.push_back(Json::parse(line))) << line;
  }
  ASSERT_GE(lines.size(), 2u);
  for (const auto& j : lines)
    for (const char* key : {"time", "steps", "dt", "wall_ms_per_step", "particles", "max_speed",
                            "max_density_error", "total_mass", "energy"})
      EXPECT_TRUE(j.contains(key)) << "missing '" << key << "' in " << j.dump();
  EXPECT_EQ(lines.front()["steps"].get<int>(), 0);
  EXPECT_EQ(lines.front()["time"].get<double>(), 0.0);
  EXPECT_EQ(lines.back()["steps"].get<int>(), 5);
  EXPECT_GT(lines.back()["total_mass"].get<double>(), 0.0);
  // One line at the first step past each output boundary, plus the start and the final partial one.
  const double end = lines.back()["time"].get<double>();
  const double dt = lines.back()["dt"].get<double>();
  ASSERT_GT(dt, 0.0);
  const int boundaries = static_cast<int>(std::floor(end / interval + 1e-9));
  ASSERT_GE(boundaries, 1) << "the run should cross an output boundary; end time " << end;
  for (int k = 1; k <= boundaries; ++k) {
    int found = 0;
    for (const auto& j : lines) {
      const double t = j["time"].get<double>();
      found += t >= k * interval - 1e-12 && t < k * interval + 1.5 * dt;
    }
    EXPECT_EQ(found, 1) << "output boundary " << k * interval << " s";
  }
  EXPECT_LE(lines.size(), static_cast<std::size_t>(boundaries) + 2);
  for (std::size_t i = 1; i < lines.size(); ++i)
    EXPECT_GT(lines[i]["steps"].get<int>(), lines[i - 1]["steps"].get<int>());

  // Frames at the start and after steps 2 and 4.
  int vtu = 0, ply = 0, pvd = 0;
  for (const auto& e : fs::directory_iterator(dir.path() / "out")) {
    const auto ext = e.path().extension();
    vtu += ext == ".vtu";
    ply += ext == ".ply";
    pvd += ext == ".pvd";
  }
  EXPECT_EQ(vtu, 3);
  EXPECT_EQ(ply, 3);
  EXPECT_EQ(pvd, 1);
}

// A melting scene through the command line: heat metrics, temperatures in the exports, resuming
// from a state file, and a runtime-style override of a heat source from --set.
TEST(ThawCli, HeatRunReportsTheEnergyBudgetAndExportsTemperature) {
  TempDir dir("cli-heat");
  const auto r = run_thaw(
      "run ice-on-plate --steps 30 --set spacing=0.006 --set solver.output_interval=0.005 "
      "--metrics m.jsonl --export out --every 30 --state-out half.state --no-progress",
      dir);
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  EXPECT_NE(r.out.find("energy closure"), std::string::npos) << r.out;
  std::ifstream in(dir / "m.jsonl");
  Json last;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) last = Json::parse(line);
  for (const char* key : {"mass", "temperature", "heat"}) ASSERT_TRUE(last.contains(key)) << last.dump();
  const Json& heat = last["heat"];
  EXPECT_GT(heat["in"]["held"].get<double>(), 0.0) << "the plate is held at 40 °C";
  EXPECT_LT(std::abs(heat["closure_relative"].get<double>()), 1e-6) << heat.dump();
  EXPECT_LE(last["temperature"]["max"].get<double>(), 40.0);

  // The PLY header and the VTU name the temperature.
  std::ifstream ply(dir.path() / "out" / "frame_000001.ply", std::ios::binary);
  std::string header((std::istreambuf_iterator<char>(ply)), {});
  EXPECT_NE(header.find("property float temperature"), std::string::npos);
  std::ifstream vtu(dir.path() / "out" / "frame_000001.vtu", std::ios::binary);
  std::string xml((std::istreambuf_iterator<char>(vtu)), {});
  EXPECT_NE(xml.find("Name=\"temperature\""), std::string::npos);

  // Resuming carries the enthalpy and the energy account: 30 + 30 steps equal 60 straight.
  const auto straight = run_thaw(
      "run ice-on-plate --steps 60 --set spacing=0.006 --set solver.output_interval=0.005 --state-out "
      "full.state "
      "--no-progress --quiet",
      dir);
  ASSERT_TRUE(straight.exited && straight.exit_code == 0) << describe(straight);
  const auto resumed =
      run_thaw("run --state-in half.state --steps 30 --state-out resumed.state --no-progress --quiet", dir);
  ASSERT_TRUE(resumed.exited && resumed.exit_code == 0) << describe(resumed);
  EXPECT_TRUE(testing::read_file_bytes(dir / "full.state") ==
              testing::read_file_bytes(dir / "resumed.state"));
}

// A state file whose checksums are valid but whose contents are not: each field is refused by name
// before any kernel sees it (positions at 1e9 crashed `thaw run --state-in` inside the OpenCL driver;
// NaN positions, a NaN time, a negative dt and an unknown material were taken silently).
TEST(ThawCli, StateFilesWithImpossibleValuesAreRefusedNamingTheField) {
  TempDir dir("cli-bad-state");
  const auto made = run_thaw(
      "run ice-on-plate --steps 2 --set spacing=0.006 --state-out s.state --no-progress --quiet", dir);
  ASSERT_TRUE(made.exited && made.exit_code == 0) << describe(made);
  const SimState good = read_state_file(dir / "s.state");
  ASSERT_GT(good.particles.size(), 10u);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    const char* name;
    void (*spoil)(SimState&, float, float);
    const char* expected;
  };
  const Case cases[] = {
      {"far", [](SimState& s, float, float) { s.particles.position[7][0] = 1e9f; },
       "section 'position', particle 7"},
      {"inf", [](SimState& s, float i, float) { s.particles.position[3][2] = i; },
       "section 'position', particle 3"},
      {"nan", [](SimState& s, float, float n) { s.particles.position[4][1] = n; },
       "section 'position', particle 4"},
      {"time", [](SimState& s, float, float n) { s.time = double(n); }, "time nan s"},
      {"dt", [](SimState& s, float, float) { s.dt = -1e-4; }, "dt -0.0001 s"},
      {"material", [](SimState& s, float, float) { s.particles.material[9] = 200; },
       "section 'material', particle 9"},
      {"velocity", [](SimState& s, float i, float) { s.particles.velocity[2][0] = i; },
       "section 'velocity', particle 2"},
      {"mass", [](SimState& s, float, float) { s.particles.position[1][3] = 0; }, "mass 0 kg"},
      {"enthalpy", [](SimState& s, float, float n) { s.particles.enthalpy[6][0] = n; },
       "section 'enthalpy', particle 6"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    SimState bad = good;
    c.spoil(bad, inf, nan);
    const std::string file = std::string(c.name) + ".state";
    write_state_file(dir / file, bad);
    const auto r = run_thaw("run --state-in " + file + " --steps 3 --no-progress --quiet", dir);
    EXPECT_TRUE(r.exited && r.exit_code != 0) << describe(r);
    EXPECT_NE(r.err.find(file + ": "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    const auto v = run_thaw("render " + file + " --out x.png --size 64x48", dir);
    EXPECT_TRUE(v.exited && v.exit_code != 0) << describe(v);
    EXPECT_NE(v.err.find(c.expected), std::string::npos) << v.err;
  }
}

// Off-screen output from the command line: PNG frames and meshes during a run, any view of a state
// file afterwards, and clear errors for bad rendering options.
TEST(ThawCli, FramesMeshesAndRenderedStates) {
  TempDir dir("cli-render");
  const auto r = run_thaw(
      "run ice-on-plate --steps 4 --set spacing=0.006 --frames frames --export-mesh meshes --mesh-format ply "
      "--every 2 --size 160x120 --state-out s.state --no-progress --quiet",
      dir);
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  for (const char* f : {"frames/frame_000000.png", "frames/frame_000002.png", "meshes/ice_000000.ply",
                        "meshes/ice_000002.ply"})
    EXPECT_TRUE(fs::exists(dir.path() / f)) << f;
  const std::string png = testing::read_file_bytes(dir.path() / "frames/frame_000001.png");
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");

  for (const char* view : {"surface", "particles --colour-by temperature", "slice --slice x,0.5"}) {
    const auto v = run_thaw(std::string("render s.state --out v.png --size 120x90 --view ") + view, dir);
    ASSERT_TRUE(v.exited && v.exit_code == 0) << view << "\n" << describe(v);
    EXPECT_TRUE(fs::exists(dir.path() / "v.png")) << view;
    fs::remove(dir.path() / "v.png");
  }
  // The image centre of the default framing looks at the middle of the domain, where the ice stands.
  const auto picked = run_thaw("render s.state --out p.png --size 160x120 --pick 80,60", dir);
  ASSERT_TRUE(picked.exited && picked.exit_code == 0) << describe(picked);
  EXPECT_NE(picked.out.find("pick 80,60: hit ("), std::string::npos) << picked.out;
  const auto corner =
      run_thaw("render s.state --out p.png --size 160x120 --pick 0,0 --target 0.06,0.06,0.5", dir);
  EXPECT_NE(corner.out.find("no surface"), std::string::npos) << corner.out;
  for (const char* bad : {"--view wireframe", "--size 10x10", "--camera 30", "--slice w,0.5",
                          "--colour-by velocity", "--target 1,2", "--fov 200", "--pick 700,1"}) {
    const auto b = run_thaw(std::string("render s.state --out b.png ") + bad, dir);
    ASSERT_TRUE(b.exited) << bad;
    EXPECT_EQ(b.exit_code, 2) << bad;
    EXPECT_NE(b.err.find(std::string(bad).substr(0, std::string(bad).find(' '))), std::string::npos)
        << "the error names the option: " << b.err;
  }
  const auto missing = run_thaw("render nowhere.state --out b.png", dir);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("nowhere.state"), std::string::npos) << missing.err;
  const auto fmt =
      run_thaw("run ice-on-plate --steps 1 --set spacing=0.006 --export-mesh m --mesh-format stl", dir);
  EXPECT_EQ(fmt.exit_code, 2);
  EXPECT_NE(fmt.err.find("stl"), std::string::npos) << fmt.err;
}

// The surface view coloured by a substance tints the water that holds it: the pool of dye-in-meltwater turns
// red (its dye's colour), less so against a higher reference concentration; a bad reference names the option.
TEST(ThawCli, TheSurfaceViewColouredByADyeTintsTheWater) {
  TempDir dir("cli-tint");
  const auto r = run_thaw("run dye-in-meltwater --steps 1 --state-out s.state --quiet", dir);
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  // The mean red less blue over the picture's middle, where the pool is.
  auto redness = [&](const std::string& options) {
    const auto v = run_thaw("render s.state --out v.png --size 160x120 " + options, dir);
    EXPECT_TRUE(v.exited && v.exit_code == 0) << options << "\n" << describe(v);
    const Image image = decode_png(testing::read_file_bytes(dir.path() / "v.png"));
    double sum = 0;
    long n = 0;
    for (int y = image.height / 4; y < image.height * 3 / 4; ++y)
      for (int x = image.width / 4; x < image.width * 3 / 4; ++x, ++n)
        sum += double(image.pixel(x, y)[0]) - double(image.pixel(x, y)[2]);
    return sum / double(n);
  };
  const double plain = redness(""), dyed = redness("--colour-by substance:dye"),
               faint = redness("--colour-by substance:dye --tint-reference 20");
  std::printf("[ info ] red less blue: plain %.1f, dyed %.1f, against 20 g/L %.1f\n", plain, dyed, faint);
  EXPECT_GT(dyed, plain + 10);
  EXPECT_GT(dyed, faint + 5);
  EXPECT_GT(faint, plain);
  for (const char* bad : {"--tint-reference 0", "--tint-reference x"}) {
    const auto b = run_thaw(std::string("render s.state --out b.png --colour-by substance:dye ") + bad, dir);
    EXPECT_EQ(b.exit_code, 2) << bad;
    EXPECT_NE(b.err.find("--tint-reference"), std::string::npos) << b.err;
  }
  const auto unknown = run_thaw("render s.state --out b.png --colour-by substance:ink", dir);
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_NE(unknown.err.find("ink"), std::string::npos) << unknown.err;
}

// A run's frames share the tint's reference, latched from the first: the dye fades as it dilutes. A new
// substance, or an earlier time (another scene, a reset), latches anew; a given reference is kept.
TEST(TintLatch, KeepsTheFirstFramesReferenceUntilTheSubstanceOrTheRunChanges) {
  TintLatch latch;
  FieldOptions wanted;
  wanted.tint = "dye";
  EXPECT_EQ(latch.apply(wanted, 0.0).tint_reference, 0.0f);
  DensityFields built;
  built.tint_reference = 2.0f;
  latch.remember(wanted, built, 0.5);
  EXPECT_EQ(latch.apply(wanted, 0.6).tint_reference, 2.0f);
  built.tint_reference = 1.0f;  // the dye has spread: a later frame alone would have scaled to 1 g/L
  latch.remember(latch.apply(wanted, 0.7), built, 0.7);
  EXPECT_EQ(latch.apply(wanted, 0.8).tint_reference, 2.0f);
  EXPECT_EQ(latch.apply(wanted, 0.1).tint_reference, 0.0f) << "an earlier time: another run";
  FieldOptions salt = wanted;
  salt.tint = "salt";
  EXPECT_EQ(latch.apply(salt, 0.8).tint_reference, 0.0f);
  FieldOptions given = wanted;
  given.tint_reference = 5.0f;
  EXPECT_EQ(latch.apply(given, 0.8).tint_reference, 5.0f);
  // A frame drawn at a given reference latches nothing: back to automatic, the automatic one holds.
  built.tint_reference = 5.0f;
  latch.remember(given, built, 0.9);
  EXPECT_EQ(latch.apply(wanted, 1.0).tint_reference, 2.0f);
  TintLatch fresh;
  fresh.remember(given, built, 0.9);
  EXPECT_EQ(fresh.apply(wanted, 1.0).tint_reference, 0.0f);
  FieldOptions none;
  EXPECT_EQ(latch.apply(none, 0.8).tint_reference, 0.0f);
}

TEST(ThawCli, InfoNamesTheRenderer) {
  TempDir dir("cli-info-render");
  const auto r = run_thaw("info", dir);
  ASSERT_TRUE(r.exited);
  EXPECT_NE(r.out.find("renderer: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("OpenGL ES"), std::string::npos) << r.out;
}

TEST(ThawCli, SceneDocMatchesTheCommittedReference) {
  TempDir dir("cli-scene-doc");
  const auto r = run_thaw("scene-doc", dir);
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  const std::string committed = testing::read_file_bytes(fs::path(THAW_SOURCE_DIR) / "docs" / "SCENES.md");
  ASSERT_FALSE(committed.empty());
  EXPECT_TRUE(r.out == committed) << "docs/SCENES.md is out of date: regenerate it with `thaw scene-doc`";
}

}  // namespace
}  // namespace thaw
