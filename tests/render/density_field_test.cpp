#include "render/density_field.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "sim/error.h"
#include "tests/render/lattice_snapshot.h"

namespace thaw {
namespace {

// Field options with `n` nodes along the longest axis.
FieldOptions cells(int n) {
  FieldOptions o;
  o.max_cells = n;
  return o;
}

constexpr float kSpacing = 0.01f;
const Eigen::Vector3f kCentre(0.1f, -0.2f, 0.3f);

void add(RenderSnapshot& s, const Eigen::Vector3f& x, Phase phase) { testing::add_particle(s, x, phase); }
void add_sphere(RenderSnapshot& s, float radius, Phase phase) {
  testing::add_lattice_sphere(s, kCentre, kSpacing, radius, phase);
}
void add_box(RenderSnapshot& s, const Eigen::Vector3f& corner, int nx, int ny, int nz, Phase phase) {
  testing::add_lattice_box(s, corner, kSpacing, nx, ny, nz, phase);
}

RenderSnapshot ice_sphere(float radius) {
  RenderSnapshot s;
  s.spacing = kSpacing;
  add_sphere(s, radius, Phase::Ice);
  return s;
}

float max_of(const std::vector<float>& v) { return v.empty() ? 0.0f : *std::max_element(v.begin(), v.end()); }

// Distance from kCentre along `dir` at which the field falls through `iso`, by bisection.
float surface_radius(const DensityFields& f, const std::vector<float>& v, Eigen::Vector3f dir, float r_max) {
  dir.normalize();
  float lo = 0, hi = r_max;
  for (int it = 0; it < 40; ++it) {
    const float mid = 0.5f * (lo + hi);
    (sample_field(f.grid, v, kCentre + mid * dir) > f.iso ? lo : hi) = mid;
  }
  return 0.5f * (lo + hi);
}

TEST(DensityField, SphereIsOneInsideAndZeroOutside) {
  const float R = 10;
  const DensityFields f = build_density_fields(ice_sphere(R), {});
  for (float r : {0.0f, 0.3f, 0.6f, 0.8f}) {
    for (const Eigen::Vector3f& dir :
         {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0.3f, -0.5f, 0.8f).normalized()}) {
      EXPECT_NEAR(sample_field(f.grid, f.ice, kCentre + r * R * kSpacing * dir), 1.0f, 0.03f) << "r " << r;
    }
  }
  // Beyond the outermost centres (R - 1/2 spacings on average) the field falls off within ~1.5 spacings.
  for (const Eigen::Vector3f& dir : {Eigen::Vector3f(0, 1, 0), Eigen::Vector3f(-1, 1, 1).normalized()}) {
    EXPECT_LT(sample_field(f.grid, f.ice, kCentre + (R + 1.5f) * kSpacing * dir), 0.03f);
    EXPECT_EQ(sample_field(f.grid, f.ice, kCentre + 100 * R * kSpacing * dir), 0.0f);
  }
  EXPECT_EQ(max_of(f.water), 0.0f);
  EXPECT_EQ(max_of(f.solid), 0.0f);
  EXPECT_EQ(f.ice.size(), f.grid.size());
  EXPECT_EQ(f.iso, 0.5f);
}

TEST(DensityField, SphereSurfaceLiesAtItsRadius) {
  const float R = 10;
  const DensityFields f = build_density_fields(ice_sphere(R), {});
  float worst = 0, sum = 0;
  int n = 0;
  for (const Eigen::Vector3f& dir :
       {Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, -1, 0), Eigen::Vector3f(0, 0, 1),
        Eigen::Vector3f(1, 1, 0), Eigen::Vector3f(1, -1, 1), Eigen::Vector3f(0.2f, 0.7f, -0.4f),
        Eigen::Vector3f(-0.9f, 0.1f, 0.35f), Eigen::Vector3f(0.5f, 0.5f, -1)}) {
    const float r = surface_radius(f, f.ice, dir, (R + 5) * kSpacing) / kSpacing;
    EXPECT_NEAR(r, R, 0.5f) << "direction " << dir.transpose();
    worst = std::max(worst, std::abs(r - R));
    sum += r;
    ++n;
  }
  // Lattice facets make single directions differ; on average the surface is where the particles' volume
  // ends, less the smoothing's sigma^2 / R.
  EXPECT_NEAR(sum / float(n), R, 0.15f);
  std::printf("[ info ] sphere R = %g spacings: surface radius %.3f on average, all within %.3f of R\n", R,
              sum / float(n), worst);
}

TEST(DensityField, GridCoversParticlesWithinMaxCells) {
  RenderSnapshot s;
  s.spacing = kSpacing;
  add_box(s, Eigen::Vector3f(0, 0, 0), 300, 40, 40, Phase::Water);
  for (int max_cells : {16, 64, 128}) {
    const DensityFields f = build_density_fields(s, cells(max_cells));
    EXPECT_EQ(f.grid.nx, max_cells);
    EXPECT_LE(f.grid.ny, max_cells);
    EXPECT_LE(f.grid.nz, max_cells);
    const Eigen::Vector3f top =
        f.grid.origin +
        f.grid.cell * Eigen::Vector3f(float(f.grid.nx - 1), float(f.grid.ny - 1), float(f.grid.nz - 1));
    for (int a = 0; a < 3; ++a) {
      EXPECT_LT(f.grid.origin[a], -kSpacing);
      EXPECT_GT(top[a], s.bounds_max[a] + kSpacing);
    }
    // Deep inside the box the field is 1 while the grid resolves the box's thickness.
    if (max_cells >= 64) {
      EXPECT_NEAR(sample_field(f.grid, f.water, Eigen::Vector3f(150, 20, 20) * kSpacing), 1.0f, 0.03f)
          << max_cells;
    }
  }
  // A small particle set is not resolved finer than half a spacing.
  const DensityFields small = build_density_fields(ice_sphere(3), cells(128));
  EXPECT_GE(small.grid.cell, 0.5f * kSpacing * 0.999f);
  EXPECT_LT(small.grid.nx, 40);
}

TEST(DensityField, PhasesGoToTheirOwnFields) {
  RenderSnapshot s;
  s.spacing = kSpacing;
  add_box(s, Eigen::Vector3f(0, 0, 0), 20, 10, 15, Phase::Water);
  const DensityFields water_only = build_density_fields(s, {});
  EXPECT_EQ(max_of(water_only.ice), 0.0f);
  EXPECT_EQ(max_of(water_only.solid), 0.0f);
  EXPECT_NEAR(max_of(water_only.water), 1.0f, 0.03f);

  add_box(s, Eigen::Vector3f(0, 0, -5 * kSpacing), 20, 10, 3, Phase::Solid);
  add(s, Eigen::Vector3f(1, 1, 1), Phase::Air);  // not drawn, and does not stretch the grid
  const DensityFields f = build_density_fields(s, {});
  EXPECT_EQ(max_of(f.ice), 0.0f);
  EXPECT_NEAR(sample_field(f.grid, f.solid, Eigen::Vector3f(10, 5, -4) * kSpacing), 1.0f, 0.05f);
  EXPECT_LT(sample_field(f.grid, f.water, Eigen::Vector3f(10, 5, -4) * kSpacing), 0.01f);
  EXPECT_NEAR(sample_field(f.grid, f.water, Eigen::Vector3f(10, 5, 7) * kSpacing), 1.0f, 0.03f);
  const Eigen::Vector3f top =
      f.grid.origin + f.grid.cell * Eigen::Vector3f(float(f.grid.nx), float(f.grid.ny), float(f.grid.nz));
  EXPECT_LT(top.maxCoeff(), 0.5f);
}

// Coloured by a substance: the dye field is the water's concentration over the reference (the most any water
// particle holds unless given), the stain a coating's deposit over its capacity on the solids and ice.
TEST(DensityField, ATintBuildsTheDyeAndStainFields) {
  RenderSnapshot s;
  s.spacing = kSpacing;
  add_box(s, Eigen::Vector3f(0, 0, 0), 20, 10, 10, Phase::Water);  // x < 0.1: 2 g/L, x >= 0.1: 0.5 g/L
  add_box(s, Eigen::Vector3f(0, 0, -5 * kSpacing), 20, 10, 3, Phase::Solid);  // x < 0.1: stained half full
  std::vector<float> c(s.position.size()), deposit(s.position.size());
  for (std::size_t p = 0; p < s.position.size(); ++p) {
    const bool left = s.position[p].x() < 0.1f - 1e-4f;
    if (static_cast<Phase>(s.phase[p]) == Phase::Water) c[p] = left ? 2.0f : 0.5f;
    if (static_cast<Phase>(s.phase[p]) == Phase::Solid) deposit[p] = left ? 1e-4f : 0.0f;
  }
  s.substances = {{"ink", c}};
  s.substance_colours = {{0.2f, 0.4f, 0.6f}};
  s.deposits = {{"ink", deposit}};
  s.deposit_capacity = {2e-4f};

  const DensityFields plain = build_density_fields(s, {});
  EXPECT_TRUE(plain.dye.empty());
  EXPECT_TRUE(plain.stain.empty());

  FieldOptions o;
  o.tint = "ink";
  const DensityFields f = build_density_fields(s, o);
  EXPECT_FLOAT_EQ(f.tint_reference, 2.0f);
  EXPECT_EQ(f.tint_colour, (std::array<float, 3>{0.2f, 0.4f, 0.6f}));
  ASSERT_EQ(f.dye.size(), f.grid.size());
  ASSERT_EQ(f.stain.size(), f.grid.size());
  const Eigen::Vector3f left(5, 5, 5), right(15, 5, 5), floor_left(5, 5, -4), floor_right(15, 5, -4);
  EXPECT_NEAR(sample_field(f.grid, f.dye, left * kSpacing), 1.0f, 0.03f);
  EXPECT_NEAR(sample_field(f.grid, f.dye, right * kSpacing), 0.25f, 0.01f);
  EXPECT_LT(sample_field(f.grid, f.dye, floor_left * kSpacing), 0.01f) << "dye only in the water";
  EXPECT_NEAR(sample_field(f.grid, f.stain, floor_left * kSpacing), 0.5f, 0.03f);
  EXPECT_LT(sample_field(f.grid, f.stain, floor_right * kSpacing), 0.01f);
  EXPECT_LT(sample_field(f.grid, f.stain, left * kSpacing), 0.01f) << "stain only on solids and ice";

  o.tint_reference = 4.0f;
  const DensityFields given = build_density_fields(s, o);
  EXPECT_FLOAT_EQ(given.tint_reference, 4.0f);
  EXPECT_NEAR(sample_field(given.grid, given.dye, left * kSpacing), 0.5f, 0.02f);

  // Nothing dissolved or deposited: nothing to tint.
  std::fill(s.substances[0].second.begin(), s.substances[0].second.end(), 0.0f);
  std::fill(s.deposits[0].second.begin(), s.deposits[0].second.end(), 0.0f);
  o.tint_reference = 0;
  const DensityFields clear = build_density_fields(s, o);
  EXPECT_TRUE(clear.dye.empty());
  EXPECT_TRUE(clear.stain.empty());

  o.tint = "salt";
  EXPECT_THROW(
      {
        try {
          build_density_fields(s, o);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("'salt'"), std::string::npos) << e.what();
          throw;
        }
      },
      Error);
}

TEST(DensityField, BuildIsDeterministic) {
  RenderSnapshot s = ice_sphere(8);
  add_box(s, kCentre + Eigen::Vector3f(0.05f, 0, 0), 12, 9, 7, Phase::Water);
  // Jitter the particles off the lattice, as a running simulation does.
  std::uint32_t state = 12345;
  for (Eigen::Vector3f& x : s.position) {
    for (int c = 0; c < 3; ++c) {
      state = state * 1664525u + 1013904223u;
      x[c] += kSpacing * 0.3f * (float(state >> 8) / float(1u << 24) - 0.5f);
    }
  }
  const DensityFields a = build_density_fields(s, {});
  const DensityFields b = build_density_fields(s, {});
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const DensityFields c = build_density_fields(s, {});
  omp_set_num_threads(3);
  const DensityFields d = build_density_fields(s, {});
  omp_set_num_threads(threads);
  for (const DensityFields* other : {&b, &c, &d}) {
    EXPECT_EQ(a.ice, other->ice);
    EXPECT_EQ(a.water, other->water);
    EXPECT_EQ(a.solid, other->solid);
  }
}

TEST(DensityField, EmptySnapshotGivesZeroField) {
  RenderSnapshot s;
  s.spacing = kSpacing;
  const DensityFields f = build_density_fields(s, {});
  EXPECT_GE(f.grid.size(), 1u);
  EXPECT_EQ(f.ice.size(), f.grid.size());
  EXPECT_EQ(max_of(f.ice) + max_of(f.water) + max_of(f.solid), 0.0f);
  EXPECT_EQ(sample_field(f.grid, f.ice, Eigen::Vector3f::Zero()), 0.0f);
}

TEST(DensityField, RejectsBadInput) {
  RenderSnapshot s = ice_sphere(2);
  EXPECT_THROW(build_density_fields(s, cells(4)), Error);
  s.spacing = 0;
  EXPECT_THROW(build_density_fields(s, {}), Error);
  s.spacing = kSpacing;
  s.phase.pop_back();
  EXPECT_THROW(build_density_fields(s, {}), Error);
}

// Not a pass/fail check: prints the build time so runs can be compared (docs/ARCHITECTURE.md: CIC of 100k
// particles into 128^3 took 22-32 ms on this machine).
TEST(DensityField, BuildTimeAt128Cubed) {
  for (int count : {25000, 100000}) {
    // Ice and water spread through a cube 64 spacings wide, so the grid is the full 128^3.
    RenderSnapshot s;
    s.spacing = kSpacing;
    std::uint32_t state = 7;
    auto uniform = [&] {
      state = state * 1664525u + 1013904223u;
      return float(state >> 8) / float(1u << 24);
    };
    for (int p = 0; p < count; ++p) {
      const Eigen::Vector3f x(uniform(), uniform(), uniform());
      add(s, 64 * kSpacing * x, p % 2 ? Phase::Water : Phase::Ice);
    }
    double best = 1e9;
    DensityFields f;
    for (int run = 0; run < 5; ++run) {
      const auto t0 = std::chrono::steady_clock::now();
      f = build_density_fields(s, cells(128));
      best = std::min(
          best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("[ info ] density fields: %d particles into %dx%dx%d: %.1f ms (best of 5, %d threads)\n",
                count, f.grid.nx, f.grid.ny, f.grid.nz, best, omp_get_max_threads());
    EXPECT_EQ(f.grid.nx, 128);
  }
}

}  // namespace
}  // namespace thaw
