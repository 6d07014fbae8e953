#include "sim/ice_bodies.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sim/cl_launch.h"
#include "sim/error.h"
#include "sim/particles.h"
#include "sim/stage.h"

namespace thaw {
namespace {

static_assert(static_cast<int>(Phase::Ice) == 1, "THAW_PHASE_ICE in sim/kernels/grid_common.h");

// SIMD lanes of the neighbour walk (THAW_VW): 8, as the solver's neighbour passes.
constexpr int kLanes = 8;

// Length of each coordinate block of the walk's points: the lanes read up to kLanes - 1 past the last.
std::size_t points_stride(std::size_t n) { return (n + kLanes + 15) / 16 * 16; }

// Particles per work-item of a label sweep: 16 took about a third less time than 1 per sweep at 100k
// particles, half of them ice (`thaw bench bodies`, plain max propagation).
constexpr std::uint32_t kSweepTile = 16;

// Particles per chunk of the grouped order in the body sums: a body of 50k particles is summed by 200
// work-items, and each piece is a short compensated sum.
constexpr std::uint32_t kChunk = 256;

// Sum terms per particle (body_terms in body_sums.cl): m, m r (3), m r r^T (6), f (3), r x f (3).
constexpr std::size_t kTerms = 16;

cl::Buffer buffer(ClRuntime& cl, std::size_t bytes) {
  return cl::Buffer(cl.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, 4));
}

// Grows buf to hold at least `count` elements of `size` bytes, by half again at least (contents are not
// kept): scratch sized by particle, body and id counts that change from call to call.
void ensure(ClRuntime& cl, cl::Buffer& buf, std::size_t& cap, std::size_t count, std::size_t size) {
  if (count <= cap && cap > 0) return;
  cap = std::max<std::size_t>({count, cap + cap / 2, 1});
  buf = buffer(cl, cap * size);
}

}  // namespace

IceLabeller::IceLabeller(ClRuntime& cl, int reach) : cl_(cl), reach_(reach) {
  if (reach < 1) throw Error("ice labels: grid reach " + std::to_string(reach) + "; must be at least 1");
  const auto program =
      cl.build({"grid_common.h", "ice_labels.cl"},
               "-DTHAW_VW=" + std::to_string(kLanes) + " -DTHAW_SWEEP_TILE=" + std::to_string(kSweepTile));
  k_points_ = cl::Kernel(program, "ice_points");
  k_neighbours_ = cl::Kernel(program, "ice_neighbours");
  k_slots_ = cl::Kernel(program, "label_slots");
  k_propagate_ = cl::Kernel(program, "propagate_labels");
  changed_ = buffer(cl, 4);
  overflow_ = buffer(cl, 4);
  bad_ = buffer(cl, 4);
}

std::uint32_t IceLabeller::label(const SortedIceParticles& p, const ClGrid& grid, float radius,
                                 cl::Buffer& label, const LabelOptions& options) {
  if (!(radius > 0.0f) || !std::isfinite(radius))
    throw Error("ice labels: connection radius " + std::to_string(radius) +
                " m; must be positive and finite");
  // A few float roundings of slack: a cell given as exactly the radius has an inverse rounded either way.
  for (int a = 0; a < 3; ++a) {
    const double inv = grid.inv_cell.s[a];
    if (double(radius) * inv > double(reach_) * (1.0 + 4.0 * std::numeric_limits<float>::epsilon()))
      throw Error("ice labels: connection radius " + std::to_string(radius) +
                  " m exceeds the grid's reach: " + std::to_string(reach_) + " cell(s) of " +
                  std::to_string(1.0 / inv) + " m along " + "xyz"[a]);
  }
  sweeps_ = 0;
  const std::uint32_t n = p.n;
  if (n == 0) return 0;
  if (p.id_capacity == 0) throw Error("ice labels: id_capacity is 0 for " + std::to_string(n) + " particles");
  auto& q = cl_.queue();
  if (n > particles_cap_) {
    particles_cap_ = std::max<std::size_t>(n, particles_cap_ + particles_cap_ / 2);
    degree_ = buffer(cl_, particles_cap_ * 4);
    spare_label_ = buffer(cl_, particles_cap_ * 4);
    points_ = buffer(cl_, points_stride(particles_cap_) * 4 * 4);
    hooks_[0] = buffer(cl_, particles_cap_ * 4);
    hooks_[1] = buffer(cl_, particles_cap_ * 4);
    edges_cap_ = 0;
  }
  if (p.id_capacity > ids_cap_) {
    ids_cap_ = std::max<std::size_t>(p.id_capacity, ids_cap_ + ids_cap_ / 2);
    slot_of_ = buffer(cl_, ids_cap_ * 4);
  }

  const cl_uint none = 0xffffffffu, zero = 0;
  q.enqueueWriteBuffer(bad_, CL_FALSE, 0, 4, &none);
  set_args(k_slots_, p.id, slot_of_, p.id_capacity, bad_, n);
  launch(q, k_slots_, n);
  const auto stride = static_cast<cl_uint>(points_stride(n));
  // Without groups the kernel reads none: any buffer stands in for the argument.
  const bool grouped = p.group() != nullptr;
  set_args(k_points_, p.position, p.phase, grouped ? p.group : p.id, cl_uint(grouped ? 1 : 0), points_,
           stride, n);
  launch(q, k_points_, stride);
  // The neighbour rows: walked again, wider, in the rare call where a particle has more neighbours than
  // the rows hold (the width only grows, so the next calls walk once).
  for (;;) {
    if (edges_cap_ < particles_cap_ * width_) {
      edges_cap_ = particles_cap_ * width_;
      edges_ = buffer(cl_, edges_cap_ * 4);
    }
    q.enqueueWriteBuffer(overflow_, CL_FALSE, 0, 4, &zero);
    set_args(k_neighbours_, points_, stride, p.id, p.cell_start, grid, radius, width_, edges_, degree_,
             overflow_, label, n);
    launch(q, k_neighbours_, n);
    cl_uint bad = 0, overflow = 0;
    q.enqueueReadBuffer(overflow_, CL_FALSE, 0, 4, &overflow);
    q.enqueueReadBuffer(bad_, CL_TRUE, 0, 4, &bad);
    if (bad != none) {
      cl_uint id = 0;
      q.enqueueReadBuffer(p.id, CL_TRUE, std::size_t(bad) * 4, 4, &id);
      throw Error("ice labels: particle " + std::to_string(bad) + " (sorted index) has id " +
                  std::to_string(id) + ", not below id_capacity " + std::to_string(p.id_capacity));
    }
    if (overflow <= width_) break;
    width_ = (overflow + 7) / 8 * 8;
  }

  // Jacobi sweeps between the caller's buffer and the spare one. The last sweep changes nothing, so both
  // then hold the result and no copy is needed. Labels only rise and each sweep that changes something
  // moves some label at least one neighbour further, so n + 1 sweeps always suffice. The two hook
  // buffers alternate too: one sweep reads the hooks the last one wrote into one and adds its own to the
  // other (on top of older hooks, which are still valid labels of the same body: no clearing needed).
  if (options.hook) {
    q.enqueueFillBuffer(hooks_[0], zero, 0, std::size_t(n) * 4);
    q.enqueueFillBuffer(hooks_[1], zero, 0, std::size_t(n) * 4);
  }
  cl::Buffer* in = &label;
  cl::Buffer* out = &spare_label_;
  for (;;) {
    if (sweeps_ > n + 1)
      throw Error("ice labels: no convergence after " + std::to_string(sweeps_) + " sweeps");
    q.enqueueWriteBuffer(changed_, CL_FALSE, 0, 4, &zero);
    set_args(k_propagate_, degree_, edges_, width_, slot_of_, *in, *out, options.jumps,
             cl_uint(options.hook ? 1 : 0), hooks_[sweeps_ % 2], hooks_[(sweeps_ + 1) % 2], changed_, n);
    launch(q, k_propagate_, (n + kSweepTile - 1) / kSweepTile);
    cl_uint changed = 0;
    q.enqueueReadBuffer(changed_, CL_TRUE, 0, 4, &changed);
    ++sweeps_;
    std::swap(in, out);
    if (!changed) break;
  }
  return sweeps_;
}

IceBodies IceLabeller::compact(const cl::Buffer& label, std::uint32_t n, std::uint32_t id_capacity,
                               cl::Buffer& body) {
  IceBodies out;
  if (n == 0) return out;
  auto& q = cl_.queue();
  host_labels_.resize(n);
  q.enqueueReadBuffer(label, CL_TRUE, 0, std::size_t(n) * 4, host_labels_.data());
  // lookup_ maps a label to its body; between calls every entry is kNoBody. The first pass marks the
  // labels seen (any value other than kNoBody).
  if (lookup_.size() < id_capacity) lookup_.resize(id_capacity, kNoBody);
  auto unmark = [&] {
    for (std::uint32_t l : out.labels) lookup_[l] = kNoBody;
  };
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t l = host_labels_[i];
    if (l == kNoLabel) continue;
    if (l >= id_capacity) {
      unmark();
      throw Error("ice bodies: particle " + std::to_string(i) + " has label " + std::to_string(l) +
                  ", not below id_capacity " + std::to_string(id_capacity));
    }
    if (lookup_[l] == kNoBody) {
      lookup_[l] = 0;
      out.labels.push_back(l);
    }
  }
  std::sort(out.labels.begin(), out.labels.end());
  for (std::size_t b = 0; b < out.labels.size(); ++b) lookup_[out.labels[b]] = static_cast<std::uint32_t>(b);
  out.counts.assign(out.labels.size(), 0);
  host_body_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t l = host_labels_[i];
    const std::uint32_t b = l == kNoLabel ? kNoBody : lookup_[l];
    host_body_[i] = b;
    if (b != kNoBody) ++out.counts[b];
  }
  unmark();
  q.enqueueWriteBuffer(body, CL_TRUE, 0, std::size_t(n) * 4, host_body_.data());
  return out;
}

IceBodies IceLabeller::find_bodies(const SortedIceParticles& p, const ClGrid& grid, float radius,
                                   cl::Buffer& label, cl::Buffer& body, const LabelOptions& options) {
  this->label(p, grid, radius, label, options);
  return compact(label, p.n, p.id_capacity, body);
}

BodyReducer::BodyReducer(ClRuntime& cl, const std::vector<float>& mass_scale) : cl_(cl) {
  if (mass_scale.empty()) throw Error("body sums: the mass-scale table is empty");
  if (mass_scale.size() > 256)
    throw Error("body sums: " + std::to_string(mass_scale.size()) +
                " materials; the material byte holds 256");
  materials_ = static_cast<std::uint32_t>(mass_scale.size());
  mass_scale_ = cl::Buffer(cl.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                           mass_scale.size() * sizeof(float), const_cast<float*>(mass_scale.data()));
  const auto program = cl.build({"body_sums.cl"});
  k_hist_ = cl::Kernel(program, "body_histogram");
  k_scan_ = cl::Kernel(program, "body_scan");
  k_offsets_ = cl::Kernel(program, "body_offsets");
  k_scatter_ = cl::Kernel(program, "body_scatter");
  k_pieces_ = cl::Kernel(program, "body_pieces");
  k_totals_ = cl::Kernel(program, "body_totals");
  bad_ = buffer(cl, 8);
}

std::vector<BodySums> BodyReducer::reduce(const BodyParticles& p, const cl::Buffer& reference,
                                          std::uint32_t nbodies) {
  std::vector<BodySums> out(nbodies);
  if (nbodies == 0 || p.n == 0) return out;
  auto& q = cl_.queue();
  const std::uint32_t n = p.n;
  // The solver's tiles (sim/stage.h): 32 on a CPU, thousands on a GPU. The per-body sums do not depend on
  // them (the scatter is stable and the pieces are chunks of the grouped order).
  const std::uint32_t tile = layout_for(n, n, cl_.layout_tiles()).tile;
  const std::uint32_t ntiles = (n + tile - 1) / tile;
  const std::uint32_t nchunks = (n + kChunk - 1) / kChunk;
  ensure(cl_, hist_, hist_cap_, std::size_t(ntiles) * nbodies, 4);
  if (nbodies > bodies_cap_) {
    bodies_cap_ = std::max<std::size_t>(nbodies, bodies_cap_ + bodies_cap_ / 2);
    count_ = buffer(cl_, bodies_cap_ * 4);
    offsets_ = buffer(cl_, (bodies_cap_ + 1) * 4);
    totals_ = buffer(cl_, bodies_cap_ * 2 * kTerms * 4);
  }
  ensure(cl_, order_, particles_cap_, n, 4);
  ensure(cl_, pieces_, pieces_cap_, std::size_t(nchunks) + nbodies, 2 * kTerms * 4);

  const cl_uint none[2] = {0xffffffffu, 0xffffffffu};
  q.enqueueWriteBuffer(bad_, CL_FALSE, 0, 8, none);
  set_args(k_hist_, p.body, hist_, bad_, n, tile, ntiles, nbodies);
  launch(q, k_hist_, ntiles);
  set_args(k_scan_, hist_, count_, ntiles, nbodies);
  launch(q, k_scan_, nbodies);
  set_args(k_offsets_, count_, offsets_, nbodies);
  launch(q, k_offsets_, 1);
  set_args(k_scatter_, p.body, hist_, offsets_, order_, n, tile, ntiles, nbodies);
  launch(q, k_scatter_, ntiles);
  set_args(k_pieces_, order_, offsets_, p.body, p.position, p.material, mass_scale_, materials_, p.force,
           reference, pieces_, bad_, nbodies, kChunk);
  launch(q, k_pieces_, nchunks);
  set_args(k_totals_, pieces_, offsets_, totals_, nbodies, kChunk);
  launch(q, k_totals_, nbodies);

  std::vector<cl_uint> counts(nbodies);
  std::vector<float> totals(std::size_t(nbodies) * 2 * kTerms);
  cl_uint bad[2] = {0, 0};
  q.enqueueReadBuffer(bad_, CL_FALSE, 0, 8, bad);
  q.enqueueReadBuffer(count_, CL_FALSE, 0, std::size_t(nbodies) * 4, counts.data());
  q.enqueueReadBuffer(totals_, CL_TRUE, 0, totals.size() * 4, totals.data());
  if (bad[0] != none[0]) {
    cl_uint b = 0;
    q.enqueueReadBuffer(p.body, CL_TRUE, std::size_t(bad[0]) * 4, 4, &b);
    throw Error("body sums: particle " + std::to_string(bad[0]) + " has body " + std::to_string(b) +
                ", neither below " + std::to_string(nbodies) + " bodies nor kNoBody");
  }
  if (bad[1] != none[1]) {
    cl_uchar m = 0;
    q.enqueueReadBuffer(p.material, CL_TRUE, bad[1], 1, &m);
    throw Error("body sums: particle " + std::to_string(bad[1]) + " has material " + std::to_string(m) +
                ", outside the mass-scale table of " + std::to_string(materials_));
  }
  for (std::uint32_t b = 0; b < nbodies; ++b) {
    const float* hi = &totals[std::size_t(b) * 2 * kTerms];
    const float* lo = hi + kTerms;
    double v[kTerms];
    for (std::size_t k = 0; k < kTerms; ++k) v[k] = double(hi[k]) + double(lo[k]);
    BodySums& s = out[b];
    s.count = counts[b];
    s.mass = v[0];
    s.first_moment = {v[1], v[2], v[3]};
    s.second_moment << v[4], v[7], v[8],  //
        v[7], v[5], v[9],                 //
        v[8], v[9], v[6];
    s.force = {v[10], v[11], v[12]};
    s.torque = {v[13], v[14], v[15]};
  }
  return out;
}

}  // namespace thaw
