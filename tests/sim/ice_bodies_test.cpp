// Ice bodies on the device (sim/ice_bodies.h): labels against a host union-find over all pairs (random
// clouds of mixed phases, chains, many small bodies, particles on and beyond the grid's boundary cells),
// the compaction into body indices, and the per-body sums against a host loop in double, bitwise the same
// on every run. The particles are sorted by cell here on the host, as the solver's grid build sorts them.
#include "sim/ice_bodies.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "sim/error.h"
#include "sim/particles.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;

constexpr auto kIce = static_cast<std::uint8_t>(Phase::Ice);
constexpr auto kWater = static_cast<std::uint8_t>(Phase::Water);

struct HostGrid {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  float cell = 0;
  int nx = 0, ny = 0, nz = 0;
  float inv() const { return 1.0f / cell; }
  ClGrid cl() const {
    return {{{origin.x(), origin.y(), origin.z(), 0.f}}, {{inv(), inv(), inv(), 0.f}}, nx, ny, nz};
  }
};

// A grid of cubes of `cell` over [lo, hi].
HostGrid grid_over(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float cell) {
  HostGrid g;
  g.origin = lo;
  g.cell = cell;
  g.nx = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)));
  g.ny = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)));
  g.nz = std::max(1, static_cast<int>(std::ceil((hi.z() - lo.z()) / cell)));
  return g;
}

// Particles in any order before sorting.
struct Cloud {
  std::vector<Float4> pos;
  std::vector<std::uint8_t> phase, material;
  std::vector<std::uint32_t> id;
  std::vector<std::uint32_t> group;  // the body before labelling (SortedIceParticles::group), or kNoBody
  void add(const Eigen::Vector3f& x, std::uint8_t ph, float mass = 1.0f, std::uint32_t in = kNoBody) {
    pos.push_back({x.x(), x.y(), x.z(), mass});
    phase.push_back(ph);
    material.push_back(0);
    id.push_back(static_cast<std::uint32_t>(id.size()));
    group.push_back(in);
  }
  std::size_t size() const { return pos.size(); }
};

// The cloud sorted by cell key exactly as grid_common.h keys cells (x fastest; clamped to the grid), stable,
// with the cell ranges.
struct Sorted {
  Cloud p;
  std::vector<std::uint32_t> cell_start;
};

Sorted sort_by_cell(const Cloud& c, const HostGrid& g) {
  const std::size_t n = c.size();
  const std::size_t ncells = std::size_t(g.nx) * g.ny * g.nz;
  const float inv = g.inv();
  const int dims[3] = {g.nx, g.ny, g.nz};
  std::vector<std::uint32_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    int cc[3];
    for (int a = 0; a < 3; ++a)
      cc[a] = std::clamp(static_cast<int>(std::floor((c.pos[i][a] - g.origin[a]) * inv)), 0, dims[a] - 1);
    key[i] = static_cast<std::uint32_t>((cc[2] * g.ny + cc[1]) * g.nx + cc[0]);
  }
  Sorted s;
  s.cell_start.assign(ncells + 1, 0);
  for (std::uint32_t k : key) ++s.cell_start[k + 1];
  for (std::size_t k = 0; k < ncells; ++k) s.cell_start[k + 1] += s.cell_start[k];
  std::vector<std::uint32_t> next(s.cell_start.begin(), s.cell_start.end() - 1);
  s.p.pos.resize(n);
  s.p.phase.resize(n);
  s.p.material.resize(n);
  s.p.id.resize(n);
  s.p.group.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t d = next[key[i]]++;
    s.p.pos[d] = c.pos[i];
    s.p.phase[d] = c.phase[i];
    s.p.material[d] = c.material[i];
    s.p.id[d] = c.id[i];
    s.p.group[d] = c.group[i];
  }
  return s;
}

template <class T>
cl::Buffer upload(ClRuntime& cl, const std::vector<T>& v) {
  if (v.empty()) return cl::Buffer(cl.context(), CL_MEM_READ_WRITE, 4);
  return cl::Buffer(cl.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                    const_cast<T*>(v.data()));
}

cl::Buffer scratch(ClRuntime& cl, std::size_t bytes) {
  return cl::Buffer(cl.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, 4));
}

std::vector<std::uint32_t> read_u32(ClRuntime& cl, const cl::Buffer& b, std::size_t n) {
  std::vector<std::uint32_t> out(n);
  if (n) cl.queue().enqueueReadBuffer(b, CL_TRUE, 0, n * 4, out.data());
  return out;
}

// As ice_near() in sim/kernels/ice_labels.cl, term for term.
bool near(const Float4& a, const Float4& b, float r2) {
  const float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz < r2;
}

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

// Whether two particles' groups let them connect: the same group, or either in none.
bool compatible(std::uint32_t a, std::uint32_t b) { return a == b || a == kNoBody || b == kNoBody; }

// Per particle (sorted order): the largest id in its ice component, or kNoLabel. All pairs: no grid. With
// grouped, only pairs whose groups are compatible connect.
std::vector<std::uint32_t> reference_labels(const Cloud& p, float radius, bool grouped = false,
                                            std::size_t* max_degree = nullptr) {
  const std::size_t n = p.size();
  const float r2 = radius * radius;
  UnionFind uf(n);
  std::vector<std::size_t> degree(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (p.phase[i] != kIce) continue;
    for (std::size_t j = i + 1; j < n; ++j)
      if (p.phase[j] == kIce && near(p.pos[i], p.pos[j], r2) &&
          (!grouped || compatible(p.group[i], p.group[j]))) {
        uf.unite(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j));
        ++degree[i];
        ++degree[j];
      }
  }
  std::vector<std::uint32_t> top(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (p.phase[i] == kIce) {
      const std::uint32_t root = uf.find(static_cast<std::uint32_t>(i));
      top[root] = std::max(top[root], p.id[i]);
    }
  std::vector<std::uint32_t> out(n, kNoLabel);
  for (std::size_t i = 0; i < n; ++i)
    if (p.phase[i] == kIce) out[i] = top[uf.find(static_cast<std::uint32_t>(i))];
  if (max_degree) *max_degree = n ? *std::max_element(degree.begin(), degree.end()) : 0;
  return out;
}

// The device's view of a sorted set.
struct DeviceSet {
  SortedIceParticles p;
  cl::Buffer material, label, body;
  DeviceSet(ClRuntime& cl, const Sorted& s, std::uint32_t id_capacity, bool grouped = false) {
    p.position = upload(cl, s.p.pos);
    if (grouped) p.group = upload(cl, s.p.group);
    p.phase = upload(cl, s.p.phase);
    p.id = upload(cl, s.p.id);
    p.cell_start = upload(cl, s.cell_start);
    p.n = static_cast<std::uint32_t>(s.p.size());
    p.id_capacity = id_capacity;
    material = upload(cl, s.p.material);
    label = scratch(cl, s.p.size() * 4);
    body = scratch(cl, s.p.size() * 4);
  }
};

// Gives the particles distinct random ids below `capacity` (>= their count).
void shuffle_ids(Cloud& c, std::uint32_t capacity, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint32_t> all(capacity);
  std::iota(all.begin(), all.end(), 0u);
  std::shuffle(all.begin(), all.end(), rng);
  for (std::size_t i = 0; i < c.size(); ++i) c.id[i] = all[i];
}

class IceBodiesTest : public ClSuite {
 protected:
  // Labels the sorted set with options o and checks them and the compaction against the union-find; returns
  // the sweeps.
  std::uint32_t check_labels(const Sorted& s, const HostGrid& g, int reach, float radius,
                             std::uint32_t capacity, const LabelOptions& o = {},
                             std::size_t* bodies = nullptr, bool grouped = false) {
    IceLabeller labeller(cl(), reach);
    DeviceSet d(cl(), s, capacity, grouped);
    const IceBodies b = labeller.find_bodies(d.p, g.cl(), radius, d.label, d.body, o);
    const std::uint32_t sweeps = labeller.last_sweeps();
    const auto expected = reference_labels(s.p, radius, grouped);
    const auto got = read_u32(cl(), d.label, s.p.size());
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < got.size(); ++i)
      if (got[i] != expected[i] && wrong++ < 5)
        ADD_FAILURE() << "particle " << i << " (id " << s.p.id[i] << ", phase " << int(s.p.phase[i])
                      << "): label " << got[i] << ", expected " << expected[i];
    EXPECT_EQ(wrong, 0u) << "wrong labels with " << o.jumps << " jumps, hooks " << (o.hook ? "on" : "off");

    // Compaction: bodies in ascending label order, each particle's body names its label, counts add up.
    std::vector<std::uint32_t> labels;
    for (std::uint32_t l : expected)
      if (l != kNoLabel) labels.push_back(l);
    std::sort(labels.begin(), labels.end());
    std::vector<std::uint32_t> counts;
    std::vector<std::uint32_t> distinct;
    for (std::size_t k = 0; k < labels.size(); ++k) {
      if (k == 0 || labels[k] != labels[k - 1]) {
        distinct.push_back(labels[k]);
        counts.push_back(0);
      }
      ++counts.back();
    }
    EXPECT_EQ(b.labels, distinct);
    EXPECT_EQ(b.counts, counts);
    const auto body = read_u32(cl(), d.body, s.p.size());
    std::size_t wrong_body = 0;
    for (std::size_t i = 0; i < body.size(); ++i) {
      const bool ok = expected[i] == kNoLabel ? body[i] == kNoBody
                                              : body[i] < b.size() && b.labels[body[i]] == expected[i];
      if (!ok && wrong_body++ < 5)
        ADD_FAILURE() << "particle " << i << ": body " << body[i] << " for label " << expected[i];
    }
    EXPECT_EQ(wrong_body, 0u) << "wrong body indices";
    if (bodies) *bodies = b.size();
    return sweeps;
  }
};

// A random cloud: about 60 % ice, the rest water, solid and air, near the continuum percolation density so
// components of every size appear; ids random below twice the count.
Cloud random_cloud(std::size_t n, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, unsigned seed) {
  std::mt19937 rng(seed);
  Cloud c;
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f x(lo.x() + (hi.x() - lo.x()) * u(rng), lo.y() + (hi.y() - lo.y()) * u(rng),
                            lo.z() + (hi.z() - lo.z()) * u(rng));
    const float r = u(rng);
    c.add(x, r < 0.6f ? kIce : static_cast<std::uint8_t>(r < 0.8f ? 0 : (r < 0.9f ? 2 : 3)));
  }
  shuffle_ids(c, static_cast<std::uint32_t>(2 * n), seed + 1);
  return c;
}

TEST_F(IceBodiesTest, RandomCloudsOfMixedPhasesMatchUnionFind) {
  // Ice spheres of radius r overlap in one infinite cluster above a covered volume fraction eta = 4/3 pi r^3
  // n_ice of about 0.34: the clouds have eta = 7.5 (one body and a few strays), 0.94, and 0.46 (near the
  // threshold: bodies of every size).
  const float r = 0.1f;
  for (const auto& [n, side, seed] :
       {std::tuple{3000, 1.0f, 1u}, std::tuple{3000, 2.0f, 2u}, std::tuple{4000, 2.8f, 3u}}) {
    SCOPED_TRACE("n " + std::to_string(n) + ", side " + std::to_string(side));
    const Eigen::Vector3f lo(-0.3f, 0.2f, 1.0f), hi = lo + Eigen::Vector3f::Constant(side);
    const Cloud c = random_cloud(std::size_t(n), lo, hi, seed);
    for (int reach : {1, 2}) {
      // Cells a little larger than r / reach: rounding in the cell index never hides a pair (as the solver).
      const HostGrid g = grid_over(lo, hi, r / float(reach) * 1.0001f);
      const Sorted s = sort_by_cell(c, g);
      std::size_t bodies = 0;
      const auto sweeps = check_labels(s, g, reach, r, static_cast<std::uint32_t>(2 * n), {}, &bodies);
      std::printf("random cloud n=%d side=%.1f reach %d: %zu bodies, %u sweeps\n", n, double(side), reach,
                  bodies, sweeps);
    }
  }
}

TEST_F(IceBodiesTest, GroupsKeepTouchingBodiesApart) {
  // Random clouds whose particles belong to one of three earlier bodies or to none: pairs of different
  // bodies never connect, a particle in none connects to any (the union-find applies the same rule).
  const float r = 0.1f;
  for (const auto& [n, side, seed] : {std::tuple{3000, 1.0f, 11u}, std::tuple{4000, 2.8f, 12u}}) {
    SCOPED_TRACE("n " + std::to_string(n) + ", side " + std::to_string(side));
    const Eigen::Vector3f lo(0.0f, 0.0f, 0.0f), hi = lo + Eigen::Vector3f::Constant(side);
    Cloud c = random_cloud(std::size_t(n), lo, hi, seed);
    std::mt19937 rng(seed);
    for (std::uint32_t& g : c.group) g = rng() % 5 < 4 ? std::uint32_t(rng() % 3) : kNoBody;
    const HostGrid grid = grid_over(lo, hi, r * 1.0001f);
    const Sorted s = sort_by_cell(c, grid);
    std::size_t bodies = 0, ungrouped = 0;
    check_labels(s, grid, 1, r, static_cast<std::uint32_t>(2 * n), {}, &bodies, true);
    check_labels(s, grid, 1, r, static_cast<std::uint32_t>(2 * n), {}, &ungrouped, false);
    EXPECT_GT(bodies, ungrouped) << "the groups split nothing";
  }

  // Two 4 x 4 x 4 lattices one spacing apart, earlier bodies 0 and 1: two bodies, though every particle of
  // one face is within the radius of the other's. One particle in no body between them joins them.
  const float dx = 1.0f;
  Cloud pair;
  for (std::uint32_t b = 0; b < 2; ++b)
    for (int z = 0; z < 4; ++z)
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x)
          pair.add({float(x + 4 * int(b)) * dx, float(y) * dx, float(z) * dx}, kIce, 1.0f, b);
  const HostGrid grid = grid_over({-1, -1, -1}, {9, 5, 5}, 1.5f * dx * 1.0001f);
  std::size_t bodies = 0;
  check_labels(sort_by_cell(pair, grid), grid, 1, 1.5f * dx, 256, {}, &bodies, true);
  EXPECT_EQ(bodies, 2u);
  Cloud bridged = pair;
  bridged.add({3.5f * dx, 1.0f * dx, 1.0f * dx}, kIce);
  check_labels(sort_by_cell(bridged, grid), grid, 1, 1.5f * dx, 256, {}, &bodies, true);
  EXPECT_EQ(bodies, 1u);
}

// A helix of n ice particles 0.8 r apart with turns 1.5 r apart: a path (no particle has more than two
// neighbours), the worst case for max propagation.
Cloud helix_chain(std::size_t n, float r) {
  Cloud c;
  const float R = 5.0f * r, pitch = 1.5f * r;
  const float step = 0.8f * r;
  // Chord of angle d on the helix: sqrt((2 R sin(d/2))^2 + (pitch d / 2 pi)^2) = step.
  double lo = 0, hi = 1;
  for (int k = 0; k < 60; ++k) {
    const double d = 0.5 * (lo + hi);
    const double chord = std::hypot(2 * R * std::sin(d / 2), pitch * d / (2 * M_PI));
    (chord < step ? lo : hi) = d;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double t = lo * double(i);
    c.add({float(R * std::cos(t)), float(R * std::sin(t)), float(pitch * t / (2 * M_PI))}, kIce);
  }
  return c;
}

TEST_F(IceBodiesTest, ChainsConvergeAndPointerJumpsCutSweeps) {
  const float r = 0.05f;
  const std::size_t n = 800;
  for (const char* order : {"increasing", "decreasing", "shuffled"}) {
    SCOPED_TRACE(order);
    Cloud c = helix_chain(n, r);
    if (std::string(order) == "decreasing") {
      for (std::size_t i = 0; i < n; ++i) c.id[i] = static_cast<std::uint32_t>(n - 1 - i);
    } else if (std::string(order) == "shuffled") {
      shuffle_ids(c, static_cast<std::uint32_t>(n), 7);
    }
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
    for (const auto& x : c.pos) {
      lo = lo.cwiseMin(Eigen::Vector3f(x[0], x[1], x[2]));
      hi = hi.cwiseMax(Eigen::Vector3f(x[0], x[1], x[2]));
    }
    const HostGrid g = grid_over(lo, hi, r * 1.0001f);
    const Sorted s = sort_by_cell(c, g);
    std::size_t degree = 0;
    const auto ref = reference_labels(s.p, r, false, &degree);
    ASSERT_EQ(degree, 2u) << "the helix must be a path";
    ASSERT_TRUE(std::all_of(ref.begin(), ref.end(), [&](std::uint32_t l) { return l == n - 1; }))
        << "one body";
    // Plain max propagation, then pointer jumps (Iwasaki: 1), then jumps with hooks (the default: 4).
    std::printf("chain of %zu, ids %s, sweeps:", n, order);
    const std::uint32_t plain = check_labels(s, g, 1, r, static_cast<std::uint32_t>(n), {0, false});
    std::printf(" plain %u;", plain);
    for (bool hook : {false, true})
      for (std::uint32_t jumps : {0u, 1u, 2u, 4u, 8u}) {
        if (jumps == 0 && !hook) continue;
        const auto sweeps = check_labels(s, g, 1, r, static_cast<std::uint32_t>(n), {jumps, hook});
        std::printf(" %s%u jumps %u;", hook ? "hooks + " : "", jumps, sweeps);
        EXPECT_LE(sweeps, plain) << jumps << " jumps, hooks " << hook;
      }
    std::printf("\n");
    // The defaults: a few dozen sweeps at most, whatever the order of the ids.
    EXPECT_LE(check_labels(s, g, 1, r, static_cast<std::uint32_t>(n)), 32u);
    // Without jumps the largest id travels the chain one neighbour a sweep.
    if (std::string(order) != "shuffled") {
      EXPECT_EQ(plain, n);
    }
  }
}

TEST_F(IceBodiesTest, ManySmallBodiesAmongWater) {
  // 20 x 20 clusters of 1 to 8 ice particles (each within 0.3 r of its centre, so pairwise connected),
  // centres 4 r apart, water particles between them.
  const float r = 0.02f;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Cloud c;
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) {
      const Eigen::Vector3f centre(4.0f * r * float(x), 4.0f * r * float(y),
                                   0.5f * r * float((x * 7 + y) % 5));
      const int count = 1 + (x * 3 + y * 5) % 8;
      for (int k = 0; k < count; ++k)
        c.add(centre + 0.17f * r * Eigen::Vector3f(u(rng), u(rng), u(rng)), kIce);
      c.add(centre + Eigen::Vector3f(2.0f * r, 2.0f * r, 0.0f), kWater);
    }
  shuffle_ids(c, static_cast<std::uint32_t>(3 * c.size()), 12);
  const Eigen::Vector3f lo(-r, -r, -r), hi(80 * r, 80 * r, 3 * r);
  const HostGrid g = grid_over(lo, hi, r * 1.0001f);
  std::size_t bodies = 0;
  check_labels(sort_by_cell(c, g), g, 1, r, static_cast<std::uint32_t>(3 * c.size()), {}, &bodies);
  EXPECT_EQ(bodies, 400u);
}

TEST_F(IceBodiesTest, ParticlesOnAndBeyondTheGridBoundary) {
  // A grid over [0, 1]^3 of 8 cells a side; particles on its faces, edges and corners, exactly on cell
  // borders, and beyond it (they key into the boundary cells, clamped, as the solver's walls do).
  const float r = 0.125f;
  const HostGrid g = grid_over(Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones(), r);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pick(0, 4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Cloud c;
  for (int k = 0; k < 8; ++k) c.add({float(k & 1), float((k >> 1) & 1), float((k >> 2) & 1)}, kIce);
  while (c.size() < 2500) {
    Eigen::Vector3f x;
    for (int a = 0; a < 3; ++a) {
      switch (pick(rng)) {
        case 0:
          x[a] = 0.0f;
          break;
        case 1:
          x[a] = 1.0f;
          break;
        case 2:
          x[a] = r * float(std::uniform_int_distribution<int>(0, 8)(rng));
          break;
        case 3:
          x[a] = -0.4f + 1.8f * u(rng);  // beyond the grid on either side
          break;
        default:
          x[a] = u(rng);
          break;
      }
    }
    c.add(x, u(rng) < 0.85f ? kIce : kWater);
  }
  shuffle_ids(c, static_cast<std::uint32_t>(c.size()), 6);
  // The radius is the cell exactly here (allowed: radius <= cell * reach); cell borders are exact binary
  // fractions, so no rounding can hide a pair.
  std::size_t bodies = 0;
  const auto sweeps =
      check_labels(sort_by_cell(c, g), g, 1, r, static_cast<std::uint32_t>(c.size()), {}, &bodies);
  std::printf("boundary cloud: %zu bodies, %u sweeps\n", bodies, sweeps);
}

TEST_F(IceBodiesTest, CrowdsWidenTheNeighbourRows) {
  // Two crowds of 150 ice particles within r / 4 of a point (149 neighbours each, beyond the rows' first
  // width) and strays: the walk runs again with wider rows.
  const float r = 0.1f;
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Cloud c;
  for (const Eigen::Vector3f& centre : {Eigen::Vector3f(0.3f, 0.3f, 0.3f), Eigen::Vector3f(0.7f, 0.5f, 0.4f)})
    for (int k = 0; k < 150; ++k) c.add(centre + 0.14f * r * Eigen::Vector3f(u(rng), u(rng), u(rng)), kIce);
  for (int k = 0; k < 40; ++k) c.add(Eigen::Vector3f(0.5f + 0.5f * u(rng), 0.5f + 0.5f * u(rng), 0.9f), kIce);
  shuffle_ids(c, static_cast<std::uint32_t>(c.size()), 9);
  const HostGrid g = grid_over(Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones(), r * 1.0001f);
  const Sorted s = sort_by_cell(c, g);
  std::size_t bodies = 0;
  check_labels(s, g, 1, r, static_cast<std::uint32_t>(c.size()), {}, &bodies);
  EXPECT_GE(bodies, 3u);
  IceLabeller labeller(cl(), 1);
  DeviceSet d(cl(), s, static_cast<std::uint32_t>(c.size()));
  EXPECT_EQ(labeller.row_width(), 32u);
  labeller.label(d.p, g.cl(), r, d.label);
  EXPECT_GE(labeller.row_width(), 149u);
}

TEST_F(IceBodiesTest, NoIceAndNoParticles) {
  Cloud c;
  for (int k = 0; k < 50; ++k) c.add(Eigen::Vector3f::Constant(0.01f * float(k)), kWater);
  const HostGrid g = grid_over(Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones(), 0.1f);
  std::size_t bodies = 1;
  check_labels(sort_by_cell(c, g), g, 1, 0.1f, 50, {}, &bodies);
  EXPECT_EQ(bodies, 0u);
  IceLabeller labeller(cl(), 1);
  DeviceSet empty(cl(), sort_by_cell(Cloud{}, g), 1);
  EXPECT_EQ(labeller.find_bodies(empty.p, g.cl(), 0.1f, empty.label, empty.body).size(), 0u);
}

TEST_F(IceBodiesTest, RejectsARadiusBeyondTheReachAndIdsBeyondTheCapacity) {
  Cloud c;
  for (int k = 0; k < 10; ++k) c.add(Eigen::Vector3f::Constant(0.05f * float(k)), kIce);
  const HostGrid g = grid_over(Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones(), 0.125f);
  const Sorted s = sort_by_cell(c, g);
  DeviceSet d(cl(), s, 10);
  IceLabeller one(cl(), 1), two(cl(), 2);
  EXPECT_NO_THROW(one.label(d.p, g.cl(), 0.125f, d.label));
  EXPECT_THROW(one.label(d.p, g.cl(), 0.126f, d.label), Error);
  EXPECT_NO_THROW(two.label(d.p, g.cl(), 0.25f, d.label));
  EXPECT_THROW(two.label(d.p, g.cl(), 0.2501f, d.label), Error);
  EXPECT_THROW(one.label(d.p, g.cl(), 0.0f, d.label), Error);
  d.p.id_capacity = 9;  // id 9 does not fit
  try {
    one.label(d.p, g.cl(), 0.1f, d.label);
    ADD_FAILURE() << "an id beyond the capacity was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("id 9"), std::string::npos) << e.what();
  }
  EXPECT_THROW(IceLabeller(cl(), 0), Error);
}

// ---- Body sums ----

struct SumCase {
  std::vector<Float4> pos, force, ref;
  std::vector<std::uint8_t> material;
  std::vector<std::uint32_t> body;
  std::vector<float> mass_scale = {1.0f, 0.917f, 2.5f};
  std::uint32_t nbodies = 0;
};

// n particles in a unit cube at (3, -2, 5), masses about 1e-3 kg, forces of a few mN; body b of particle i
// from `body_of`; references near each body's centre, off by up to 5 cm.
template <class F>
SumCase sum_case(std::size_t n, std::uint32_t nbodies, unsigned seed, F body_of) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  SumCase s;
  s.nbodies = nbodies;
  for (std::size_t i = 0; i < n; ++i) {
    s.pos.push_back({3.0f + u(rng), -2.0f + u(rng), 5.0f + u(rng), 1e-3f * (0.5f + u(rng))});
    s.force.push_back({1e-3f * (u(rng) - 0.5f), 2e-3f * (u(rng) - 0.5f), -9.81e-3f + 1e-3f * u(rng), 0.0f});
    s.material.push_back(static_cast<std::uint8_t>(i % 3));
    s.body.push_back(body_of(i));
  }
  std::vector<Eigen::Vector3d> centre(nbodies, Eigen::Vector3d::Zero());
  std::vector<double> mass(nbodies, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    if (s.body[i] < nbodies) {
      centre[s.body[i]] += Eigen::Vector3d(s.pos[i][0], s.pos[i][1], s.pos[i][2]);
      mass[s.body[i]] += 1;
    }
  for (std::uint32_t b = 0; b < nbodies; ++b) {
    const Eigen::Vector3d c =
        mass[b] > 0 ? Eigen::Vector3d(centre[b] / mass[b]) : Eigen::Vector3d(3.5, -1.5, 5.5);
    s.ref.push_back({float(c.x() + 0.1 * (u(rng) - 0.5)), float(c.y() + 0.1 * (u(rng) - 0.5)),
                     float(c.z() + 0.1 * (u(rng) - 0.5)), 0.0f});
  }
  return s;
}

// The 16 sums of body_sums.cl in double from the same float inputs, and the scale of each: the sum of the
// magnitudes of its terms (of the products in each torque term).
struct HostSums {
  std::vector<std::array<double, 16>> value, scale;
  std::vector<std::uint32_t> count;
};

HostSums host_sums(const SumCase& s) {
  HostSums h;
  h.value.assign(s.nbodies, {});
  h.scale.assign(s.nbodies, {});
  h.count.assign(s.nbodies, 0);
  for (std::size_t i = 0; i < s.pos.size(); ++i) {
    const std::uint32_t b = s.body[i];
    if (b >= s.nbodies) continue;
    const double m = double(s.pos[i][3] * s.mass_scale[s.material[i]]);
    const Eigen::Vector3d r(double(s.pos[i][0]) - s.ref[b][0], double(s.pos[i][1]) - s.ref[b][1],
                            double(s.pos[i][2]) - s.ref[b][2]);
    const Eigen::Vector3d f(s.force[i][0], s.force[i][1], s.force[i][2]);
    const Eigen::Vector3d t = r.cross(f);
    const double v[16] = {m,
                          m * r.x(),
                          m * r.y(),
                          m * r.z(),
                          m * r.x() * r.x(),
                          m * r.y() * r.y(),
                          m * r.z() * r.z(),
                          m * r.x() * r.y(),
                          m * r.x() * r.z(),
                          m * r.y() * r.z(),
                          f.x(),
                          f.y(),
                          f.z(),
                          t.x(),
                          t.y(),
                          t.z()};
    // Each torque term is a difference of products, and its float error scales with the products.
    const Eigen::Vector3d ra = r.cwiseAbs(), fa = f.cwiseAbs();
    const double products[3] = {ra.y() * fa.z() + ra.z() * fa.y(), ra.z() * fa.x() + ra.x() * fa.z(),
                                ra.x() * fa.y() + ra.y() * fa.x()};
    for (int k = 0; k < 16; ++k) {
      h.value[b][k] += v[k];
      h.scale[b][k] += k < 13 ? std::abs(v[k]) : products[k - 13];
    }
    ++h.count[b];
  }
  return h;
}

std::vector<BodySums> device_sums(ClRuntime& cl, const SumCase& s) {
  BodyReducer reducer(cl, s.mass_scale);
  BodyParticles p;
  p.position = upload(cl, s.pos);
  p.material = upload(cl, s.material);
  p.force = upload(cl, s.force);
  p.body = upload(cl, s.body);
  p.n = static_cast<std::uint32_t>(s.pos.size());
  const cl::Buffer ref = upload(cl, s.ref);
  return reducer.reduce(p, ref, s.nbodies);
}

// Largest error of any sum relative to its scale (HostSums).
double check_sums(const SumCase& s, const std::vector<BodySums>& got) {
  const HostSums h = host_sums(s);
  EXPECT_EQ(got.size(), s.nbodies);
  double worst = 0;
  for (std::uint32_t b = 0; b < s.nbodies && b < got.size(); ++b) {
    EXPECT_EQ(got[b].count, h.count[b]) << "body " << b;
    const auto v = got[b].terms();
    for (int k = 0; k < 16; ++k) {
      const double err = std::abs(v[k] - h.value[b][k]);
      const double rel = h.scale[b][k] > 0 ? err / h.scale[b][k] : err;
      worst = std::max(worst, rel);
      EXPECT_LE(rel, 1e-6) << "body " << b << " sum " << k << ": " << v[k] << " vs " << h.value[b][k];
    }
    EXPECT_TRUE(got[b].second_moment == got[b].second_moment.transpose());
  }
  return worst;
}

bool bitwise_equal(const std::vector<BodySums>& a, const std::vector<BodySums>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const auto x = a[k].terms(), y = b[k].terms();
    if (a[k].count != b[k].count || std::memcmp(x.data(), y.data(), sizeof x) != 0) return false;
  }
  return true;
}

TEST_F(IceBodiesTest, BodySumsMatchADoubleLoopAndRepeatBitwise) {
  struct Case {
    const char* name;
    SumCase s;
  };
  std::vector<Case> cases;
  // A few bodies among non-ice particles, interleaved in memory.
  cases.push_back({"7 bodies", sum_case(20000, 7, 1, [](std::size_t i) {
                     return i % 5 == 0 ? kNoBody : static_cast<std::uint32_t>((i * 2654435761u >> 7) % 7);
                   })});
  // One body of 60k particles: hundreds of chunks.
  cases.push_back({"one body", sum_case(60000, 1, 2, [](std::size_t) { return 0u; })});
  // 3000 bodies of about 10 particles, in runs; body 2999 empty.
  cases.push_back({"3000 bodies", sum_case(30000, 3000, 3, [](std::size_t i) {
                     return std::min<std::uint32_t>(static_cast<std::uint32_t>(i / 10), 2998u);
                   })});
  // One particle, one body.
  cases.push_back({"single", sum_case(1, 1, 4, [](std::size_t) { return 0u; })});
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto a = device_sums(cl(), c.s);
    const double worst = check_sums(c.s, a);
    std::printf("body sums, %s: worst error / sum of |terms| %.2e\n", c.name, worst);
    const auto b = device_sums(cl(), c.s);
    EXPECT_TRUE(bitwise_equal(a, b)) << "two runs differ";
  }
  // The inertia tensor about ref from the second moment.
  const auto& s = cases.front().s;
  const auto sums = device_sums(cl(), s);
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < s.pos.size(); ++i)
    if (s.body[i] == 0) {
      const Eigen::Vector3d r(double(s.pos[i][0]) - s.ref[0][0], double(s.pos[i][1]) - s.ref[0][1],
                              double(s.pos[i][2]) - s.ref[0][2]);
      inertia += double(s.pos[i][3] * s.mass_scale[s.material[i]]) *
                 (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    }
  EXPECT_LE((sums[0].inertia() - inertia).norm(), 1e-6 * inertia.norm());
}

TEST_F(IceBodiesTest, BodySumsOfLabelledBodies) {
  // The whole path: a random cloud labelled and compacted on the device, then summed by body.
  const float r = 0.1f;
  const Eigen::Vector3f lo(0, 0, 0), hi(1.4f, 1.4f, 1.4f);
  Cloud c = random_cloud(5000, lo, hi, 21);
  std::mt19937 rng(22);
  for (auto& m : c.material) m = static_cast<std::uint8_t>(rng() % 3);
  const HostGrid g = grid_over(lo, hi, r * 1.0001f);
  const Sorted s = sort_by_cell(c, g);
  DeviceSet d(cl(), s, 10000);
  IceLabeller labeller(cl(), 1);
  const IceBodies bodies = labeller.find_bodies(d.p, g.cl(), r, d.label, d.body);
  ASSERT_GT(bodies.size(), 10u);
  SumCase sc;
  sc.pos = s.p.pos;
  sc.material = s.p.material;
  sc.body = read_u32(cl(), d.body, s.p.size());
  sc.nbodies = static_cast<std::uint32_t>(bodies.size());
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::size_t i = 0; i < s.p.size(); ++i) sc.force.push_back({u(rng), u(rng), u(rng), 0.0f});
  for (std::uint32_t b = 0; b < sc.nbodies; ++b) sc.ref.push_back({0.5f, 0.6f, 0.7f, 0.0f});
  BodyReducer reducer(cl(), sc.mass_scale);
  BodyParticles p{d.p.position, d.material, upload(cl(), sc.force), d.body, d.p.n};
  const auto sums = reducer.reduce(p, upload(cl(), sc.ref), sc.nbodies);
  check_sums(sc, sums);
  for (std::uint32_t b = 0; b < sc.nbodies; ++b) EXPECT_EQ(sums[b].count, bodies.counts[b]);
  // The reducer keeps its scratch between calls: a second call on the same inputs gives the same bits.
  EXPECT_TRUE(bitwise_equal(sums, reducer.reduce(p, upload(cl(), sc.ref), sc.nbodies)));
}

TEST_F(IceBodiesTest, BodySumsRejectBadBodiesAndMaterials) {
  SumCase s = sum_case(1000, 4, 9, [](std::size_t i) { return static_cast<std::uint32_t>(i % 4); });
  s.body[700] = 4;
  try {
    device_sums(cl(), s);
    ADD_FAILURE() << "a body index beyond nbodies was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("particle 700 has body 4"), std::string::npos) << e.what();
  }
  s.body[700] = 0;
  s.material[300] = 3;
  EXPECT_THROW(device_sums(cl(), s), Error);
  EXPECT_THROW(BodyReducer(cl(), {}), Error);
}

}  // namespace
}  // namespace thaw
