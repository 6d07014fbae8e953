// `thaw bench throughput`: its scene is valid at any requested size, and at small sizes the bench runs
// and its hand-written reference loops agree with the device (the timings are not asserted).
#include <gtest/gtest.h>

#include <cmath>

#include "bench/throughput.h"
#include "sim/error.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;

// Walls need whole numbers of spacings along walled extents; the bench derives its spacing from the
// particle count, so it must round the tank to it. Once it did not, and every default size was refused.
TEST(ThroughputScene, IsValidAtAnySize) {
  for (std::size_t n : {1000u, 25000u, 77777u, 100000u, 123457u, 400000u, 1000000u}) {
    Scene scene;
    ASSERT_NO_THROW(scene = throughput_scene(n)) << n;
    const double dx = scene.spacing;
    const Eigen::Vector3d extent = scene.domain.max - scene.domain.min;
    for (int a = 0; a < 2; ++a) {
      const double cells = extent[a] / dx;
      EXPECT_NEAR(cells, std::round(cells), 1e-6) << n << ", axis " << a;
    }
    EXPECT_NEAR(extent.x(), 1.0, dx) << n;
    EXPECT_NEAR(extent.y(), 0.5, dx) << n;
  }
}

class ThroughputBench : public ClSuite {};

TEST_F(ThroughputBench, RunsAtSmallSizesAndAgreesWithItsReferenceLoops) {
  ThroughputOptions o;
  o.sizes = {3000, 7000};
  o.steps = 2;
  const Json r = bench_throughput(cl(), o, false);
  ASSERT_EQ(r["sizes"].size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const Json& row = r["sizes"][k];
    const double fluid = row["fluid_particles"].get<double>();
    EXPECT_NEAR(fluid / double(o.sizes[k]), 1.0, 0.1) << row.dump();
    EXPECT_GT(row["stage_us"]["step"].get<double>(), 0.0);
    // The lanes loop sums in the device's order: bitwise on pocl, which rounds each product as the loop
    // does; a GPU compiler fuses multiply-adds (-cl-mad-enable), 3e-7 on an NVIDIA H200. The scalar loop
    // within float rounding.
    const double lanes = row["reference_lanes_max_rel_diff_rho"].get<double>();
    if (cl().info().type == "CPU")
      EXPECT_EQ(lanes, 0.0);
    else
      EXPECT_LT(lanes, 1e-5);
    EXPECT_LT(row["reference_scalar_max_rel_diff_rho"].get<double>(), 1e-5);
    EXPECT_LT(row["reference_heat_max_rel_diff_q"].get<double>(), 1e-5);
  }
}

}  // namespace
}  // namespace thaw
