#include "bench/bodies_bench.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "sim/cl_grid.h"
#include "sim/error.h"
#include "sim/ice_bodies.h"
#include "sim/kernels/sph_kernel.h"
#include "sim/solver.h"

namespace thaw {
namespace {

constexpr auto kIce = static_cast<std::uint8_t>(Phase::Ice);

// A cube lattice of side^3 particles spacing dx, water, with an ice block in it (a margin of an eighth of
// the side all round) that one water layer across x and one across y split into 4 bodies. Ids in
// creation order, x fastest, as sample_scene() numbers particles.
HostParticles bench_lattice(int side, double dx, std::uint8_t water, std::uint8_t ice) {
  HostParticles p;
  p.resize(std::size_t(side) * side * side);
  const int lo = side / 8, hi = side - side / 8, mid = side / 2;
  std::size_t i = 0;
  for (int z = 0; z < side; ++z)
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x, ++i) {
        const bool in_block = x >= lo && x < hi && y >= lo && y < hi && z >= lo && z < hi;
        const bool is_ice = in_block && x != mid && y != mid;
        const float mass = static_cast<float>(1000.0 * dx * dx * dx);
        p.position[i] = {float((x + 0.5) * dx), float((y + 0.5) * dx), float((z + 0.5) * dx), mass};
        // Some motion, so the ice-force pass's viscosity term has something to work on.
        p.velocity[i] = {0.01f * std::sin(0.7f * float(i)), 0.01f * std::cos(1.3f * float(i)),
                         0.01f * std::sin(2.1f * float(i)), 0.f};
        p.density[i] = 1000.0f;
        p.phase[i] = is_ice ? kIce : static_cast<std::uint8_t>(Phase::Water);
        p.material[i] = is_ice ? ice : water;
        p.id[i] = static_cast<std::uint32_t>(i);
        p.enthalpy[i] = {0.f, 0.f};
      }
  return p;
}

Scene bench_scene(int side, double dx) {
  const double L = side * dx;
  const Json doc = {
      {"name", "bench/bodies"},
      {"domain", {{"min", {0, 0, 0}}, {"max", {L, L, L}}}},
      {"spacing", dx},
      {"heat", {{"enabled", false}}},
      {"materials",
       {{"water", {{"kind", "fluid"}, {"density", 1000}, {"conductivity", 0.56}, {"specific_heat", 4217}}},
        {"ice",
         {{"kind", "ice"},
          {"density", 917},
          {"conductivity", 2.22},
          {"specific_heat", 2050},
          {"melts_into", "water"}}}}},
      {"fluids", {{{"material", "water"}, {"box", {{"min", {0, 0, 0}}, {"max", {L, L, L}}}}}}},
      // Free ice, so the solver builds its rigid-ice stage (the particles come from bench_lattice), with
      // a viscous coupling to time both of the ice-force pass's terms.
      {"ice",
       {{{"material", "ice"},
         {"box", {{"min", {L / 8, L / 8, L / 8}}, {"max", {L - L / 8, L - L / 8, L - L / 8}}}},
         {"motion", "free"}}}},
      {"solver", {{"boundary_viscosity", 0.1}}},
  };
  return scene_from_json(doc);
}

int material_index(const Scene& s, const std::string& name) {
  for (std::size_t m = 0; m < s.materials.size(); ++m)
    if (s.materials[m].name == name) return static_cast<int>(m);
  throw Error("bench bodies: no material '" + name + "'");
}

template <class T>
cl::Buffer upload(ClRuntime& cl, const std::vector<T>& v) {
  return cl::Buffer(cl.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                    const_cast<T*>(v.data()));
}

// Lock-free union-find (link the larger root under the smaller by compare-and-swap, path halving): the
// usual hand-written parallel labelling on a CPU.
class ConcurrentUnionFind {
 public:
  explicit ConcurrentUnionFind(std::size_t n) : parent_(n) {
    for (std::size_t i = 0; i < n; ++i)
      parent_[i].store(static_cast<std::uint32_t>(i), std::memory_order_relaxed);
  }
  std::uint32_t find(std::uint32_t x) {
    for (;;) {
      std::uint32_t px = parent_[x].load(std::memory_order_acquire);
      if (px == x) return x;
      const std::uint32_t gp = parent_[px].load(std::memory_order_acquire);
      if (gp != px) parent_[x].compare_exchange_weak(px, gp, std::memory_order_acq_rel);
      x = gp;
    }
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    for (;;) {
      a = find(a);
      b = find(b);
      if (a == b) return;
      if (a < b) std::swap(a, b);
      std::uint32_t expected = a;
      if (parent_[a].compare_exchange_strong(expected, b, std::memory_order_acq_rel)) return;
    }
  }

 private:
  std::vector<std::atomic<std::uint32_t>> parent_;
};

// The reference labelling over the solver's sorted particles and cell ranges: pairs (i, j > i) found by the
// device's grid walk, united; each particle's label is the largest id under its root.
std::vector<std::uint32_t> reference_labels(const HostParticles& p,
                                            const std::vector<std::uint32_t>& cell_start,
                                            const Solver::GridInfo& g, float radius) {
  const auto n = static_cast<std::uint32_t>(p.size());
  const float r2 = radius * radius;
  const float inv[3] = {1.0f / g.cells.x(), 1.0f / g.cells.y(), 1.0f / g.cells.z()};
  const int dims[3] = {g.nx, g.ny, g.nz};
  const int reach = g.reach;
  ConcurrentUnionFind uf(n);
#pragma omp parallel for schedule(dynamic, 512)
  for (std::uint32_t i = 0; i < n; ++i) {
    if (p.phase[i] != kIce) continue;
    const Float4 xi = p.position[i];
    int c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(static_cast<int>(std::floor((xi[a] - g.origin[a]) * inv[a])), 0, dims[a] - 1);
    for (int z = std::max(c[2] - reach, 0); z <= std::min(c[2] + reach, g.nz - 1); ++z)
      for (int y = std::max(c[1] - reach, 0); y <= std::min(c[1] + reach, g.ny - 1); ++y) {
        const int row = (z * g.ny + y) * g.nx;
        const std::uint32_t jb = std::max(cell_start[row + std::max(c[0] - reach, 0)], i + 1);
        const std::uint32_t je = cell_start[row + std::min(c[0] + reach, g.nx - 1) + 1];
        for (std::uint32_t j = jb; j < je; ++j) {
          if (p.phase[j] != kIce) continue;
          const float dx = xi[0] - p.position[j][0], dy = xi[1] - p.position[j][1],
                      dz = xi[2] - p.position[j][2];
          if (dx * dx + dy * dy + dz * dz < r2) uf.unite(i, j);
        }
      }
  }
  std::vector<std::uint32_t> root(n, kNoLabel), top(n, 0), label(n, kNoLabel);
#pragma omp parallel for
  for (std::uint32_t i = 0; i < n; ++i)
    if (p.phase[i] == kIce) root[i] = uf.find(i);
  for (std::uint32_t i = 0; i < n; ++i)
    if (root[i] != kNoLabel) top[root[i]] = std::max(top[root[i]], p.id[i]);
#pragma omp parallel for
  for (std::uint32_t i = 0; i < n; ++i)
    if (root[i] != kNoLabel) label[i] = top[root[i]];
  return label;
}

using Terms = std::array<double, 16>;

// The reference sums: one plain loop in double (the 16 sums of body_sums.cl and the counts); with
// `magnitudes`, the sums of the terms' magnitudes instead (of the products in each torque term): the scale
// errors are measured against.
void reference_sums(const HostParticles& p, const std::vector<Float4>& force,
                    const std::vector<std::uint32_t>& body, const std::vector<float>& mass_scale,
                    const std::vector<Float4>& ref, bool magnitudes, std::vector<Terms>& sums,
                    std::vector<std::uint32_t>& counts) {
  sums.assign(ref.size(), Terms{});
  counts.assign(ref.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::uint32_t b = body[i];
    if (b == kNoBody) continue;
    const double m = double(p.position[i][3] * mass_scale[p.material[i]]);
    const double rx = double(p.position[i][0]) - ref[b][0], ry = double(p.position[i][1]) - ref[b][1],
                 rz = double(p.position[i][2]) - ref[b][2];
    const double fx = force[i][0], fy = force[i][1], fz = force[i][2];
    const Terms v = {m,
                     m * rx,
                     m * ry,
                     m * rz,
                     m * rx * rx,
                     m * ry * ry,
                     m * rz * rz,
                     m * rx * ry,
                     m * rx * rz,
                     m * ry * rz,
                     fx,
                     fy,
                     fz,
                     ry * fz - rz * fy,
                     rz * fx - rx * fz,
                     rx * fy - ry * fx};
    Terms& s = sums[b];
    if (magnitudes) {
      // Each torque term is a difference of products, and its float error scales with the products.
      const double ax = std::abs(rx), ay = std::abs(ry), az = std::abs(rz);
      const double gx = std::abs(fx), gy = std::abs(fy), gz = std::abs(fz);
      const Terms a = {v[0],
                       v[1],
                       v[2],
                       v[3],
                       v[4],
                       v[5],
                       v[6],
                       v[7],
                       v[8],
                       v[9],
                       v[10],
                       v[11],
                       v[12],
                       ay * gz + az * gy,
                       az * gx + ax * gz,
                       ax * gy + ay * gx};
      for (std::size_t k = 0; k < v.size(); ++k) s[k] += std::abs(a[k]);
    } else {
      for (std::size_t k = 0; k < v.size(); ++k) s[k] += v[k];
    }
    ++counts[b];
  }
}

// The reference ice-force pass (sim/kernels/rigid.cl, rigid_forces) over the same sorted particles and
// grid walk: for each ice particle, the reaction to the water's pressure and viscosity forces from it as
// a boundary particle. Contacts are left out: the bench's bodies are a water layer apart.
void reference_ice_forces(const HostParticles& p, const std::vector<Float4>& state,
                          const std::vector<std::uint32_t>& cell_start, const Solver::GridInfo& g, float H,
                          float eps2, float visc_boundary, float rho0, std::vector<Float4>& out) {
  const auto n = static_cast<std::uint32_t>(p.size());
  const float inv[3] = {1.0f / g.cells.x(), 1.0f / g.cells.y(), 1.0f / g.cells.z()};
  const int dims[3] = {g.nx, g.ny, g.nz};
  const int reach = g.reach;
  const float H2 = H * H;
  out.assign(n, Float4{0.f, 0.f, 0.f, 0.f});
#pragma omp parallel for schedule(dynamic, 256)
  for (std::uint32_t i = 0; i < n; ++i) {
    if (p.phase[i] != kIce) continue;
    const Float4 xi = p.position[i], vi = p.velocity[i];
    const float rho_i = state[i][0], dpi = state[i][1];
    int c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(static_cast<int>(std::floor((xi[a] - g.origin[a]) * inv[a])), 0, dims[a] - 1);
    float f[3] = {0.f, 0.f, 0.f};
    for (int z = std::max(c[2] - reach, 0); z <= std::min(c[2] + reach, g.nz - 1); ++z)
      for (int y = std::max(c[1] - reach, 0); y <= std::min(c[1] + reach, g.ny - 1); ++y) {
        const int row = (z * g.ny + y) * g.nx;
        const std::uint32_t jb = cell_start[row + std::max(c[0] - reach, 0)];
        const std::uint32_t je = cell_start[row + std::min(c[0] + reach, g.nx - 1) + 1];
        for (std::uint32_t j = jb; j < je; ++j) {
          if (p.phase[j] != static_cast<std::uint8_t>(Phase::Water)) continue;
          const float d[3] = {xi[0] - p.position[j][0], xi[1] - p.position[j][1], xi[2] - p.position[j][2]};
          const float r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
          if (r2 >= H2) continue;
          const float mj = p.position[j][3];
          const float vd = (vi[0] - p.velocity[j][0]) * d[0] + (vi[1] - p.velocity[j][1]) * d[1] +
                           (vi[2] - p.velocity[j][2]) * d[2];
          const float s =
              visc_boundary * mj * (rho0 / (rho_i * state[j][0])) * vd / (r2 + eps2) - mj * (dpi + state[j][1]);
          const float gf = s * sph::cubic_spline_grad_factor(std::sqrt(r2), H);
          for (int a = 0; a < 3; ++a) f[a] += gf * d[a];
        }
      }
    out[i] = {xi[3] * f[0], xi[3] * f[1], xi[3] * f[2], 0.f};
  }
}

template <class F>
double best_of(int reps, const std::function<void()>& pause, F&& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < reps; ++r) {
    pause();
    const auto t0 = Clock::now();
    f();
    best = std::min(best, seconds_since(t0));
  }
  return best;
}

}  // namespace

Json bench_bodies(ClRuntime& cl, const BodiesBenchOptions& o, bool print) {
  if (o.particles < 1000) throw Error("bench bodies: --size must be at least 1000 particles");
  if (!(o.radius > 0.0) || o.radius > 2.0) throw Error("bench bodies: --radius must be in (0, 2] spacings");
  const int side = static_cast<int>(std::lround(std::cbrt(double(o.particles))));
  const double dx = 0.01;
  const Scene scene = bench_scene(side, dx);
  const auto water = static_cast<std::uint8_t>(material_index(scene, "water"));
  const auto ice = static_cast<std::uint8_t>(material_index(scene, "ice"));
  SimState st;
  st.particles = bench_lattice(side, dx, water, ice);
  st.dt = 1e-4;

  // The solver's own grid build sorts the particles (ids no longer match sorted indices).
  Solver solver(cl, scene, st);
  solver.build_grid();
  cl.queue().finish();
  const HostParticles p = solver.particles();
  const std::vector<std::uint32_t> cell_start = solver.cell_starts();
  const Solver::GridInfo& gi = solver.grid();
  const auto n = static_cast<std::uint32_t>(p.size());
  const std::size_t ice_count = p.count(Phase::Ice);
  const float radius = static_cast<float>(o.radius * dx);
  const ClGrid grid{{{gi.origin.x(), gi.origin.y(), gi.origin.z(), 0.f}},
                    {{1.0f / gi.cells.x(), 1.0f / gi.cells.y(), 1.0f / gi.cells.z(), 0.f}},
                    gi.nx,
                    gi.ny,
                    gi.nz};

  SortedIceParticles sp;
  sp.position = upload(cl, p.position);
  sp.phase = upload(cl, p.phase);
  sp.cell_start = upload(cl, cell_start);
  sp.n = n;
  sp.id_capacity = n;
  cl::Buffer label(cl.context(), CL_MEM_READ_WRITE, std::size_t(n) * 4);
  cl::Buffer body(cl.context(), CL_MEM_READ_WRITE, std::size_t(n) * 4);
  IceLabeller labeller(cl, gi.reach);

  // pocl's and OpenMP's worker threads spin a while after a parallel section: a pause before each timed
  // run lets the other's go to sleep first (as `thaw bench throughput`).
  const std::function<void()> pause = [] { std::this_thread::sleep_for(std::chrono::milliseconds(20)); };
  const double per = 1e6 / double(n);

  // Labelling, with ids in creation order (as sampled) and shuffled (as water that froze after mixing),
  // for plain max propagation, pointer jumps and hooks; the reference alternates with the device runs.
  struct Variant {
    const char* name;
    LabelOptions options;
  };
  const Variant variants[] = {{"plain max propagation", {0, false}},
                              {"1 jump a sweep (Iwasaki)", {1, false}},
                              {"4 jumps", {4, false}},
                              {"hooks + 1 jump", {1, true}},
                              {"hooks + 4 jumps (default)", {4, true}}};
  std::vector<std::uint32_t> shuffled(n);
  std::iota(shuffled.begin(), shuffled.end(), 0u);
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(17));
  Json label_runs = Json::array();
  for (const bool shuffle : {false, true}) {
    HostParticles q = p;
    if (shuffle)
      for (auto& id : q.id) id = shuffled[id];
    sp.id = upload(cl, q.id);
    std::vector<std::uint32_t> ref_label = reference_labels(q, cell_start, gi, radius);  // warms the threads
    double ref_s = std::numeric_limits<double>::infinity();
    Json rows = Json::array();
    bool match = true;
    for (const Variant& v : variants) {
      labeller.label(sp, grid, radius, label, v.options);  // first enqueues compile
      const double t = best_of(o.reps, pause, [&] { labeller.label(sp, grid, radius, label, v.options); });
      const std::uint32_t sweeps = labeller.last_sweeps();
      ref_s = std::min(ref_s, best_of(std::max(1, o.reps / 3), pause,
                                      [&] { ref_label = reference_labels(q, cell_start, gi, radius); }));
      std::vector<std::uint32_t> got(n);
      cl.queue().enqueueReadBuffer(label, CL_TRUE, 0, std::size_t(n) * 4, got.data());
      match = match && got == ref_label;
      rows.push_back({{"variant", v.name},
                      {"jumps", v.options.jumps},
                      {"hooks", v.options.hook},
                      {"sweeps", sweeps},
                      {"label_us", t * per}});
    }
    label_runs.push_back({{"ids", shuffle ? "shuffled" : "creation order"},
                          {"variants", rows},
                          {"reference_label_us", ref_s * per},
                          {"labels_match_reference", match}});
  }

  // Compaction and the sums on the bodies of the ids in creation order.
  sp.id = upload(cl, p.id);
  labeller.label(sp, grid, radius, label);
  IceBodies bodies;
  const double compact_s =
      best_of(o.reps, pause, [&] { bodies = labeller.compact(label, n, sp.id_capacity, body); });

  // As the solver labels: grouped by the bodies of the last labelling (each particle's body), the default
  // options. The lattice's bodies do not touch, so the labels are the union-find's.
  sp.group = body;
  labeller.label(sp, grid, radius, label);
  const double grouped_s = best_of(o.reps, pause, [&] { labeller.label(sp, grid, radius, label); });
  const std::uint32_t grouped_sweeps = labeller.last_sweeps();
  std::vector<std::uint32_t> grouped_label(n);
  cl.queue().enqueueReadBuffer(label, CL_TRUE, 0, std::size_t(n) * 4, grouped_label.data());
  const bool grouped_match = grouped_label == reference_labels(p, cell_start, gi, radius);
  sp.group = cl::Buffer();

  // Per-body sums: m g plus a little of everything as the force, references near each body's centre.
  std::vector<float> mass_scale(scene.materials.size(), 1.0f);
  mass_scale[ice] = static_cast<float>(scene.materials[ice].density / 1000.0);
  std::vector<std::uint32_t> host_body(n);
  cl.queue().enqueueReadBuffer(body, CL_TRUE, 0, std::size_t(n) * 4, host_body.data());
  std::vector<Float4> force(n);
  std::vector<Eigen::Vector3d> centre(bodies.size(), Eigen::Vector3d::Zero());
  for (std::uint32_t i = 0; i < n; ++i) {
    const float m = p.position[i][3];
    force[i] = {1e-3f * std::sin(float(i)), 1e-3f * std::cos(float(i)), -9.81f * m, 0.f};
    if (host_body[i] != kNoBody)
      centre[host_body[i]] += Eigen::Vector3d(p.position[i][0], p.position[i][1], p.position[i][2]);
  }
  std::vector<Float4> ref(bodies.size());
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    const Eigen::Vector3d c = centre[b] / double(bodies.counts[b]);
    ref[b] = {float(c.x()) + 0.001f, float(c.y()), float(c.z()) - 0.002f, 0.f};
  }
  BodyReducer reducer(cl, mass_scale);
  BodyParticles bp;
  bp.position = sp.position;
  bp.material = upload(cl, p.material);
  bp.force = upload(cl, force);
  bp.body = body;
  bp.n = n;
  const auto nbodies = static_cast<std::uint32_t>(bodies.size());
  const cl::Buffer ref_buf = upload(cl, ref.empty() ? std::vector<Float4>(1) : ref);
  std::vector<BodySums> sums = reducer.reduce(bp, ref_buf, nbodies);
  std::vector<Terms> ref_sums;
  std::vector<std::uint32_t> ref_counts;
  double sums_s = std::numeric_limits<double>::infinity(), ref_sums_s = sums_s;
  for (int r = 0; r < o.reps; ++r) {
    sums_s = std::min(sums_s, best_of(1, pause, [&] { sums = reducer.reduce(bp, ref_buf, nbodies); }));
    ref_sums_s = std::min(ref_sums_s, best_of(1, pause, [&] {
                            reference_sums(p, force, host_body, mass_scale, ref, false, ref_sums, ref_counts);
                          }));
  }
  // Error of each device sum relative to the sum of its terms' magnitudes (sums like m r about a point
  // near the centre of mass nearly cancel).
  std::vector<Terms> scale;
  std::vector<std::uint32_t> unused;
  reference_sums(p, force, host_body, mass_scale, ref, true, scale, unused);
  double worst = 0;
  bool counts_match = true;
  for (std::uint32_t b = 0; b < nbodies; ++b) {
    const Terms got = sums[b].terms();
    for (std::size_t k = 0; k < got.size(); ++k) {
      const double err = std::abs(got[k] - ref_sums[b][k]);
      worst = std::max(worst, scale[b][k] > 0 ? err / scale[b][k] : err);
    }
  }
  for (std::uint32_t b = 0; b < nbodies; ++b) counts_match = counts_match && sums[b].count == ref_counts[b];

  // Coupling: the ice-force pass against the reference loop, on the density pass's pressure state.
  solver.compute_density();
  solver.label_ice();
  const std::vector<Float4> pstate = solver.pressure_state();
  const SolverConstants& sc = solver.constants();
  const float eps2 = 0.01f * sc.smoothing * sc.smoothing;
  std::vector<Float4> ref_force;
  double force_s = std::numeric_limits<double>::infinity(), ref_force_s = force_s;
  for (int r = 0; r < o.reps; ++r) {
    force_s = std::min(force_s, best_of(1, pause, [&] {
                         solver.compute_ice_forces();
                         cl.queue().finish();
                       }));
    ref_force_s = std::min(ref_force_s, best_of(1, pause, [&] {
                             reference_ice_forces(p, pstate, cell_start, gi, sc.support, eps2,
                                                  sc.visc_boundary, sc.rest_density, ref_force);
                           }));
  }
  const std::vector<Float4> dev_force = solver.ice_forces();
  double force_scale = 0, force_err = 0;
  for (std::uint32_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      force_scale = std::max(force_scale, double(std::abs(ref_force[i][a])));
      force_err = std::max(force_err, double(std::abs(dev_force[i][a] - ref_force[i][a])));
    }
  const double force_rel = force_scale > 0 ? force_err / force_scale : force_err;

  Json out;
  out["device"] = cl.description();
  out["omp_threads"] = omp_get_max_threads();
  out["unit"] = "wall microseconds per particle (of the whole set), fastest of the timed runs";
  out["particles"] = n;
  out["ice_particles"] = ice_count;
  out["bodies"] = nbodies;
  out["radius_spacings"] = o.radius;
  out["grid_reach"] = gi.reach;
  out["labelling"] = label_runs;
  out["grouped_label_us"] = grouped_s * per;
  out["grouped_sweeps"] = grouped_sweeps;
  out["grouped_labels_match_reference"] = grouped_match;
  out["compact_us"] = compact_s * per;
  out["sums_us"] = sums_s * per;
  out["reference_sums_us"] = ref_sums_s * per;
  out["sums_counts_match_reference"] = counts_match;
  out["sums_max_err_of_sum_of_magnitudes"] = worst;
  out["ice_forces_us"] = force_s * per;
  out["reference_ice_forces_us"] = ref_force_s * per;
  out["ice_forces_max_err_of_largest"] = force_rel;
  if (print) {
    std::printf("%u particles (%zu ice in %u bodies), connection radius %.2f spacings, grid reach %d; %s\n",
                n, ice_count, nbodies, o.radius, gi.reach, cl.description().c_str());
    std::printf("%-28s %22s | %22s\n", "labelling", "ids in creation order", "ids shuffled");
    std::printf("%-28s %10s %11s | %10s %11s\n", "", "us/part", "sweeps", "us/part", "sweeps");
    for (std::size_t k = 0; k < std::size(variants); ++k) {
      const Json& a = label_runs[0]["variants"][k];
      const Json& b = label_runs[1]["variants"][k];
      std::printf("%-28s %10.4f %11u | %10.4f %11u\n", variants[k].name, double(a["label_us"]),
                  unsigned(a["sweeps"]), double(b["label_us"]), unsigned(b["sweeps"]));
    }
    const bool match =
        bool(label_runs[0]["labels_match_reference"]) && bool(label_runs[1]["labels_match_reference"]);
    std::printf("%-28s %10.4f %11s | %10.4f %11s   (labels %s)\n", "reference union-find (OMP)",
                double(label_runs[0]["reference_label_us"]), "-", double(label_runs[1]["reference_label_us"]),
                "-", match ? "match" : "DIFFER");
    std::printf("%-28s %10.4f %11u   (grouped by the last bodies, as the solver; labels %s)\n",
                "hooks + 4 jumps, grouped", grouped_s * per, grouped_sweeps,
                grouped_match ? "match" : "DIFFER");
    std::printf("%-28s %10.4f\n", "compaction (host)", compact_s * per);
    std::printf("%-28s %10.4f\n", "body sums, device", sums_s * per);
    std::printf("%-28s %10.4f   (max error / sum of |terms| %.2e, counts %s)\n", "body sums, reference loop",
                ref_sums_s * per, worst, counts_match ? "match" : "DIFFER");
    std::printf("%-28s %10.4f\n", "ice forces, device", force_s * per);
    std::printf("%-28s %10.4f   (max error / largest force %.2e)\n", "ice forces, reference loop",
                ref_force_s * per, force_rel);
    std::printf(
        "(labelling: IceLabeller::label, one walk for the neighbour lists, then sweeps with a flag read back "
        "after each;\n ids shuffled: a random permutation, as water that froze after mixing; reference: "
        "union-find on %d OpenMP\n threads over the same sorted data and grid walk; compaction: "
        "IceLabeller::compact, labels to body indices on the\n host; body sums: BodyReducer::reduce against "
        "one "
        "plain loop in double)\n",
        omp_get_max_threads());
  }
  return out;
}

}  // namespace thaw
