// Thermal photons (sim/photons.h, sim/kernels/photons.cl): the 3D-DDA walk against a brute-force
// slab test over every voxel for axis-aligned, diagonal and random rays from inside and outside the
// grid; a slab under a lamp (only its top layer absorbs, a lamp facing away absorbs nothing); the
// absorbed fraction of a small box against the analytic view factor and a host Monte Carlo; closure
// and determinism of the counts; the photon energy of Iwasaki et al. 2010.
#include "sim/photons.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "sim/embedded_kernels.h"
#include "sim/error.h"
#include "sim/particles.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::ClSuite;
using Vec3 = Eigen::Vector3f;

constexpr double kPi = 3.14159265358979323846;

// Particles on the device, as the solver holds them.
struct DeviceParticles {
  cl::Buffer position, phase, hits;
  std::uint32_t n = 0;
};

DeviceParticles upload(ClRuntime& cl, const std::vector<Vec3>& x, const std::vector<Phase>& phase) {
  DeviceParticles d;
  d.n = static_cast<std::uint32_t>(x.size());
  std::vector<Float4> pos(x.size());
  std::vector<std::uint8_t> ph(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    pos[i] = {x[i].x(), x[i].y(), x[i].z(), 1.0f};
    ph[i] = static_cast<std::uint8_t>(phase[i]);
  }
  const std::size_t n = std::max<std::size_t>(x.size(), 1);
  d.position = cl::Buffer(cl.context(), CL_MEM_READ_WRITE, n * 16);
  d.phase = cl::Buffer(cl.context(), CL_MEM_READ_WRITE, n);
  d.hits = cl::Buffer(cl.context(), CL_MEM_READ_WRITE, n * 4);
  if (!x.empty()) {
    cl.queue().enqueueWriteBuffer(d.position, CL_TRUE, 0, x.size() * 16, pos.data());
    cl.queue().enqueueWriteBuffer(d.phase, CL_TRUE, 0, x.size(), ph.data());
  }
  cl.queue().enqueueFillBuffer(d.hits, cl_uint(0), 0, n * 4);
  return d;
}

std::vector<std::uint32_t> read_hits(ClRuntime& cl, DeviceParticles& d) {
  std::vector<std::uint32_t> h(d.n);
  cl.queue().enqueueReadBuffer(d.hits, CL_TRUE, 0, d.n * 4, h.data());
  return h;
}

void zero_hits(ClRuntime& cl, DeviceParticles& d) {
  cl.queue().enqueueFillBuffer(d.hits, cl_uint(0), 0, std::max<std::size_t>(d.n, 1) * 4);
}

std::uint64_t sum(const std::vector<std::uint32_t>& h) {
  return std::accumulate(h.begin(), h.end(), std::uint64_t(0));
}

// Centre of voxel (i, j, k).
Vec3 voxel_centre(const VoxelGridInfo& g, int i, int j, int k) {
  return g.origin + g.cell * Vec3(float(i) + 0.5f, float(j) + 0.5f, float(k) + 0.5f);
}

// Ice filling voxels [lo, hi) (one particle per voxel, at its centre), x fastest.
void add_ice_box(const VoxelGridInfo& g, Eigen::Vector3i lo, Eigen::Vector3i hi, std::vector<Vec3>& x,
                 std::vector<Phase>& phase) {
  for (int k = lo.z(); k < hi.z(); ++k)
    for (int j = lo.y(); j < hi.y(); ++j)
      for (int i = lo.x(); i < hi.x(); ++i) {
        x.push_back(voxel_centre(g, i, j, k));
        phase.push_back(Phase::Ice);
      }
}

// Uniform in [0, 1) from mt19937's specified output (the std distributions differ between libraries).
double uniform(std::mt19937& rng) { return double(rng() >> 8) * 0x1p-24; }

class PhotonTracerTest : public ClSuite {};

TEST(PhotonEnergy, StefanBoltzmannOfTheSourceTemperature) {
  const double sigma = 5.670374419e-8;
  const double t = 773.15;
  EXPECT_NEAR(photon_energy(1.0, 500.0, 1.0, 1.0, 1), sigma * t * t * t * t, 1e-9);
  EXPECT_NEAR(photon_energy(1.0, 500.0, 1.0, 1.0, 1), 20261.275, 1e-3);
  // Linear in emissivity, area and dt; shared among the photons.
  EXPECT_NEAR(photon_energy(0.5, 500.0, 0.02, 0.001, 1000), photon_energy(1.0, 500.0, 1.0, 1.0, 1) * 1e-8,
              1e-15);
  // The melting point itself still radiates.
  EXPECT_NEAR(photon_energy(1.0, 0.0, 1.0, 1.0, 1), sigma * std::pow(273.15, 4), 1e-9);
  EXPECT_THROW(photon_energy(1.0, 500.0, 1.0, 1.0, 0), Error);
}

TEST_F(PhotonTracerTest, RejectsGridsTooLargeNamingTheVoxelCounts) {
  try {
    PhotonTracer t(cl(), {Vec3::Zero(), 0.01f, 1024, 1024, 512});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("1024 x 1024 x 512"), std::string::npos) << e.what();
  }
  EXPECT_THROW(PhotonTracer(cl(), {Vec3::Zero(), 0.0f, 4, 4, 4}), Error);
  EXPECT_THROW(PhotonTracer(cl(), {Vec3::Zero(), 0.1f, 4, 0, 4}), Error);
}

// --- The DDA walk against brute force --------------------------------------------------------------

// Calls photon_first_hit() of photons.cl for explicit rays.
constexpr const char* kFirstHitKernel = R"(
kernel void first_hits(const VoxelGrid vg, global const int* occ, global const float4* o, global const float4* d,
                       global int* out, const uint n) {
  const uint r = get_global_id(0);
  if (r < n) out[r] = photon_first_hit(vg, occ, o[r].xyz, d[r].xyz);
}
)";

struct Ray {
  Vec3 o, d;
};

// The first occupied voxel's owner along the ray, by a slab test of every voxel in double precision,
// or -1; `ambiguous` when a voxel the ray grazes or a tie at the entry (within eps voxels) could
// change the answer, so that float rounding in either walk may legitimately differ.
int brute_force_first_hit(const VoxelGridInfo& g, const std::vector<int>& occ, const Ray& ray,
                          bool& ambiguous) {
  constexpr double eps = 1e-4;
  const Eigen::Vector3d p = (ray.o.cast<double>() - g.origin.cast<double>()) / double(g.cell);
  const Eigen::Vector3d d = ray.d.cast<double>();
  const int n[3] = {g.nx, g.ny, g.nz};
  ambiguous = false;
  for (int a = 0; a < 3; ++a)
    if (d[a] == 0.0 && std::abs(p[a] - std::round(p[a])) < eps) ambiguous = true;
  double best = std::numeric_limits<double>::infinity();
  int owner = -1;
  struct Touch {
    double t, chord;
  };
  std::vector<Touch> touches;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const int o = occ[(k * n[1] + j) * n[0] + i];
        if (o < 0) continue;
        const int c[3] = {i, j, k};
        double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
          if (d[a] == 0.0) {
            inside = inside && p[a] >= c[a] && p[a] < c[a] + 1;
            continue;
          }
          const double ta = (c[a] - p[a]) / d[a], tb = (c[a] + 1 - p[a]) / d[a];
          t0 = std::max(t0, std::min(ta, tb));
          t1 = std::min(t1, std::max(ta, tb));
        }
        if (!inside) continue;
        const double len = d.norm();
        touches.push_back({t0 * len, (t1 - t0) * len});
        if (t1 - t0 > 0 && t0 < best) {
          best = t0;
          owner = o;
        }
      }
  best *= d.norm();
  int at_best = 0;
  for (const auto& t : touches) {
    if (std::abs(t.chord) < eps && t.t < best + eps) ambiguous = true;
    if (t.chord > 0 && std::abs(t.t - best) < eps) ++at_best;
  }
  if (at_best > 1) ambiguous = true;
  return owner;
}

TEST_F(PhotonTracerTest, DdaMatchesBruteForceOnAxisDiagonalAndRandomRays) {
  // An odd grid with an origin and cell that are not binary fractions, about a quarter occupied.
  const VoxelGridInfo g{Vec3(-0.3f, 0.2f, 0.1f), 0.13f, 9, 7, 6};
  const int ncells = g.nx * g.ny * g.nz;
  std::mt19937 rng(12345);
  std::vector<int> occ(ncells, -1);
  for (int c = 0; c < ncells; ++c)
    if (uniform(rng) < 0.12) occ[c] = 1000 + c;

  const Vec3 size = g.cell * Vec3(float(g.nx), float(g.ny), float(g.nz));
  // A point in the grid's box widened by `margin` of its size on each side.
  auto point = [&](double margin) {
    Vec3 u;
    for (int a = 0; a < 3; ++a) u[a] = float(-margin + (1 + 2 * margin) * uniform(rng));
    return Vec3(g.origin + size.cwiseProduct(u));
  };
  std::vector<Ray> rays;
  const Vec3 axes[6] = {Vec3::UnitX(),  -Vec3::UnitX(), Vec3::UnitY(),
                        -Vec3::UnitY(), Vec3::UnitZ(),  -Vec3::UnitZ()};
  for (int r = 0; r < 60; ++r)
    for (const auto& a : axes) rays.push_back({point(r % 2 ? 0.0 : 0.5), a});  // inside, and from all around
  for (int r = 0; r < 60; ++r)
    for (int s = 0; s < 8; ++s) {
      const Vec3 d(s & 1 ? 1.f : -1.f, s & 2 ? 1.f : -1.f, s & 4 ? 1.f : -1.f);
      rays.push_back({point(r % 2 ? 0.0 : 0.5), d.normalized()});
    }
  for (int r = 0; r < 1500; ++r) {
    Vec3 d;
    do d = Vec3(float(uniform(rng) - 0.5), float(uniform(rng) - 0.5), float(uniform(rng) - 0.5));
    while (d.norm() < 0.1f);
    // In-plane rays (one zero component) too: they cross only two kinds of face.
    if (r % 5 == 0) d[r % 3] = 0.0f;
    rays.push_back({point(r % 3 == 0 ? 0.0 : 1.0), r % 2 ? d.normalized() : Vec3(3.0f * d)});
  }
  // Rays that start outside and point away, or run parallel beside the grid: never enter.
  rays.push_back({g.origin - Vec3(0.1f, 0.1f, 0.1f), -Vec3::Ones().normalized()});
  rays.push_back({g.origin + Vec3(-0.05f, 0.3f, 0.3f), Vec3::UnitY()});
  rays.push_back({g.origin + Vec3(0.3f, 0.3f, size.z() + 0.05f), Vec3(1.0f, 1.0f, 0.0f).normalized()});

  auto& ctx = cl().context();
  const auto& files = embedded_kernel_files();
  const auto program = cl().build_sources({{"sim/kernels/grid_common.h", files.at("grid_common.h")},
                                           {"sim/kernels/photons.cl", files.at("photons.cl")},
                                           {"photons_test.cpp", kFirstHitKernel}});
  cl::Kernel k(program, "first_hits");
  const auto n = static_cast<cl_uint>(rays.size());
  std::vector<Float4> o(n), d(n);
  for (std::size_t r = 0; r < n; ++r) {
    o[r] = {rays[r].o.x(), rays[r].o.y(), rays[r].o.z(), 0.f};
    d[r] = {rays[r].d.x(), rays[r].d.y(), rays[r].d.z(), 0.f};
  }
  cl::Buffer occ_b(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, occ.size() * 4, occ.data());
  cl::Buffer o_b(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, n * 16, o.data());
  cl::Buffer d_b(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, n * 16, d.data());
  cl::Buffer out_b(ctx, CL_MEM_READ_WRITE, n * 4);
  struct {
    cl_float4 origin;
    cl_float cell;
    cl_int nx, ny, nz;
  } vg{{{g.origin.x(), g.origin.y(), g.origin.z(), 0.f}}, g.cell, g.nx, g.ny, g.nz};
  k.setArg(0, vg);
  k.setArg(1, occ_b);
  k.setArg(2, o_b);
  k.setArg(3, d_b);
  k.setArg(4, out_b);
  k.setArg(5, n);
  cl().queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n));
  std::vector<int> out(n);
  cl().queue().enqueueReadBuffer(out_b, CL_TRUE, 0, n * 4, out.data());

  int compared = 0, skipped = 0, hits = 0, escapes = 0, mismatches = 0;
  for (std::size_t r = 0; r < n; ++r) {
    bool ambiguous = false;
    const int want = brute_force_first_hit(g, occ, rays[r], ambiguous);
    if (ambiguous) {
      ++skipped;
      continue;
    }
    ++compared;
    (want >= 0 ? hits : escapes)++;
    if (out[r] != want && ++mismatches <= 10)
      ADD_FAILURE() << "ray " << r << " from (" << rays[r].o.transpose() << ") along ("
                    << rays[r].d.transpose() << "): DDA " << out[r] << ", brute force " << want;
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_LT(skipped, int(n) / 50) << "too many rays graze a voxel to be a test";
  EXPECT_GT(hits, 500);
  EXPECT_GT(escapes, 300);
  // The rays that never enter the grid escape.
  for (std::size_t r = n - 3; r < n; ++r) EXPECT_EQ(out[r], -1) << "ray " << r;
}

// --- Whole traces --------------------------------------------------------------------------------

// A 64 x 64 slab of ice four voxels thick on the bottom of the grid, with empty voxels above.
struct Slab {
  VoxelGridInfo g{Vec3(0.0f, 0.0f, 0.0f), 0.05f, 64, 64, 8};
  std::vector<Vec3> x;
  std::vector<Phase> phase;
  Slab() { add_ice_box(g, {0, 0, 0}, {64, 64, 4}, x, phase); }
  int layer(std::size_t particle) const { return static_cast<int>(particle / (64 * 64)); }
  LampGeometry lamp(float height, float facing) const {
    return {Vec3(1.6f, 1.6f, height), Vec3(0.0f, 0.0f, facing), Vec3(0.1f, 0.0f, 0.0f),
            Vec3(0.0f, 0.07f, 0.0f)};
  }
};

TEST_F(PhotonTracerTest, SlabUnderALampAbsorbsNearlyAllInItsTopLayerOnly) {
  const Slab s;
  auto d = upload(cl(), s.x, s.phase);
  PhotonTracer tracer(cl(), s.g);
  tracer.build_occupancy(d.position, d.phase, d.n);

  // Half a voxel above the slab (top at z = 0.2 m), about 1.5 m from the grid's sides: a photon escapes
  // only if cos(theta) < 0.025 / 1.5, probability (cosine-weighted) 0.0167^2 = 2.8e-4.
  const std::uint32_t photons = 20000;
  const auto tally = tracer.trace(s.lamp(0.225f, -1.0f), photons, 7, 0, d.hits);
  const auto hits = read_hits(cl(), d);
  EXPECT_EQ(tally.emitted, photons);
  EXPECT_EQ(tally.absorbed + tally.escaped(), tally.emitted);
  EXPECT_EQ(sum(hits), tally.absorbed);
  EXPECT_GE(tally.absorbed, photons - 20);
  for (std::size_t i = 0; i < hits.size(); ++i)
    if (hits[i] > 0) {
      ASSERT_EQ(s.layer(i), 3) << "particle " << i << " below the top layer was hit";
    }

  // Facing away, every photon leaves through the top of the grid.
  zero_hits(cl(), d);
  const auto away = tracer.trace(s.lamp(0.225f, 1.0f), photons, 7, 0, d.hits);
  EXPECT_EQ(away.absorbed, 0u);
  EXPECT_EQ(away.escaped(), photons);
  EXPECT_EQ(sum(read_hits(cl(), d)), 0u);
}

TEST_F(PhotonTracerTest, LampBelowTheGridReachesOnlyTheBottomLayer) {
  const Slab s;
  auto d = upload(cl(), s.x, s.phase);
  PhotonTracer tracer(cl(), s.g);
  tracer.build_occupancy(d.position, d.phase, d.n);
  // Outside the grid, 1 cm under its floor and facing up: photons are clipped into the grid first.
  const auto tally = tracer.trace(s.lamp(-0.01f, 1.0f), 20000, 3, 1, d.hits);
  const auto hits = read_hits(cl(), d);
  EXPECT_EQ(sum(hits), tally.absorbed);
  // Photons pass under the grid's edge only if cos(theta) < 0.01 / 1.5: probability 4e-5.
  EXPECT_GE(tally.absorbed, 19980u);
  for (std::size_t i = 0; i < hits.size(); ++i)
    if (hits[i] > 0) {
      ASSERT_EQ(s.layer(i), 0) << "particle " << i << " above the bottom layer was hit";
    }
  // Facing away from the grid it never enters it.
  zero_hits(cl(), d);
  EXPECT_EQ(tracer.trace(s.lamp(-0.01f, -1.0f), 20000, 3, 1, d.hits).absorbed, 0u);
}

TEST_F(PhotonTracerTest, OnlyIceAndSolidAbsorbAndTheLargestIndexOwnsAVoxel) {
  const VoxelGridInfo g{Vec3(0.0f, 0.0f, 0.0f), 0.1f, 4, 4, 4};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Particles 0-2 share voxel (1, 1, 0) [ice, solid, water]; 3 is outside the grid; 4 is not finite;
  // 5 is water in voxel (2, 2, 0).
  const std::vector<Vec3> x = {{0.12f, 0.13f, 0.02f},  {0.18f, 0.17f, 0.08f}, {0.15f, 0.15f, 0.05f},
                               {0.25f, 0.25f, -0.05f}, {nan, 0.2f, 0.02f},    {0.25f, 0.25f, 0.05f}};
  const std::vector<Phase> ph = {Phase::Ice, Phase::Solid, Phase::Water,
                                 Phase::Ice, Phase::Ice,   Phase::Water};
  auto d = upload(cl(), x, ph);
  PhotonTracer tracer(cl(), g);
  // Before any occupancy is built, nothing absorbs.
  const LampGeometry lamp{Vec3(0.2f, 0.2f, 0.35f), Vec3(0.0f, 0.0f, -1.0f), Vec3(0.2f, 0.0f, 0.0f),
                          Vec3(0.0f, 0.2f, 0.0f)};
  EXPECT_EQ(tracer.trace(lamp, 20000, 0, 0, d.hits).absorbed, 0u);

  tracer.build_occupancy(d.position, d.phase, d.n);
  const auto tally = tracer.trace(lamp, 20000, 0, 0, d.hits);
  const auto hits = read_hits(cl(), d);
  EXPECT_GT(tally.absorbed, 100u);
  EXPECT_EQ(hits[1], tally.absorbed);
  for (std::size_t i : {0, 2, 3, 4, 5}) EXPECT_EQ(hits[i], 0u) << "particle " << i;
}

// Analytic view factor from a point (differential area) to a parallel rectangle [0, a] x [0, b] at
// height h with one corner above the point (Howell's catalogue, B-3).
double view_factor_corner(double a, double b, double h) {
  const double X = a / h, Y = b / h;
  const double sx = std::sqrt(1 + X * X), sy = std::sqrt(1 + Y * Y);
  return (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy)) / (2 * kPi);
}

TEST_F(PhotonTracerTest, AbsorbedFractionMatchesTheViewFactorOfASmallBox) {
  // A 0.4 m x 0.4 m x 0.2 m ice box at the bottom centre of a 2 x 2 x 2 m grid.
  const VoxelGridInfo g{Vec3(-1.0f, -1.0f, 0.0f), 0.1f, 20, 20, 20};
  std::vector<Vec3> x;
  std::vector<Phase> ph;
  add_ice_box(g, {8, 8, 0}, {12, 12, 2}, x, ph);
  auto d = upload(cl(), x, ph);
  PhotonTracer tracer(cl(), g);
  tracer.build_occupancy(d.position, d.phase, d.n);

  // A 2 mm lamp 1 m above the box's top face, on its axis: from there the box shows only its top, so
  // the fraction is four corner view factors (0.0484 for a cosine-weighted source; a uniform one would
  // give half of that).
  const std::uint32_t photons = 100000;
  const LampGeometry above{Vec3(0.0f, 0.0f, 1.2f), Vec3(0.0f, 0.0f, -1.0f), Vec3(0.001f, 0.0f, 0.0f),
                           Vec3(0.0f, 0.001f, 0.0f)};
  const auto tally = tracer.trace(above, photons, 11, 0, d.hits);
  const double f = 4 * view_factor_corner(0.2, 0.2, 1.0);
  const double sd = std::sqrt(photons * f * (1 - f));
  EXPECT_NEAR(double(tally.absorbed), photons * f, 4 * sd) << "view factor " << f;
  const auto hits = read_hits(cl(), d);
  EXPECT_EQ(sum(hits), tally.absorbed);
  for (std::size_t i = 0; i < hits.size(); ++i)
    if (hits[i] > 0) {
      ASSERT_GE(i, 16u) << "particle " << i << " of the lower layer was hit";
    }

  // A tilted 0.3 m x 0.2 m lamp off to the side sees the top and two side faces: against a host
  // Monte Carlo of the same emitter and box.
  zero_hits(cl(), d);
  const Vec3 n = Vec3(-1.0f, -0.5f, -0.8f).normalized();
  const Vec3 u = 0.15f * n.cross(Vec3::UnitZ()).normalized();
  const Vec3 v = 0.1f * n.cross(u).normalized();
  const LampGeometry tilted{Vec3(0.7f, 0.4f, 0.8f), n, u, v};
  const auto t2 = tracer.trace(tilted, photons, 12, 2, d.hits);
  std::mt19937 rng(99);
  const int samples = 400000;
  int in = 0;
  const Eigen::Vector3d lo(-0.2, -0.2, 0.0), hi(0.2, 0.2, 0.2);
  const Eigen::Vector3d nd = n.cast<double>(), ud = u.cast<double>(), vd = v.cast<double>();
  const Eigen::Vector3d t1 = ud.normalized(), b1 = nd.cross(t1);
  for (int s = 0; s < samples; ++s) {
    const Eigen::Vector3d o =
        tilted.centre.cast<double>() + (2 * uniform(rng) - 1) * ud + (2 * uniform(rng) - 1) * vd;
    const double r2 = uniform(rng), phi = 2 * kPi * uniform(rng);
    const Eigen::Vector3d dir =
        std::sqrt(r2) * (std::cos(phi) * t1 + std::sin(phi) * b1) + std::sqrt(1 - r2) * nd;
    double t0 = 0, tm = 1e30;
    for (int a = 0; a < 3; ++a) {
      const double ta = (lo[a] - o[a]) / dir[a], tb = (hi[a] - o[a]) / dir[a];
      t0 = std::max(t0, std::min(ta, tb));
      tm = std::min(tm, std::max(ta, tb));
    }
    in += t0 < tm;
  }
  const double f2 = double(in) / samples;
  const double sd2 = std::sqrt(photons * f2 * (1 - f2) * (1 + double(photons) / samples));
  EXPECT_GT(f2, 0.02);
  EXPECT_NEAR(double(t2.absorbed), photons * f2, 4 * sd2) << "host Monte Carlo fraction " << f2;
  EXPECT_EQ(sum(read_hits(cl(), d)), t2.absorbed);
}

TEST_F(PhotonTracerTest, SameStepGivesIdenticalHitsAndOtherStepsOnlyTheSameStatistics) {
  const Slab s;
  auto d = upload(cl(), s.x, s.phase);
  PhotonTracer tracer(cl(), s.g);
  tracer.build_occupancy(d.position, d.phase, d.n);
  // High above the slab, so that many photons escape and the absorbed count itself varies.
  const auto lamp = s.lamp(0.39f, -1.0f);
  const std::uint32_t photons = 20000;
  auto run = [&](std::uint64_t step, std::uint32_t lamp_index, PhotonTally& tally) {
    zero_hits(cl(), d);
    tally = tracer.trace(lamp, photons, step, lamp_index, d.hits);
    return read_hits(cl(), d);
  };
  PhotonTally a, b, c, e, f;
  const auto ha = run(5, 0, a);
  tracer.warm_up();
  tracer.build_occupancy(d.position, d.phase, d.n);
  const auto hb = run(5, 0, b);
  EXPECT_EQ(ha, hb);
  EXPECT_EQ(a.absorbed, b.absorbed);
  EXPECT_LT(a.absorbed, photons - 100u);

  const std::uint64_t far_step = (std::uint64_t(1) << 32) + 5;  // the step's high word counts too
  const std::vector<std::uint32_t> others[] = {run(6, 0, c), run(5, 1, e), run(far_step, 0, f)};
  const PhotonTally* tallies[] = {&c, &e, &f};
  for (int o = 0; o < 3; ++o) {
    EXPECT_NE(others[o], ha) << "variant " << o;
    EXPECT_EQ(sum(others[o]), tallies[o]->absorbed);
    const double sd = std::sqrt(double(a.absorbed) * (1.0 - double(a.absorbed) / photons));
    EXPECT_NEAR(double(tallies[o]->absorbed), double(a.absorbed), 5 * std::sqrt(2.0) * sd) << "variant " << o;
  }
}

}  // namespace
}  // namespace thaw
