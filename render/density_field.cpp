#include "render/density_field.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "sim/error.h"

// Each phase's field is its particles' volume fraction smoothed by a Gaussian: a cloud-in-cell deposit of
// (spacing / cell)^3 per particle, so a lattice of particles deposits 1 per node on average, followed by
// a separable Gaussian blur. The blur costs 3 x 9 taps per node of the phase's box whatever the particle
// count, on contiguous rows that vectorise; splatting the same kernel per particle would touch 9^3 nodes
// each, scattered, which at 100k particles is more work than blurring all of a 128^3 grid. A symmetric kernel
// puts the 0.5 level of a flat lattice surface exactly half a spacing beyond the outermost particle centres,
// where the particles' own volume ends.

namespace thaw {
namespace {

// The profile's width: the Gaussian blur's standard deviation. A lattice whose points sit on every other
// node (cell = spacing / 2) leaves a ripple of about 2 exp(-2 pi^2 sigma^2 / s^2) per axis inside the
// phase: 1.4 % at sigma = 0.5 spacings (4 % where three axes add up), 0.16 % at 0.6. A sphere's surface moves
// inward by only sigma^2 / R; 1.5 spacings beyond the surface the field is below 0.01.
constexpr float kSigmaPerSpacing = 0.6f;
// On a grid coarser than the particles, the field cannot be sharper than the grid resolves.
constexpr float kSigmaPerCell = 0.8f;
// Cells finer than half a spacing add nodes without adding shape: the profile is already resolved.
constexpr float kMinCellPerSpacing = 0.5f;
// The grid reaches this far beyond the particles, so the field is well below the surface level at the
// grid's faces and iso-surfaces of particle sets close.
constexpr float kMarginSpacings = 2.0f;
constexpr float kMarginSigmas = 2.5f;
// The Gaussian is cut at this many of its standard deviations (weight lost: 0.3 %, renormalised).
constexpr float kBlurCutoff = 3.0f;

constexpr int kIce = 0, kWater = 1, kSolid = 2, kGlass = 3, kSlots = 4;

int slot_of(std::uint8_t phase, bool glass = false) {
  switch (static_cast<Phase>(phase)) {
    case Phase::Ice:
      return kIce;
    case Phase::Water:
      return kWater;
    case Phase::Solid:
      return glass ? kGlass : kSolid;
    case Phase::Air:
      break;
  }
  return -1;
}

bool finite(const Eigen::Vector3f& x) {
  return std::isfinite(x.x()) && std::isfinite(x.y()) && std::isfinite(x.z());
}

// Inclusive node-index box; empty while lo > hi.
struct IndexBox {
  Eigen::Vector3i lo = Eigen::Vector3i::Constant(std::numeric_limits<int>::max());
  Eigen::Vector3i hi = Eigen::Vector3i::Constant(std::numeric_limits<int>::min());
  bool empty() const { return (lo.array() > hi.array()).any(); }
  int extent(int axis) const { return hi[axis] - lo[axis] + 1; }
};

// The grid and the blur width in cells for particles spanning [lo, hi] at spacing s.
struct Layout {
  FieldGrid grid;
  float sigma_cells = 1;  // the Gaussian blur's standard deviation, in cells
};

Layout lay_out(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float s, int max_cells) {
  const Eigen::Vector3f extent = hi - lo;
  const float longest = extent.maxCoeff();
  // The margin depends on the kernel width, which depends on the cell, which depends on the margin; a
  // few rounds of substitution settle it.
  float cell = kMinCellPerSpacing * s, sigma = kSigmaPerSpacing * s, margin = kMarginSpacings * s;
  for (int round = 0; round < 4; ++round) {
    cell = std::max((longest + 2 * margin) / float(max_cells - 1), kMinCellPerSpacing * s);
    sigma = std::max(kSigmaPerSpacing * s, kSigmaPerCell * cell);
    margin = std::max(kMarginSpacings * s, 0.5f * s + kMarginSigmas * sigma + cell);
  }
  Layout l;
  l.grid.cell = cell;
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) {
    // The small allowance keeps rounding from adding a node beyond max_cells along the longest axis.
    n[a] = std::clamp(int(std::ceil((extent[a] + 2 * margin) / cell - 1e-3f)) + 1, 2, max_cells);
  }
  l.grid.nx = n[0];
  l.grid.ny = n[1];
  l.grid.nz = n[2];
  const Eigen::Vector3f span = cell * Eigen::Vector3f(float(n[0] - 1), float(n[1] - 1), float(n[2] - 1));
  l.grid.origin = 0.5f * (lo + hi) - 0.5f * span;
  // The deposit's tent is no smoothing for particles that sit on nodes, so the blur alone sets the width.
  l.sigma_cells = sigma / cell;
  return l;
}

std::vector<float> gaussian_weights(float sigma) {
  const int r = std::max(1, int(std::ceil(kBlurCutoff * sigma)));
  std::vector<float> w(2 * r + 1);
  double sum = 0;
  for (int t = -r; t <= r; ++t)
    sum += w[t + r] = float(std::exp(-0.5 * double(t * t) / double(sigma * sigma)));
  for (float& v : w) v = float(v / sum);
  return w;
}

// dst[i] += wt * src[i] for i < n: every pass of the blur is this loop over contiguous memory.
inline void axpy(float* dst, const float* src, float wt, int n) {
#pragma omp simd
  for (int i = 0; i < n; ++i) dst[i] += wt * src[i];
}

// Blurs `field` in place along x, y and z. `d` bounds the deposit; everything outside `d` grown by the
// blur radius stays 0, so only that box `b` is read or written (an absent phase costs nothing).
//
// Deposit slices are blurred in x and y into a ring of 2r + 1 compact slices, and each output slice is
// summed from the ring as soon as it holds the slices around it: no grid-sized scratch to fault in and
// stream through memory, and the ring (under 1 MB at 128^2) stays in cache. Output overwrites the deposit
// in place, since slice k's deposit has been read into the ring before output slice k is written.
void blur(std::vector<float>& field, const FieldGrid& g, const IndexBox& d, const std::vector<float>& w) {
  if (d.empty()) return;
  const int r = int(w.size() / 2), ring = 2 * r + 1;
  IndexBox b;
  const Eigen::Vector3i top(g.nx - 1, g.ny - 1, g.nz - 1);
  b.lo = (d.lo.array() - r).max(0).matrix();
  b.hi = (d.hi.array() + r).min(top.array()).matrix();
  const int bx = b.extent(0), by = b.extent(1);
  const std::size_t compact = std::size_t(bx) * by;  // one slice of b: rows of bx from b.lo.x
  const std::size_t slice = std::size_t(g.nx) * g.ny;
  std::vector<float> rows(std::size_t(d.extent(1)) * bx), store(compact * ring);
  auto ring_slice = [&](int z) { return store.data() + std::size_t(z - d.lo.z()) % ring * compact; };

  // Blurs deposit slice z in x and y into the ring.
  auto blur_xy = [&](int z) {
    const float* in = field.data() + std::size_t(z) * slice;
    for (int j = d.lo.y(); j <= d.hi.y(); ++j) {
      float* row = rows.data() + std::size_t(j - d.lo.y()) * bx;  // row[x - b.lo.x()]
      std::fill(row, row + bx, 0.0f);
      const float* src = in + std::size_t(j) * g.nx;
      for (int t = 0; t <= 2 * r; ++t) {
        // Output x reads src[x + t - r], only inside the deposit's x-range.
        const int a = std::max(b.lo.x(), d.lo.x() - t + r), e = std::min(b.hi.x(), d.hi.x() - t + r);
        axpy(row + (a - b.lo.x()), src + (a + t - r), w[t], e - a + 1);
      }
    }
    float* out = ring_slice(z);
    for (int j = b.lo.y(); j <= b.hi.y(); ++j) {
      float* o = out + std::size_t(j - b.lo.y()) * bx;
      std::fill(o, o + bx, 0.0f);
      const int t0 = std::max(0, d.lo.y() - j + r), t1 = std::min(2 * r, d.hi.y() - j + r);
      for (int t = t0; t <= t1; ++t) axpy(o, rows.data() + std::size_t(j + t - r - d.lo.y()) * bx, w[t], bx);
    }
  };

  // Output slice k needs deposit slices k - r .. k + r; b.lo.z is d.lo.z - r or 0.
  for (int z = d.lo.z(); z < std::min(b.lo.z() + r, d.hi.z() + 1); ++z) blur_xy(z);
  for (int k = b.lo.z(); k <= b.hi.z(); ++k) {
    if (k + r >= d.lo.z() && k + r <= d.hi.z()) blur_xy(k + r);
    float* out = field.data() + std::size_t(k) * slice;
    const int t0 = std::max(0, d.lo.z() - k + r), t1 = std::min(2 * r, d.hi.z() - k + r);
    for (int j = b.lo.y(); j <= b.hi.y(); ++j) {
      float* o = out + std::size_t(j) * g.nx + b.lo.x();
      std::fill(o, o + bx, 0.0f);
      for (int t = t0; t <= t1; ++t)
        axpy(o, ring_slice(k + t - r) + std::size_t(j - b.lo.y()) * bx, w[t], bx);
    }
  }
}

// The tint's per-particle weights (build_density_fields). The dye's: each water particle's concentration of
// the tint substance over the reference (the given one, else the most any water particle holds); none when no
// water holds any. The stain's, for a coating: each ice and solid particle's deposit over the coating's
// capacity (unlimited: the most any holds); none when nothing holds any. An unknown substance is an Error.
template <class SlotAt>
void tint_weights(const RenderSnapshot& s, const FieldOptions& o, const SlotAt& slot_at, DensityFields& f,
                  std::vector<float>& dye, std::vector<float>& stain) {
  std::size_t index = s.substances.size();
  for (std::size_t i = 0; i < s.substances.size(); ++i)
    if (s.substances[i].first == o.tint) index = i;
  if (index == s.substances.size() || s.substances[index].second.size() != s.position.size())
    throw Error("density field: the snapshot holds no substance '" + o.tint + "' to tint by");
  if (index < s.substance_colours.size()) f.tint_colour = s.substance_colours[index];
  const std::vector<float>& c = s.substances[index].second;
  float reference = o.tint_reference;
  if (!(reference > 0))
    for (std::size_t p = 0; p < c.size(); ++p)
      if (slot_at(p) == kWater && std::isfinite(c[p])) reference = std::max(reference, c[p]);
  if (reference > 0) {
    f.tint_reference = reference;
    dye.assign(c.size(), 0.0f);
    for (std::size_t p = 0; p < c.size(); ++p)
      if (slot_at(p) == kWater && std::isfinite(c[p])) dye[p] = std::max(c[p], 0.0f) / reference;
  }
  for (std::size_t k = 0; k < s.deposits.size(); ++k) {
    const auto& [name, deposit] = s.deposits[k];
    if (name != o.tint || deposit.size() != s.position.size()) continue;
    float most = 0;  // the most any particle holds
    for (float v : deposit) most = std::max(most, std::isfinite(v) ? v : 0.0f);
    const float capacity = k < s.deposit_capacity.size() ? s.deposit_capacity[k] : 0.0f;
    const float full = capacity > 0 ? capacity : most;
    if (!(most > 0)) break;
    stain.assign(deposit.size(), 0.0f);
    for (std::size_t p = 0; p < deposit.size(); ++p) {
      const int slot = slot_at(p);
      if ((slot == kIce || slot == kSolid) && std::isfinite(deposit[p]))
        stain[p] = std::clamp(deposit[p] / full, 0.0f, 1.0f);
    }
  }
}

}  // namespace

DensityFields build_density_fields(const RenderSnapshot& s, const FieldOptions& options) {
  if (options.max_cells < 8)
    throw Error("density field: max_cells is " + std::to_string(options.max_cells) + ", at least 8 needed");
  if (s.phase.size() != s.position.size())
    throw Error("density field: " + std::to_string(s.phase.size()) + " phases for " +
                std::to_string(s.position.size()) + " particles");
  if (!s.glass.empty() && s.glass.size() != s.position.size())
    throw Error("density field: " + std::to_string(s.glass.size()) + " glass flags for " +
                std::to_string(s.position.size()) + " particles");
  const auto slot_at = [&](std::size_t p) { return slot_of(s.phase[p], !s.glass.empty() && s.glass[p]); };

  // The grid covers what is drawn (not air, not a particle that has left the numbers behind); the
  // snapshot's bounds include every particle, so they are recomputed here.
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity()), hi = -lo;
  std::size_t drawn = 0;
  for (std::size_t p = 0; p < s.position.size(); ++p) {
    if (slot_at(p) < 0 || !finite(s.position[p])) continue;
    lo = lo.cwiseMin(s.position[p]);
    hi = hi.cwiseMax(s.position[p]);
    ++drawn;
  }
  if (drawn > 0 && !(s.spacing > 0))
    throw Error("density field: particle spacing is " + std::to_string(s.spacing) + ", must be positive");

  DensityFields f;
  f.iso = options.iso;
  if (drawn == 0) {
    // Nothing to draw: a small grid of zeros keeps consumers free of zero-sized special cases.
    f.grid.cell = s.spacing > 0 ? s.spacing : 1.0f;
    f.grid.nx = f.grid.ny = f.grid.nz = 2;
    f.grid.origin = 0.5f * (s.bounds_min + s.bounds_max);
    f.ice.assign(f.grid.size(), 0.0f);
    f.water = f.solid = f.ice;
    return f;
  }

  // The tint's weights per particle: concentration over the reference in water, deposit over the capacity on
  // solids and ice (the glass left clear).
  std::vector<float> dye_weight, stain_weight;
  if (!options.tint.empty()) tint_weights(s, options, slot_at, f, dye_weight, stain_weight);

  const Layout layout = lay_out(lo, hi, s.spacing, options.max_cells);
  const FieldGrid& g = f.grid = layout.grid;
  // Cloud-in-cell deposit of each particle's volume in cells, bucketed first by phase and z-cell with a
  // stable counting sort, so that each field's deposit walks its slices in order (in cache, whatever the
  // particle order) and sums each node in a fixed order.
  const float inv_cell = 1.0f / g.cell;
  const float volume = std::pow(s.spacing * inv_cell, 3.0f);
  const Eigen::Vector3i top(g.nx - 2, g.ny - 2, g.nz - 2);
  struct Deposit {
    std::size_t node;  // lower corner of the particle's cell
    Eigen::Vector3f frac;
  };
  std::vector<Deposit> deposits(s.position.size());
  std::vector<int> bucket(s.position.size(), -1);  // slot * nz + cell z; -1: not drawn
  std::vector<std::size_t> start(std::size_t(kSlots) * g.nz + 1, 0);
  std::array<IndexBox, kSlots> box;
  for (std::size_t p = 0; p < s.position.size(); ++p) {
    const int slot = slot_at(p);
    if (slot < 0 || !finite(s.position[p])) continue;
    const Eigen::Vector3f u = (s.position[p] - g.origin) * inv_cell;
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor(u[a])), 0, top[a]);
    deposits[p] = {g.index(c.x(), c.y(), c.z()), (u - c.cast<float>()).cwiseMax(0.0f).cwiseMin(1.0f)};
    bucket[p] = slot * g.nz + c.z();
    ++start[std::size_t(bucket[p]) + 1];
    box[slot].lo = box[slot].lo.cwiseMin(c);
    box[slot].hi = box[slot].hi.cwiseMax((c.array() + 1).matrix());
  }
  for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
  std::vector<std::uint32_t> order(start.back());
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (std::size_t p = 0; p < s.position.size(); ++p)
      if (bucket[p] >= 0) order[next[bucket[p]]++] = std::uint32_t(p);
  }

  // One task per field: zero (which faults its pages in), deposit, blur. Tasks rather than slabs of one
  // field, because the two cores here are shared with the simulation: a team that meets at barriers
  // waits a scheduler time slice at each one when the other core is busy (measured: 5x slower than one
  // thread), while independent tasks meet once. Each field is computed by one thread in one order, so
  // the result does not depend on the thread count.
  // Tasks 0-3 are the phases; 4 the dye, deposited by the water's particles; 5 the stain, by the ice's and
  // solids'. Each weights its particles' volume by its own weights (none: 1).
  struct Task {
    std::vector<float>* field;
    std::vector<int> slots;
    const std::vector<float>* weight;
  };
  const std::array<Task, kSlots + 2> tasks = {{{&f.ice, {kIce}, nullptr},
                                               {&f.water, {kWater}, nullptr},
                                               {&f.solid, {kSolid}, nullptr},
                                               {&f.glass, {kGlass}, nullptr},
                                               {&f.dye, {kWater}, &dye_weight},
                                               {&f.stain, {kIce, kSolid}, &stain_weight}}};
  const std::vector<float> w = gaussian_weights(layout.sigma_cells);
  const std::size_t dy = std::size_t(g.nx), dz = std::size_t(g.nx) * g.ny;
#pragma omp parallel for schedule(dynamic, 1)
  for (int t = 0; t < int(tasks.size()); ++t) {
    const Task& task = tasks[std::size_t(t)];
    std::vector<float>& field = *task.field;
    if (t == kGlass && s.glass.empty()) continue;       // no glass: no field
    if (task.weight && task.weight->empty()) continue;  // no tint
    field.assign(g.size(), 0.0f);
    IndexBox bounds;
    for (const int slot : task.slots) {
      bounds.lo = bounds.lo.cwiseMin(box[slot].lo);
      bounds.hi = bounds.hi.cwiseMax(box[slot].hi);
      for (std::size_t q = start[std::size_t(slot) * g.nz]; q < start[std::size_t(slot + 1) * g.nz]; ++q) {
        const Deposit& dep = deposits[order[q]];
        const float amount = task.weight ? volume * (*task.weight)[order[q]] : volume;
        if (amount == 0.0f) continue;
        const float wx[2] = {1 - dep.frac.x(), dep.frac.x()}, wy[2] = {1 - dep.frac.y(), dep.frac.y()};
        const float wz[2] = {1 - dep.frac.z(), dep.frac.z()};
        for (int k = 0; k < 2; ++k) {
          for (int j = 0; j < 2; ++j) {
            float* v = field.data() + dep.node + k * dz + j * dy;
            const float wjk = amount * wy[j] * wz[k];
            v[0] += wx[0] * wjk;
            v[1] += wx[1] * wjk;
          }
        }
      }
    }
    blur(field, g, bounds, w);
  }
  return f;
}

float sample_field(const FieldGrid& g, const std::vector<float>& values, const Eigen::Vector3f& p) {
  if (g.nx < 2 || g.ny < 2 || g.nz < 2 || values.size() < g.size()) return 0.0f;
  const Eigen::Vector3f u = (p - g.origin) / g.cell;
  const Eigen::Vector3i n(g.nx, g.ny, g.nz);
  Eigen::Vector3i c;
  Eigen::Vector3f fr;
  for (int a = 0; a < 3; ++a) {
    if (!(u[a] >= 0.0f && u[a] <= float(n[a] - 1))) return 0.0f;
    c[a] = std::min(int(u[a]), n[a] - 2);
    fr[a] = u[a] - float(c[a]);
  }
  auto at = [&](int i, int j, int k) { return values[g.index(c.x() + i, c.y() + j, c.z() + k)]; };
  auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
  const float c00 = lerp(at(0, 0, 0), at(1, 0, 0), fr.x()), c10 = lerp(at(0, 1, 0), at(1, 1, 0), fr.x());
  const float c01 = lerp(at(0, 0, 1), at(1, 0, 1), fr.x()), c11 = lerp(at(0, 1, 1), at(1, 1, 1), fr.x());
  return lerp(lerp(c00, c10, fr.y()), lerp(c01, c11, fr.y()), fr.z());
}

}  // namespace thaw
