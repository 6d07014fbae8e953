#include "sim/geometry/winding_number.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace thaw {

namespace {

constexpr int kLeafSize = 8;
constexpr double kFourPi = 4.0 * M_PI;

Eigen::Vector3d centroid(const Triangle& t) { return (t.a + t.b + t.c) / 3.0; }

}  // namespace

double solid_angle(const Triangle& t, const Eigen::Vector3d& q) {
  const Eigen::Vector3d a = t.a - q, b = t.b - q, c = t.c - q;
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  // tan(Omega / 2) = det[a b c] / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|); atan2 keeps the quadrant.
  const double det = a.dot(b.cross(c));
  const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  return 2.0 * std::atan2(det, denominator);
}

double winding_number(const TriangleSoup& mesh, const Eigen::Vector3d& q) {
  double sum = 0.0;
  for (const Triangle& t : mesh) sum += solid_angle(t, q);
  return sum / kFourPi;
}

WindingNumber::WindingNumber(TriangleSoup mesh) : mesh_(std::move(mesh)), bounds_(bounding_box(mesh_)) {
  nodes_.reserve(2 * mesh_.size() / kLeafSize + 2);
  if (!mesh_.empty()) build(0, static_cast<int>(mesh_.size()));
}

int WindingNumber::build(int first, int count) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  const auto begin = mesh_.begin() + first, end = begin + count;

  Node node;
  node.first = first;
  node.count = count;
  double area = 0.0;
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  Eigen::AlignedBox3d centroids;
  for (auto t = begin; t != end; ++t) {
    const double a = 0.5 * (t->b - t->a).cross(t->c - t->a).norm();
    area += a;
    weighted += a * centroid(*t);
    centroids.extend(centroid(*t));
  }
  node.centre = area > 0.0 ? Eigen::Vector3d(weighted / area) : centroids.center();
  for (auto t = begin; t != end; ++t) {
    const Eigen::Vector3d area_normal = 0.5 * (t->b - t->a).cross(t->c - t->a);
    node.area_normal += area_normal;
    node.moment += area_normal * (centroid(*t) - node.centre).transpose();
    for (const Eigen::Vector3d* v : {&t->a, &t->b, &t->c})
      node.radius = std::max(node.radius, (*v - node.centre).norm());
  }

  if (count > kLeafSize) {
    // Median split along the longest extent of the centroids: a balanced tree, and a deterministic one.
    int axis = 0;
    centroids.sizes().maxCoeff(&axis);
    const int half = count / 2;
    std::nth_element(begin, begin + half, end, [axis](const Triangle& x, const Triangle& y) {
      return centroid(x)[axis] < centroid(y)[axis];
    });
    node.left = build(first, half);
    node.right = build(first + half, count - half);
  }
  nodes_[static_cast<std::size_t>(index)] = node;
  return index;
}

double WindingNumber::operator()(const Eigen::Vector3d& q) const {
  if (nodes_.empty()) return 0.0;
  double sum = 0.0;  // 4 pi w
  std::array<int, 128> stack;
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[static_cast<std::size_t>(stack[--top])];
    const Eigen::Vector3d r = n.centre - q;
    const double d2 = r.squaredNorm();
    if (d2 > kFarField * kFarField * n.radius * n.radius) {
      // Barill et al. 2018: the integral of (x - q) . n / |x - q|^3 over the group, Taylor-expanded about its
      // centre p: G(p) . sum(a n) + grad G(p) : sum((a n)(x_t - p)^T), G(x) = (x - q) / |x - q|^3.
      const double d = std::sqrt(d2), inv3 = 1.0 / (d2 * d), inv5 = inv3 / d2;
      sum += r.dot(n.area_normal) * inv3 + n.moment.trace() * inv3 - 3.0 * r.dot(n.moment * r) * inv5;
    } else if (n.left < 0) {
      for (int t = n.first; t < n.first + n.count; ++t)
        sum += solid_angle(mesh_[static_cast<std::size_t>(t)], q);
    } else {
      stack[top++] = n.right;
      stack[top++] = n.left;
    }
  }
  return sum / kFourPi;
}

std::vector<std::uint8_t> WindingNumber::inside(const std::vector<Eigen::Vector3d>& points) const {
  std::vector<std::uint8_t> out(points.size());
  const auto n = static_cast<std::ptrdiff_t>(points.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::ptrdiff_t i = 0; i < n; ++i)
    out[static_cast<std::size_t>(i)] = inside(points[static_cast<std::size_t>(i)]);
  return out;
}

}  // namespace thaw
