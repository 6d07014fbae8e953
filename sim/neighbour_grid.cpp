#include "sim/neighbour_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "sim/cl_launch.h"
#include "sim/emitters.h"
#include "sim/error.h"

namespace thaw {

namespace {
// Tiles per chunk of the sort's scan (grid.cl): a CPU's 32 tiles are one chunk, a GPU's thousands many.
constexpr cl_uint kScanChunk = 32;
}  // namespace

ClGrid cl_grid(const GridInfo& gi) {
  return {{{gi.origin.x(), gi.origin.y(), gi.origin.z(), 0.f}},
          {{1.0f / gi.cells.x(), 1.0f / gi.cells.y(), 1.0f / gi.cells.z(), 0.f}},
          gi.nx,
          gi.ny,
          gi.nz};
}

NeighbourGrid::NeighbourGrid(ClRuntime& cl, const Scene& scene, float support, int reach,
                             const std::string& build_options, const ParticleLayout& layout,
                             const Eigen::Vector3f& lo, const Eigen::Vector3f& hi)
    : cl_(cl), scene_(scene), layout_(layout), support_(support) {
  // A few ulps above H / reach, so float rounding in grid_cell() never puts a neighbour just inside the
  // support more than `reach` cells away.
  info_.cell = support / float(reach) * (1.0f + 8.0f * std::numeric_limits<float>::epsilon());
  info_.reach = reach;
  info_.origin = lo - Eigen::Vector3f::Constant(info_.cell);
  const Eigen::Vector3f ext = hi + Eigen::Vector3f::Constant(info_.cell) - info_.origin;
  // Counted in double and checked before any conversion to int: particles far out (or a tiny spacing)
  // would overflow an int cell count into a negative one that passed the check below.
  const Eigen::Vector3d count = (ext.cast<double>() / double(info_.cell)).array().ceil() + 1.0;
  if (!count.allFinite() || count.prod() > double(1u << 28)) {
    std::ostringstream needed;
    needed.precision(3);
    needed << count.prod();
    throw SceneError("spacing", "the neighbour grid would need " + needed.str() + " cells (at most " +
                                    std::to_string(1u << 28) + "); use a smaller domain or a larger spacing");
  }
  info_.nx = static_cast<int>(count.x());
  info_.ny = static_cast<int>(count.y());
  info_.nz = static_cast<int>(count.z());
  info_.cells = Eigen::Vector3f::Constant(info_.cell);
  // A periodic axis is cut into whole cells of at least H between the domain's faces, so the cells around
  // one wrap exactly (the scene guarantees at least three).
  int* counts[3] = {&info_.nx, &info_.ny, &info_.nz};
  for (int a = 0; a < 3; ++a) {
    if (!scene.solver.periodic[static_cast<std::size_t>(a)]) continue;
    const float length = static_cast<float>(scene.domain.max[a] - scene.domain.min[a]);
    *counts[a] = std::max(3, static_cast<int>(std::floor(length / info_.cell)));
    info_.cells[a] = length / float(*counts[a]);
    info_.origin[a] = static_cast<float>(scene.domain.min[a]);
  }
  ncells_ = static_cast<std::uint32_t>(double(info_.nx) * info_.ny * info_.nz);
  intake_ = scene.air_dryer_count() > 0;
  // With open sides or intakes the keys run to ncells: particles that left sort behind every cell.
  const std::uint32_t max_key = scene.open_faces || intake_ ? ncells_ : ncells_ - 1;
  int bits = 1;
  while (bits < 32 && max_key >> bits) ++bits;
  // The fewest radix passes of at most 11 bits, the key's bits spread evenly over them (17 bits: two
  // passes of 9 rather than three of 8).
  sort_passes_ = static_cast<std::uint32_t>((bits + 10) / 11);
  radix_bits_ = static_cast<std::uint32_t>((bits + int(sort_passes_) - 1) / int(sort_passes_));

  const bool room_air = EmitterStage::admits_room_air(scene);
  const auto program = cl.build(neighbour_program({"grid.cl"}),
                                build_options + " -DTHAW_RADIX_BITS=" + std::to_string(radix_bits_) +
                                    " -DTHAW_SCAN_CHUNK=" + std::to_string(kScanChunk) +
                                    (intake_ ? " -DTHAW_INTAKE" : "") + (room_air ? " -DTHAW_ROOM_AIR" : ""));
  k_cell_keys_ = cl::Kernel(program, "cell_keys");
  if (room_air) k_empty_sites_ = cl::Kernel(program, "empty_sites");
  if (intake_) {
    k_intake_flags_ = cl::Kernel(program, "intake_flags");
    k_set_flags_ = cl::Kernel(program, "set_flags");
    k_pipe_drive_ = cl::Kernel(program, "pipe_drive");
  }
  k_hist_ = cl::Kernel(program, "radix_histogram");
  k_chunk_counts_ = cl::Kernel(program, "radix_chunk_counts");
  k_scan_chunks_ = cl::Kernel(program, "radix_scan_chunks");
  k_scan_tiles_ = cl::Kernel(program, "radix_scan_tiles");
  k_scatter_ = cl::Kernel(program, "radix_scatter");
  k_starts_ = cl::Kernel(program, "cell_starts");

  auto& ctx = cl.context();
  const std::size_t n = std::max<std::size_t>(layout.capacity, 1);
  auto buf = [&](std::size_t bytes) {
    return cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<std::size_t>(bytes, 4));
  };
  for (int i = 0; i < 2; ++i) {
    keys_[i] = buf(n * 4);
    order_[i] = buf(n * 4);
  }
  hist_ = buf((std::size_t(1) << radix_bits_) * std::max<cl_uint>(layout.max_tiles, 1) * 4);
  totals_ = buf((std::size_t(1) << radix_bits_) * 4);
  chunks_ = buf((std::size_t(1) << radix_bits_) *
                ((std::max<cl_uint>(layout.max_tiles, 1) + kScanChunk - 1) / kScanChunk) * 4);
  cell_start_ = buf((std::size_t(ncells_) + 1) * 4);
  if (intake_) {
    intakes_ = buf(scene.dryers.size() * 4 * 16);
    take_ = buf(n);
    listed_ = buf(4);
    list_ = buf(n * 8);
  }
  soa_ = buf(std::size_t(layout.stride) * 7 * 4);
  // The padding past the last particle is read by masked lanes only; keep it finite anyway.
  cl.queue().enqueueFillBuffer(soa_, 0.0f, 0, std::size_t(layout.stride) * 7 * 4);
}

std::size_t NeighbourGrid::build(ParticleStore& store, const CoreFields& f, const cl::Buffer& clamped,
                                 std::vector<double>* owed) {
  if (layout_.n == 0) return 0;
  auto& q = cl_.queue();
  const auto n = static_cast<cl_uint>(layout_.n);
  const cl_uint tile = layout_.tile, ntiles = layout_.ntiles;
  const ClGrid g = cl_grid(info_);
  const auto& d = scene_.domain;
  ClKeysParams P{};
  P.dmin = {{float(d.min.x()), float(d.min.y()), float(d.min.z()), 0.f}};
  P.dmax = {{float(d.max.x()), float(d.max.y()), float(d.max.z()), 0.f}};
  P.open_faces = static_cast<cl_uint>(scene_.open_faces);
  P.ncells = ncells_;
  P.n = n;
  if (intake_) {
    // The blowing dryers' intakes as they are now (a client may aim or switch them between steps).
    std::vector<cl_float4> in;
    const double dx = scene_.spacing;
    for (std::size_t k = 0; k < scene_.dryers.size(); ++k) {
      const Dryer& dr = scene_.dryers[k];
      if (!dr.blows_air()) continue;
      const double r = 0.5 * dr.nozzle_diameter + dx, pipe = EmitterStage::pipe_radius(dr, dx);
      const Eigen::Vector3d x = dr.position;
      const Eigen::Vector3d& u = dr.direction;
      in.push_back({{float(x.x()), float(x.y()), float(x.z()), float(r * r)}});
      in.push_back({{float(u.x()), float(u.y()), float(u.z()), float(EmitterStage::pipe_length(scene_))}});
      in.push_back(
          {{float(EmitterStage::mouth_depth * dx), float(0.5 * dr.speed), float(k), float(pipe * pipe)}});
      in.push_back({{float(dr.speed), float(EmitterStage::body_depth * dx), 0.f, 0.f}});
    }
    blowing_ = static_cast<cl_uint>(in.size() / 4);
    if (!in.empty()) q.enqueueWriteBuffer(intakes_, CL_TRUE, 0, in.size() * 16, in.data());
    if (!in.empty() && owed) {
      q.enqueueFillBuffer(listed_, cl_uint(0), 0, 4);
      set_args(k_intake_flags_, store[f.position], store[f.velocity], store[f.phase], take_, intakes_,
               static_cast<cl_uint>(in.size() / 4), n, listed_, list_);
      launch(q, k_intake_flags_, layout_.n);
      // Only the flagged come back (grid.cl): a few hundred near the nozzles, not a byte per particle.
      cl_uint listed = 0;
      q.enqueueReadBuffer(listed_, CL_TRUE, 0, 4, &listed);
      flagged_.resize(listed);
      if (listed > 0) q.enqueueReadBuffer(list_, CL_TRUE, 0, std::size_t(listed) * 8, flagged_.data());
      // Which to take in, in index order (the sort's, so a rerun chooses the same): every one flagged in
      // a pipe or a mouth (it is in the discs' way), one in a housing while its dryer owes. Those left
      // get their flags cleared.
      std::sort(flagged_.begin(), flagged_.end(),
                [](const cl_uint2& a, const cl_uint2& b) { return a.s[0] < b.s[0]; });
      std::size_t left = 0;
      for (const cl_uint2& e : flagged_) {
        const cl_uint t = e.s[1];
        double& debt = (*owed)[std::size_t((t - 1) / 2)];
        if (t % 2 == 1 || debt >= 1.0) {
          debt -= 1.0;
          P.intakes = 1;
        } else {
          flagged_[left++] = {{e.s[0], 0}};
        }
      }
      if (left > 0) {
        q.enqueueWriteBuffer(list_, CL_TRUE, 0, left * 8, flagged_.data());
        set_args(k_set_flags_, take_, list_, static_cast<cl_uint>(left));
        launch(q, k_set_flags_, left);
      }
    }
    set_args(k_cell_keys_, store[f.position], store[f.velocity], store[f.phase], keys_[0], order_[0], clamped,
             g, P, take_);
  } else {
    set_args(k_cell_keys_, store[f.position], store[f.velocity], store[f.phase], keys_[0], order_[0], clamped,
             g, P);
  }
  launch(q, k_cell_keys_, layout_.n);

  for (std::uint32_t pass = 0; pass < sort_passes_; ++pass) {
    const int src = pass % 2, dst = 1 - src;
    const cl_uint shift = radix_bits_ * pass;
    set_args(k_hist_, keys_[src], hist_, shift, n, tile, ntiles);
    launch(q, k_hist_, ntiles);
    // The digits' rows of tile counts scanned in chunks of tiles (grid.cl).
    const std::size_t digits = std::size_t(1) << radix_bits_;
    const cl_uint nchunks = (ntiles + kScanChunk - 1) / kScanChunk;
    set_args(k_chunk_counts_, hist_, chunks_, ntiles, nchunks);
    launch(q, k_chunk_counts_, digits * nchunks);
    set_args(k_scan_chunks_, chunks_, totals_, nchunks);
    launch(q, k_scan_chunks_, digits);
    set_args(k_scan_tiles_, hist_, chunks_, ntiles, nchunks);
    launch(q, k_scan_tiles_, digits * nchunks);
    set_args(k_scatter_, keys_[src], order_[src], keys_[dst], order_[dst], hist_, totals_, shift, n, tile,
             ntiles);
    launch(q, k_scatter_, ntiles);
  }
  const cl::Buffer& keys = keys_[sort_passes_ % 2];
  const cl::Buffer& order = order_[sort_passes_ % 2];

  // Every declared field follows the sort in one pass (sim/particle_store.h).
  store.reorder(order, soa_, layout_.stride);

  set_args(k_starts_, keys, cell_start_, n, ncells_);
  launch(q, k_starts_, layout_.n + 1);
  if (!scene_.open_faces && !intake_) return layout_.n;
  // cell_start[ncells] is the first particle that left (or n): those behind it are removed.
  cl_uint kept = 0;
  q.enqueueReadBuffer(cell_start_, CL_TRUE, std::size_t(ncells_) * 4, 4, &kept);
  return kept;
}

void NeighbourGrid::set_room_sites(const std::vector<Eigen::Vector3d>& sites) {
  room_sites_ = static_cast<cl_uint>(sites.size());
  if (sites.empty()) return;
  if (!k_empty_sites_()) throw Error("room-air sites given to a grid built without -DTHAW_ROOM_AIR");
  // Each site, and the outward normal of the nearest open side (grid.cl).
  const auto& d = scene_.domain;
  std::vector<cl_float4> x(sites.size()), out(sites.size());
  for (std::size_t s = 0; s < sites.size(); ++s) {
    x[s] = {{float(sites[s].x()), float(sites[s].y()), float(sites[s].z()), 0.f}};
    double nearest = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a)
      for (const bool upper : {false, true}) {
        if (!(scene_.open_faces & (1u << (2 * a + (upper ? 1 : 0))))) continue;
        const double dist = upper ? d.max[a] - sites[s][a] : sites[s][a] - d.min[a];
        if (dist >= nearest) continue;
        nearest = dist;
        out[s] = {{0.f, 0.f, 0.f, 0.f}};
        out[s].s[a] = upper ? 1.f : -1.f;
      }
  }
  auto& ctx = cl_.context();
  sites_ = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, x.size() * 16, x.data());
  site_out_ = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, out.size() * 16, out.data());
  empty_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, x.size() * 4);
  site_vel_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, x.size() * 16);
  if (!listed_()) listed_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, 4);
}

NeighbourGrid::EmptySites NeighbourGrid::empty_sites(ParticleStore& store, const CoreFields& f, double gap) {
  EmptySites out;
  if (!room_sites_ || layout_.n == 0) return out;
  auto& q = cl_.queue();
  q.enqueueFillBuffer(listed_, cl_uint(0), 0, 4);
  set_args(k_empty_sites_, store[f.position], store[f.velocity], store[f.phase], cell_start_, cl_grid(info_),
           sites_, site_out_, room_sites_, static_cast<cl_float>(gap * gap), static_cast<cl_float>(support_),
           listed_, empty_, site_vel_);
  launch(q, k_empty_sites_, room_sites_);
  cl_uint listed = 0;
  q.enqueueReadBuffer(listed_, CL_TRUE, 0, 4, &listed);
  if (listed == 0) return out;
  out.site.resize(listed);
  q.enqueueReadBuffer(empty_, CL_TRUE, 0, std::size_t(listed) * 4, out.site.data());
  // The slots' order varies from run to run; the particles laid must not.
  std::sort(out.site.begin(), out.site.end());
  std::vector<cl_float4> v(room_sites_);
  q.enqueueReadBuffer(site_vel_, CL_TRUE, 0, v.size() * 16, v.data());
  for (const std::uint32_t s : out.site) out.velocity.emplace_back(v[s].s[0], v[s].s[1], v[s].s[2]);
  return out;
}

void NeighbourGrid::drive_pipes(ParticleStore& store, const CoreFields& f) {
  if (!intake_ || !blowing_ || layout_.n == 0) return;
  set_args(k_pipe_drive_, store[f.position], store[f.velocity], store[f.phase], intakes_, blowing_,
           static_cast<cl_uint>(layout_.n));
  launch(cl_.queue(), k_pipe_drive_, layout_.n);
}

std::vector<std::uint32_t> NeighbourGrid::cell_starts() const {
  std::vector<std::uint32_t> out(std::size_t(ncells_) + 1);
  cl_.queue().enqueueReadBuffer(cell_start_, CL_TRUE, 0, out.size() * 4, out.data());
  return out;
}

}  // namespace thaw
