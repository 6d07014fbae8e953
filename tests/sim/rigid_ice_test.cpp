// Rigid ice in the solver: bodies from the labelling, momentum exchanged with the water, contacts,
// splitting, resuming from state files.
#include "sim/rigid_ice.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/error.h"
#include "sim/metrics.h"
#include "sim/solver.h"
#include "sim/state_file.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;
using testing::TempDir;

Json materials(double viscosity = 1e-3) {
  Json m = Json::parse(R"({
    "water": {"kind": "fluid", "density": 1000, "viscosity": 1e-3, "conductivity": 0.56, "specific_heat": 4217},
    "ice": {"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050, "melts_into": "water"},
    "wall": {"kind": "solid", "density": 2500, "conductivity": 1.0, "specific_heat": 840}
  })");
  m["water"]["viscosity"] = viscosity;
  return m;
}

Json box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return {{"min", {x0, y0, z0}}, {"max", {x1, y1, z1}}};
}

// A ball of water in zero gravity with no walls and an ice block inside it: nothing outside the water
// and the ice can push them, so their total momentum must stay what it was. Without viscosity: the
// water's own viscosity term (k m_j / rho_j, forces.cl) is symmetric only where neighbours' densities
// agree, which would blur what this measures (measured: 0.3 % of the ice's momentum over 300 steps
// with it, against round-off without).
Json blob_scene() {
  return {
      {"name", "rigid-blob"},
      {"domain", box(-0.1, -0.1, -0.1, 0.14, 0.14, 0.14)},
      {"gravity", {0, 0, 0}},
      {"spacing", 0.004},
      {"solver", {{"speed_of_sound", 5.0}, {"artificial_viscosity", 0.0}, {"boundary_viscosity", 0.0}}},
      {"heat", {{"enabled", false}}},
      {"materials", materials(0.0)},
      {"fluids", {{{"material", "water"}, {"box", box(0, 0, 0, 0.04, 0.04, 0.04)}}}},
      {"ice",
       {{{"material", "ice"}, {"box", box(0.012, 0.012, 0.012, 0.028, 0.028, 0.028)}, {"motion", "free"}}}}};
}

Eigen::Vector3d momentum(const Solver& s) {
  // Water: physical mass; ice: its body's momentum (the particles carry the rigid velocity field).
  const HostParticles p = s.particles();
  Eigen::Vector3d P = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.phase[i] == std::uint8_t(Phase::Water))
      P += double(p.position[i][3]) * Eigen::Vector3d(p.velocity[i][0], p.velocity[i][1], p.velocity[i][2]);
  for (const IceBody& b : s.rigid_ice()->bodies()) P += b.body.mass * b.body.velocity;
  return P;
}

class RigidIceTest : public ClSuite {};

TEST_F(RigidIceTest, IceAndWaterKeepTheirTotalMomentumWithoutGravity) {
  const Scene scene = scene_from_json(blob_scene());
  SimState st = initial_state(scene);
  // Push the ice: 5 cm/s along x and a spin about z.
  const Eigen::Vector3d c(0.02, 0.02, 0.02);
  for (std::size_t i = 0; i < st.particles.size(); ++i) {
    if (st.particles.phase[i] != std::uint8_t(Phase::Ice)) continue;
    const Eigen::Vector3d x(st.particles.position[i][0], st.particles.position[i][1],
                            st.particles.position[i][2]);
    const Eigen::Vector3d v = Eigen::Vector3d(0.05, 0, 0) + Eigen::Vector3d(0, 0, 2.0).cross(x - c);
    st.particles.velocity[i] = {float(v.x()), float(v.y()), float(v.z()), 0.f};
  }
  Solver solver(cl(), scene, st);
  solver.warm_up();
  ASSERT_TRUE(solver.rigid_ice());
  ASSERT_EQ(solver.rigid_ice()->bodies().size(), 1u);
  const RigidBody& start = solver.rigid_ice()->bodies()[0].body;
  EXPECT_NEAR(start.velocity.x(), 0.05, 1e-6);
  EXPECT_NEAR(start.angular_velocity().z(), 2.0, 1e-4);
  const Eigen::Vector3d P0 = momentum(solver);
  const double scale = start.mass * 0.05;
  for (int k = 0; k < 300; ++k) solver.step();
  const RigidBody& now = solver.rigid_ice()->bodies()[0].body;
  const Eigen::Vector3d P1 = momentum(solver);
  std::printf("ice velocity %.4f -> %.4f m/s, spin %.3f -> %.3f rad/s, momentum change %.3g of the ice's\n",
              0.05, now.velocity.x(), 2.0, now.angular_velocity().z(), (P1 - P0).norm() / scale);
  EXPECT_LT(now.velocity.x(), 0.05);  // the water drags the ice ...
  EXPECT_GT(now.velocity.x(), 0.0);
  EXPECT_LT((P1 - P0).norm(), 1e-5 * scale);             // ... and takes up exactly what the ice loses
  EXPECT_LT(std::abs(now.angular_velocity().z()), 2.0);  // the spin is damped, never pumped
}

}  // namespace
}  // namespace thaw
