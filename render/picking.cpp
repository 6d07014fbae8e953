#include "render/picking.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/error.h"

namespace thaw {
namespace {

// The union of the phases: the max of their fields is above iso exactly where one of them is, so its
// iso-surface is every phase's surface at once (the ray caster marches the same max).
double field(const DensityFields& f, const Eigen::Vector3d& p) {
  const Eigen::Vector3f q = p.cast<float>();
  return std::max(
      {sample_field(f.grid, f.ice, q), sample_field(f.grid, f.water, q), sample_field(f.grid, f.solid, q)});
}

}  // namespace

bool pick(const DensityFields& f, const OrbitCamera& camera, double px, double py, Eigen::Vector3d& hit,
          Eigen::Vector3d& normal) {
  const FieldGrid& g = f.grid;
  if (g.nx < 2 || g.ny < 2 || g.nz < 2 || g.cell <= 0) return false;
  for (const auto* v : {&f.ice, &f.water, &f.solid})
    if (!v->empty() && v->size() != g.size())
      throw Error("pick: a phase field holds " + std::to_string(v->size()) + " values for a grid of " +
                  std::to_string(g.size()) + " nodes");
  Eigen::Vector3d o, d;
  camera.ray(px, py, o, d);

  // Clip to the box of nodes (slab test); `entry_axis` remembers which face the ray came in through.
  const Eigen::Vector3d lo = g.origin.cast<double>();
  const Eigen::Vector3d hi = lo + double(g.cell) * Eigen::Vector3d(g.nx - 1, g.ny - 1, g.nz - 1);
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  int entry_axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-300) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) {
      t0 = ta;
      entry_axis = a;
    }
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return false;

  // A phase cut by the box (its field already above iso where the ray enters): the box face is its
  // visible surface.
  if (field(f, o + t0 * d) >= f.iso) {
    hit = o + t0 * d;
    normal = Eigen::Vector3d::Zero();
    if (entry_axis >= 0)
      normal[entry_axis] = d[entry_axis] > 0 ? -1.0 : 1.0;
    else
      normal = -d;
    return true;
  }

  // Half a cell per step: features a cell thin still show a sample above iso.
  const double step = 0.5 * g.cell;
  double ta = t0;
  for (double t = t0 + step;; t += step) {
    double tb = std::min(t, t1);
    if (field(f, o + tb * d) >= f.iso) {
      // Bisection keeps the bracket [below iso, above iso]; 40 halvings reach the float positions' precision.
      for (int k = 0; k < 40; ++k) {
        const double tm = 0.5 * (ta + tb);
        if (field(f, o + tm * d) >= f.iso)
          tb = tm;
        else
          ta = tm;
      }
      hit = o + tb * d;
      const double h = 0.5 * g.cell;
      Eigen::Vector3d grad;
      for (int a = 0; a < 3; ++a) {
        Eigen::Vector3d e = Eigen::Vector3d::Zero();
        e[a] = h;
        grad[a] = field(f, hit + e) - field(f, hit - e);
      }
      normal = grad.norm() > 0 ? Eigen::Vector3d(-grad.normalized()) : Eigen::Vector3d(-d);
      return true;
    }
    if (tb >= t1) return false;
    ta = tb;
  }
}

}  // namespace thaw
