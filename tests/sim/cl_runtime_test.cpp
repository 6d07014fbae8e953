// Device choice and kernel builds: errors say what was looked for and where a kernel failed.
#include "sim/cl_runtime.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sim/error.h"
#include "sim/scene.h"
#include "sim/solver.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ClRuntime, DefaultDeviceIsFound) {
  const DeviceInfo d = choose_device("");
  EXPECT_FALSE(d.name.empty());
  EXPECT_FALSE(list_devices().empty());
}

TEST(ClRuntime, UnknownDeviceSaysWhatWasLookedForAndWhatExists) {
  const std::string msg = error_of([] { choose_device("no-such-device-xyz"); });
  EXPECT_NE(msg.find("no-such-device-xyz"), std::string::npos) << msg;
  EXPECT_NE(msg.find(list_devices().front().name), std::string::npos) << msg;
  EXPECT_NE(error_of([] { choose_device("7:9"); }).find("7:9"), std::string::npos);
}

TEST(ClRuntime, EnvironmentVariableChoosesTheDevice) {
  ::setenv("THAW_DEVICE", "no-such-device-xyz", 1);
  const std::string msg = error_of([] { choose_device(""); });
  ::unsetenv("THAW_DEVICE");
  EXPECT_NE(msg.find("THAW_DEVICE"), std::string::npos) << msg;
}

class KernelBuild : public testing::ClSuite {};

TEST_F(KernelBuild, FailedBuildNamesTheFileAndShowsTheLog) {
  const std::string broken = "kernel void k(global float* x) {\n  x[0] = undefined_name;\n}\n";
  const std::string msg = error_of([&] { cl().build_sources({{"sim/kernels/broken.cl", broken}}); });
  EXPECT_NE(msg.find("sim/kernels/broken.cl"), std::string::npos) << msg;
  EXPECT_NE(msg.find("undefined_name"), std::string::npos) << "the build log is part of the message: " << msg;
  EXPECT_NE(msg.find("broken.cl:2"), std::string::npos) << "the log points at the line: " << msg;
}

TEST_F(KernelBuild, MissingEmbeddedFileIsNamed) {
  const std::string msg = error_of([&] { cl().build({"nope.cl"}); });
  EXPECT_NE(msg.find("sim/kernels/nope.cl"), std::string::npos) << msg;
}

TEST_F(KernelBuild, EveryEmbeddedStageBuilds) {
  for (const char* stage : {"grid.cl", "boundary.cl", "density.cl", "forces.cl", "integrate.cl",
                            "step_limits.cl", "heat.cl", "dfsph.cl"})
    EXPECT_NO_THROW(
        cl().build(neighbour_program({"thermal_law.h", "dryer_model.h", "heat_params.h", "fluid_params.h",
                                      "dfsph_columns.h", "wrapped_walk.h", stage}),
                   "-DKERNEL_W=cubic_spline_w -DKERNEL_GRAD=cubic_spline_grad_factor -DTHAW_EOS_TAIT"))
        << stage;
  // The surface stage, both models (sim/surface_stage.cpp).
  for (const char* model : {"-DTHAW_AREA_BRACKBILL1992", "-DTHAW_AREA_ORTHMANN2013"})
    EXPECT_NO_THROW(cl().build(neighbour_program({"wrapped_walk.h", "surface_params.h", "surface.cl"}),
                               std::string("-DTHAW_REACH=1 -DTHAW_VW=8 ") + model))
        << model;
  // The tension stage, its three models (sim/tension_stage.cpp).
  const std::pair<const char*, const char*> models[] = {
      {"tension_akinci2013.cl", "-DTHAW_TENSION_AKINCI2013"},
      {"tension_iwasaki2010.cl", "-DTHAW_TENSION_IWASAKI2010"},
      {"tension_brackbill1992.cl",
       "-DTHAW_TENSION_BRACKBILL1992 -DTHAW_FIT_REACH=2 -DTHAW_TENSION_ADHESION"}};
  for (const auto& [file, model] : models)
    EXPECT_NO_THROW(cl().build(neighbour_program({"tension_params.h", "tension.cl", file}),
                               std::string("-DTHAW_REACH=1 -DTHAW_VW=8 ") + model))
        << model;
}

// NVIDIA's compiler ignores #line and counts lines of the joined source ("<kernel>:12:5"); the message
// names the embedded file and its own line instead.
TEST(ClRuntime, VendorLogPositionsNameTheEmbeddedFile) {
  const std::vector<ClRuntime::Source> sources = {{"sim/kernels/a.h", "int a;\nint b;\n"},
                                                  {"sim/kernels/b.cl", "kernel void k() {\n  x;\n}"}};
  // Joined: 1 #line a.h, 2-3 a.h, 4 (blank), 5 #line b.cl, 6-8 b.cl.
  const std::string log = "<kernel>:3:5: warning: w\n<kernel>:7:3: error: use of undeclared identifier 'x'\n";
  EXPECT_EQ(
      annotate_build_log(log, sources),
      "sim/kernels/a.h:2:5: warning: w\nsim/kernels/b.cl:2:3: error: use of undeclared identifier 'x'\n");
  EXPECT_EQ(annotate_build_log("no positions: <kernel>:x", sources), "no positions: <kernel>:x");
  EXPECT_EQ(annotate_build_log("sim/kernels/b.cl:2:3: pocl's own", sources),
            "sim/kernels/b.cl:2:3: pocl's own");
}

// Every program that the scenes build, with the options they build it with, passes a strict OpenCL C
// 1.2 compiler (clang, -pedantic-errors): pocl accepts clang's extensions (variadic macros, for one),
// and NVIDIA's compiler refused them, so every kernel failed to build on a GPU.
TEST_F(KernelBuild, EveryProgramIsPortableOpenClC) {
  namespace fs = std::filesystem;
  const char* clang = "clang-15";
  ASSERT_EQ(std::system((std::string("command -v ") + clang + " >/dev/null").c_str()), 0)
      << clang << " is missing (scripts/debian-packages.txt installs it)";
  std::map<std::string, std::string> programs;  // options + source -> options
  cl().set_build_observer([&](const std::string& source, const std::string& options) {
    programs.emplace(options + "\n" + source, options);
  });
  struct Variant {
    std::string scene;
    std::vector<std::string> sets;
  };
  std::vector<Variant> variants;
  for (const auto& e : fs::directory_iterator(fs::path(THAW_SOURCE_DIR) / "configs"))
    if (e.path().extension() == ".json") {
      const std::string name = e.path().stem().string();
      variants.push_back({name, {}});
      variants.push_back({name, {"solver.pressure=dfsph"}});
    }
  variants.push_back({"dam-break", {"solver.pressure=dfsph", "solver.boundary_pressure=akinci2012"}});
  variants.push_back({"dam-break", {"solver.kernel=wendland_c2", "solver.support_ratio=3"}});
  variants.push_back(
      {"ice-on-plate", {"domain.walls=[]", "solver.flow=false", "solver.periodic=[\"x\",\"y\"]"}});
  // A surface-active substance beside a salt that lowers the melting point (substance.cl's THAW_SURFACE with
  // THAW_MELT_SHIFT and THAW_REJECT).
  variants.push_back({"salt-on-ice", {"substances.dye={\"kind\": \"surface_active\"}"}});
  // A coating there (THAW_DEPOSIT with THAW_MELT_SHIFT and THAW_REJECT); wash-the-plate has one beside a
  // surface-active detergent.
  variants.push_back({"salt-on-ice", {"substances.dye={\"kind\": \"coating\"}"}});
  // Tension lowered by wash-the-plate's detergent, each model (THAW_TENSION_LOWERED, THAW_TENSION_LAW).
  for (const char* model : {"akinci2013", "iwasaki2010", "brackbill1992"})
    variants.push_back({"wash-the-plate", {std::string("tension.model=") + model}});
  // Tension, both models, beside free ice (rigid.cl takes the adhesion's reaction).
  variants.push_back({"default", {"tension.model=akinci2013"}});
  variants.push_back({"default", {"tension.model=iwasaki2010", "solver.pressure=dfsph"}});
  variants.push_back({"default", {"tension.model=brackbill1992"}});
  // Air beside the meltwater: the multiphase passes (both models), eq 8's buoyancy, and room air through an
  // open top.
  const std::string air_material =
      "materials.air={\"kind\": \"air\", \"density\": 1.2, \"viscosity\": 1.8e-5, \"conductivity\": 0.025, "
      "\"specific_heat\": 1006}";
  variants.push_back(
      {"ice-on-plate",
       {air_material, "air={\"material\": \"air\", \"artificial_buoyancy\": 0.1}", "domain.open=[\"+z\"]"}});
  variants.push_back(
      {"ice-on-plate", {air_material, "air={\"material\": \"air\"}", "solver.multiphase=domaradzki_martyn"}});
  for (const auto& v : variants) {
    SCOPED_TRACE(v.scene);
    try {
      const Scene scene = load_scene(v.scene, v.sets);
      Solver solver(cl(), scene, initial_state(scene));
      solver.step();
    } catch (const Error& e) {
      ADD_FAILURE() << e.what();
    }
  }
  cl().set_build_observer(nullptr);
  ASSERT_GE(programs.size(), 10u);
  testing::TempDir dir("portable-cl");
  int k = 0;
  for (const auto& [key, options] : programs) {
    const std::string file = dir / ("p" + std::to_string(k++) + ".cl");
    testing::write_text(file, key.substr(options.size() + 1));
    const std::string log = dir / "clang.log";
    // A device defines __OPENCL_VERSION__ (OpenCL C 1.2, 6.10); clang alone does not.
    const std::string cmd = std::string(clang) +
                            " -x cl -fsyntax-only -pedantic-errors -Werror -Wno-unused-command-line-argument"
                            " -D__OPENCL_VERSION__=120 -Xclang -finclude-default-header " +
                            options + " " + testing::shell_quote(file) + " >" + testing::shell_quote(log) +
                            " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << "options '" << options << "':\n"
                                           << testing::read_file_bytes(log);
  }
  std::printf("%zu programs checked with %s\n", programs.size(), clang);
}

}  // namespace
}  // namespace thaw
