// The device neighbour grid (sim/kernels/grid.cl): the sort, the cell ranges, and the neighbour sets
// that a walk over the cells as FOR_EACH_NEIGHBOUR (sim/kernels/grid_common.h) does finds, against
// brute force, on random, clustered and boundary-touching particles; then the device density against
// a host sum over the brute-force neighbours.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "sim/kernels/sph_kernel.h"
#include "sim/solver.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;

constexpr double kRho0 = 1000.0;

// A scene without walls (every particle is fluid). Spacing 2^-5 m makes the cell (H = 2 dx, one cell of
// reach: NeighbourGrid in sim/neighbour_grid.h) and every domain face exact binary fractions, so "on a
// cell border" is exact.
Scene grid_scene(double spacing = 0.03125, Eigen::Vector3d max = {0.5, 0.375, 0.25}) {
  Json doc = {
      {"name", "neighbour-grid-test"},
      {"domain", {{"min", {0.0, 0.0, 0.0}}, {"max", {max.x(), max.y(), max.z()}}}},
      {"gravity", {0.0, 0.0, -9.81}},
      {"spacing", spacing},
      {"materials",
       {{"water",
         {{"kind", "fluid"},
          {"density", kRho0},
          {"viscosity", 1e-3},
          {"conductivity", 0.56},
          {"specific_heat", 4217}}}}},
      {"fluids",
       {{{"material", "water"}, {"box", {{"min", {0.0, 0.0, 0.0}}, {"max", {0.125, 0.125, 0.125}}}}}}},
  };
  return scene_from_json(doc);
}

// A state holding exactly `positions`, all water of mass rho0 dx^3, with ids in input order.
SimState state_with(const Scene& scene, const std::vector<Eigen::Vector3f>& positions) {
  SimState st = initial_state(scene);
  const auto mass = static_cast<float>(kRho0 * std::pow(scene.spacing, 3));
  st.particles.resize(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const auto& x = positions[i];
    st.particles.position[i] = {x.x(), x.y(), x.z(), mass};
    st.particles.velocity[i] = {0.f, 0.f, 0.f, 0.f};
    st.particles.density[i] = 0.f;
    st.particles.phase[i] = static_cast<std::uint8_t>(Phase::Water);
    st.particles.material[i] = 0;
    st.particles.id[i] = static_cast<std::uint32_t>(i);
  }
  return st;
}

Eigen::Vector3f clamp_to(const Scene& s, Eigen::Vector3f x) {
  return x.cwiseMax(s.domain.min.cast<float>()).cwiseMin(s.domain.max.cast<float>());
}

std::vector<Eigen::Vector3f> uniform_points(const Scene& s, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Eigen::Vector3f> out;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3f x;
    for (int a = 0; a < 3; ++a)
      x[a] = std::uniform_real_distribution<float>(float(s.domain.min[a]), float(s.domain.max[a]))(rng);
    out.push_back(clamp_to(s, x));
  }
  return out;
}

// A few tight Gaussian clusters: hundreds of particles per cell, one cluster on a domain corner.
std::vector<Eigen::Vector3f> clustered_points(const Scene& s, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  const float cell = 0.5f * float(s.spacing * s.solver.support_ratio);  // half a cell of H
  const Eigen::Vector3f lo = s.domain.min.cast<float>(), hi = s.domain.max.cast<float>();
  const std::vector<Eigen::Vector3f> centres = {
      lo + 0.3f * (hi - lo), lo + 0.7f * (hi - lo), {hi.x() * 0.5f, lo.y(), hi.z() * 0.4f}, hi};
  std::normal_distribution<float> g(0.0f, 0.4f * cell);
  std::vector<Eigen::Vector3f> out;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& c = centres[i % centres.size()];
    out.push_back(clamp_to(s, c + Eigen::Vector3f(g(rng), g(rng), g(rng))));
  }
  return out;
}

// Points on the domain's faces, edges and corners and on cell borders, each coordinate exactly.
std::vector<Eigen::Vector3f> boundary_points(const Scene& s, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  // Borders every half cell of H: every cell border of the grid, and the midlines between them.
  const float cell = 0.5f * float(s.spacing * s.solver.support_ratio);
  std::vector<Eigen::Vector3f> out;
  // The eight corners, exactly.
  for (int c = 0; c < 8; ++c)
    out.push_back({float((c & 1) ? s.domain.max.x() : s.domain.min.x()),
                   float((c & 2) ? s.domain.max.y() : s.domain.min.y()),
                   float((c & 4) ? s.domain.max.z() : s.domain.min.z())});
  std::uniform_int_distribution<int> pick(0, 3);
  while (out.size() < n) {
    Eigen::Vector3f x;
    for (int a = 0; a < 3; ++a) {
      const float lo = float(s.domain.min[a]), hi = float(s.domain.max[a]);
      const int borders = static_cast<int>(std::floor((hi - lo) / cell));
      switch (pick(rng)) {
        case 0:
          x[a] = lo;
          break;
        case 1:
          x[a] = hi;
          break;
        case 2:
          x[a] = lo + cell * float(std::uniform_int_distribution<int>(0, borders)(rng));
          break;
        default:
          x[a] = std::uniform_real_distribution<float>(lo, hi)(rng);
          break;
      }
    }
    out.push_back(clamp_to(s, x));
  }
  return out;
}

float dist2(const Float4& a, const Float4& b) {
  const float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

// Host copy of grid_cell() in sim/kernels/grid_common.h.
Eigen::Vector3i host_cell(const Solver::GridInfo& g, const Float4& p) {
  const float inv = 1.0f / g.cell;
  const int n[3] = {g.nx, g.ny, g.nz};
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a)
    c[a] = std::clamp(static_cast<int>(std::floor((p[a] - g.origin[a]) * inv)), 0, n[a] - 1);
  return c;
}

// Everything the checks compare, for one state.
void check_grid(ClRuntime& cl, const Scene& scene, const std::vector<Eigen::Vector3f>& points,
                const std::string& label) {
  SCOPED_TRACE(label);
  const SimState st = state_with(scene, points);
  const std::size_t n = points.size();
  Solver solver(cl, scene, st);
  const auto& g = solver.grid();
  const float H = solver.constants().support;
  ASSERT_GE(static_cast<float>(g.reach) * g.cell, H) << "the walk must cover the support";
  ASSERT_LE(static_cast<float>(g.reach) * g.cell, H * 1.00001f) << "cells barely larger than H / reach";
  solver.build_grid();
  const HostParticles p = solver.particles();
  const std::vector<std::uint32_t> starts = solver.cell_starts();
  const std::size_t ncells = std::size_t(g.nx) * g.ny * g.nz;
  ASSERT_EQ(p.size(), n);
  ASSERT_EQ(starts.size(), ncells + 1);

  // The ids are a permutation, and every particle kept its data through the gathers.
  std::vector<char> seen(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_LT(p.id[i], n);
    ASSERT_FALSE(seen[p.id[i]]) << "id " << p.id[i] << " appears twice";
    seen[p.id[i]] = 1;
    EXPECT_EQ(std::memcmp(p.position[i].data(), st.particles.position[p.id[i]].data(), sizeof(Float4)), 0)
        << "particle " << p.id[i] << " moved or lost its mass in the sort";
    EXPECT_EQ(p.phase[i], st.particles.phase[p.id[i]]);
  }

  // Cell ranges: start at 0, end at n, never decrease; every particle lies in its own cell's range,
  // so the keys are non-decreasing in sorted order.
  ASSERT_EQ(starts[0], 0u);
  ASSERT_EQ(starts[ncells], n);
  std::vector<std::uint32_t> key(n, 0xffffffffu);
  for (std::size_t k = 0; k < ncells; ++k) {
    ASSERT_LE(starts[k], starts[k + 1]) << "cell " << k;
    for (std::uint32_t i = starts[k]; i < starts[k + 1]; ++i) key[i] = static_cast<std::uint32_t>(k);
  }
  std::size_t cells_used = 0, most = 0;
  for (std::size_t k = 0; k < ncells; ++k) {
    cells_used += starts[k + 1] > starts[k];
    most = std::max<std::size_t>(most, starts[k + 1] - starts[k]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3i c = host_cell(g, p.position[i]);
    const auto expected = static_cast<std::uint32_t>((c.z() * g.ny + c.y()) * g.nx + c.x());
    ASSERT_EQ(key[i], expected) << "particle " << p.id[i] << " at (" << p.position[i][0] << ", "
                                << p.position[i][1] << ", " << p.position[i][2]
                                << ") sorted into the wrong cell";
    // Stable: the input was in id order, so equal keys keep increasing ids.
    if (i > 0 && key[i] == key[i - 1]) {
      EXPECT_LT(p.id[i - 1], p.id[i]) << "unstable sort in cell " << key[i];
    }
  }
  ::testing::Test::RecordProperty(label + "_cells_used", std::to_string(cells_used));
  ::testing::Test::RecordProperty(label + "_most_per_cell", std::to_string(most));

  // Neighbour sets: the cell walk against brute force.
  const float H2 = H * H;
  std::size_t pairs = 0;
  int mismatches = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3i c = host_cell(g, p.position[i]);
    std::vector<std::uint32_t> walked, brute;
    for (int dz = -g.reach; dz <= g.reach; ++dz) {
      const int z = c.z() + dz;
      if (z < 0 || z >= g.nz) continue;
      for (int dy = -g.reach; dy <= g.reach; ++dy) {
        const int y = c.y() + dy;
        if (y < 0 || y >= g.ny) continue;
        const int row = (z * g.ny + y) * g.nx;
        const std::uint32_t jb = starts[row + std::max(c.x() - g.reach, 0)];
        const std::uint32_t je = starts[row + std::min(c.x() + g.reach, g.nx - 1) + 1];
        for (std::uint32_t j = jb; j < je; ++j)
          if (dist2(p.position[i], p.position[j]) < H2) walked.push_back(p.id[j]);
      }
    }
    for (std::size_t j = 0; j < n; ++j)
      if (dist2(p.position[i], p.position[j]) < H2) brute.push_back(p.id[j]);
    std::sort(walked.begin(), walked.end());
    std::sort(brute.begin(), brute.end());
    pairs += brute.size();
    if (walked != brute && ++mismatches <= 5) {
      std::vector<std::uint32_t> missed;
      std::set_difference(brute.begin(), brute.end(), walked.begin(), walked.end(),
                          std::back_inserter(missed));
      std::ostringstream detail;
      detail.precision(9);
      for (const std::uint32_t id : missed) {
        const auto j = static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), id) - p.id.begin());
        const Eigen::Vector3i cj = host_cell(g, p.position[j]);
        detail << " id " << id << " at r/H = " << std::sqrt(dist2(p.position[i], p.position[j])) / H
               << ", cell offset (" << cj.x() - c.x() << ", " << cj.y() - c.y() << ", " << cj.z() - c.z()
               << ");";
      }
      ADD_FAILURE() << "particle " << p.id[i] << ": the grid walk finds " << walked.size()
                    << " neighbours (duplicates included), brute force " << brute.size()
                    << "; missed:" << detail.str();
    }
  }
  EXPECT_EQ(mismatches, 0) << "particles whose neighbour set differs from brute force";
  EXPECT_GT(pairs, n) << "the case should have neighbours beyond each particle itself";

  // Sorting sorted particles again keeps their order (stable, and deterministic).
  solver.build_grid();
  const HostParticles again = solver.particles();
  EXPECT_EQ(again.id, p.id);
  EXPECT_EQ(solver.cell_starts(), starts);

  // Device summation density against a host sum over the brute-force neighbours.
  solver.compute_density();
  const std::vector<float> rho = solver.densities();
  ASSERT_EQ(rho.size(), n);
  int bad = 0;
  for (std::size_t i = 0; i < n && bad < 5; ++i) {
    double sum = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const float r2 = dist2(again.position[i], again.position[j]);
      if (r2 < H2) sum += double(again.position[j][3]) * sph::cubic_spline_w(std::sqrt(r2), H);
    }
    if (std::abs(rho[i] - sum) > 1e-5 * sum) {
      ++bad;
      ADD_FAILURE() << "particle " << again.id[i] << ": device density " << rho[i] << ", host " << sum;
    }
  }
}

class NeighbourGrid : public ClSuite {};

TEST_F(NeighbourGrid, UniformRandomPointsMatchBruteForce) {
  const Scene s = grid_scene();
  check_grid(cl(), s, uniform_points(s, 3000, 1), "uniform");
}

TEST_F(NeighbourGrid, ClusteredPointsMatchBruteForce) {
  const Scene s = grid_scene();
  check_grid(cl(), s, clustered_points(s, 2400, 2), "clustered");
}

TEST_F(NeighbourGrid, PointsOnFacesCornersAndCellBordersMatchBruteForce) {
  const Scene s = grid_scene();
  check_grid(cl(), s, boundary_points(s, 2500, 3), "boundary");
}

// Spacing that is not a binary fraction: cell borders fall between floats, and pairs just inside the
// support straddle them, so rounding in the cell computation would show as a missed neighbour.
TEST_F(NeighbourGrid, PairsJustInsideSupportAcrossInexactCellBordersMatchBruteForce) {
  const Scene s = grid_scene(0.02, {0.3, 0.2, 0.14});
  const auto H = static_cast<float>(s.spacing * s.solver.support_ratio);
  const float cell = 0.5f * H;
  std::mt19937 rng(4);
  std::vector<Eigen::Vector3f> points;
  std::uniform_int_distribution<int> axis(0, 2);
  std::uniform_real_distribution<float> frac(1e-6f, 1e-4f);
  for (int t = 0; t < 600; ++t) {
    // First point on (or within an ulp of) a cell border, second one just under H away along an axis.
    Eigen::Vector3f a;
    for (int k = 0; k < 3; ++k) {
      const int borders = static_cast<int>(std::floor(float(s.domain.max[k]) / cell));
      a[k] = cell * float(std::uniform_int_distribution<int>(1, borders - 2)(rng));
      if (t % 3 == 1) a[k] = std::nextafter(a[k], 1.0f);
      if (t % 3 == 2) a[k] = std::nextafter(a[k], 0.0f);
    }
    Eigen::Vector3f b = a;
    const int k = axis(rng);
    b[k] += (t % 2 ? 1.0f : -1.0f) * H * (1.0f - frac(rng));
    points.push_back(clamp_to(s, a));
    points.push_back(clamp_to(s, b));
  }
  check_grid(cl(), s, points, "near-support");
}

}  // namespace
}  // namespace thaw
