// Device choice and kernel builds: errors say what was looked for and where a kernel failed.
#include "sim/cl_runtime.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include "sim/error.h"
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
  for (const char* stage :
       {"grid.cl", "boundary.cl", "density.cl", "forces.cl", "integrate.cl", "step_limits.cl", "heat.cl", "dfsph.cl"})
    EXPECT_NO_THROW(
        cl().build({"sph_kernel.h", "grid_common.h", "sph_lanes.h", "thermal_law.h", "dryer_model.h",
                    "heat_params.h", "fluid_params.h", stage},
                   "-DKERNEL_W=cubic_spline_w -DKERNEL_GRAD=cubic_spline_grad_factor -DTHAW_EOS_TAIT"))
        << stage;
}

}  // namespace
}  // namespace thaw
