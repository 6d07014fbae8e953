#include "sim/geometry/voxelize.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace thaw {

namespace {

using Vec3 = Eigen::Vector3d;

// The lattice over a shape's bounding box: n points along each axis from `min`.
struct Lattice {
  Vec3 min;
  Eigen::Array3i n;
  double dx;

  Vec3 point(int i, int j, int k) const { return min + dx * Vec3(i + 0.5, j + 0.5, k + 0.5); }
  std::size_t index(int i, int j, int k) const {
    return (std::size_t(k) * std::size_t(n.y()) + std::size_t(j)) * std::size_t(n.x()) + std::size_t(i);
  }
  std::vector<Vec3> points() const {
    std::vector<Vec3> out;
    out.reserve(std::size_t(n.prod()));
    for (int k = 0; k < n.z(); ++k)
      for (int j = 0; j < n.y(); ++j)
        for (int i = 0; i < n.x(); ++i) out.push_back(point(i, j, k));
    return out;
  }
};

Lattice lattice_of(const Shape& shape, double dx, const Vec3* origin) {
  const Eigen::AlignedBox3d& b = shape.bounds();
  // The tolerance keeps an extent that is a whole number of spacings, up to rounding, at that number.
  const bool whole_cells = shape.axis_aligned_box();
  Vec3 min = b.min();
  if (origin && !whole_cells)
    min = *origin + dx * ((b.min() - *origin) / dx)
                             .array()
                             .unaryExpr([](double v) { return std::floor(v + 1e-9); })
                             .matrix();
  const Eigen::Array3i n = ((b.max() - min) / dx).array().unaryExpr([whole_cells](double v) {
    return std::max(0, static_cast<int>(whole_cells ? std::floor(v + 1e-6) : std::ceil(v - 1e-6)));
  });
  return {min, n, dx};
}

std::vector<Vec3> select(const std::vector<Vec3>& points, const std::vector<std::uint8_t>& keep) {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (keep[i]) out.push_back(points[i]);
  return out;
}

}  // namespace

std::vector<Vec3> voxelize(const Shape& shape, double spacing, const Vec3* origin) {
  const Lattice lattice = lattice_of(shape, spacing, origin);
  const std::vector<Vec3> points = lattice.points();
  if (shape.axis_aligned_box()) return points;
  return select(points, shape.contains(points));
}

std::vector<Vec3> voxelize_shell(const Shape& shape, double spacing, int layers, const Vec3* origin) {
  const Lattice lattice = lattice_of(shape, spacing, origin);
  const std::vector<Vec3> points = lattice.points();
  const double depth = layers * spacing;
  if (shape.axis_aligned_box()) {
    const Vec3 min = shape.bounds().min(), max = shape.bounds().max();
    std::vector<std::uint8_t> keep(points.size());
    for (std::size_t p = 0; p < points.size(); ++p)
      keep[p] = std::min((points[p] - min).minCoeff(), (max - points[p]).minCoeff()) < depth;
    return select(points, keep);
  }
  const std::vector<std::uint8_t> inside = shape.contains(points);
  // Offsets within `layers` spacings, nearest first, so that most points of the shell stop early.
  std::vector<Eigen::Array3i> offsets;
  for (int k = -layers; k <= layers; ++k)
    for (int j = -layers; j <= layers; ++j)
      for (int i = -layers; i <= layers; ++i)
        if ((i || j || k) && i * i + j * j + k * k <= layers * layers) offsets.emplace_back(i, j, k);
  std::stable_sort(offsets.begin(), offsets.end(), [](const Eigen::Array3i& a, const Eigen::Array3i& b) {
    return a.square().sum() < b.square().sum();
  });
  const Eigen::Array3i& n = lattice.n;
  auto outside = [&](int i, int j, int k) {
    // The lattice covers the bounding box, so a point off it is outside the shape.
    if (i < 0 || j < 0 || k < 0 || i >= n.x() || j >= n.y() || k >= n.z()) return true;
    return inside[lattice.index(i, j, k)] == 0;
  };
  std::vector<std::uint8_t> keep(points.size(), 0);
  for (int k = 0; k < n.z(); ++k)
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i) {
        const std::size_t p = lattice.index(i, j, k);
        if (!inside[p]) continue;
        keep[p] = std::any_of(offsets.begin(), offsets.end(), [&](const Eigen::Array3i& o) {
          return outside(i + o.x(), j + o.y(), k + o.z());
        });
      }
  return select(points, keep);
}

}  // namespace thaw
