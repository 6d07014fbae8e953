#pragma once
// Sampling a shape on the particle lattice: the points min + (i + 1/2) dx over its bounding box, i, j, k
// from 0, that lie inside it, in the order x fastest, then y, then z.
#include <Eigen/Core>
#include <vector>

#include "sim/geometry/shape.h"

namespace thaw {

// An axis-aligned box keeps the whole cells that fit in it, as fluid and ice blocks always have:
// floor(extent / dx) points along each axis. Every other shape takes each lattice point over its bounding
// box that passes its inside test, so the count times dx^3 estimates its volume without bias. With an
// `origin`, those other shapes use the lattice origin + (i + 1/2) dx (i any integer), so that a sphere,
// a mesh or a rotated box meets water sampled on that lattice without particles closer than a spacing;
// without one, the lattice starts at their bounding box's corner.
std::vector<Eigen::Vector3d> voxelize(const Shape& shape, double spacing,
                                      const Eigen::Vector3d* origin = nullptr);

// The points of voxelize() that lie less than `layers` spacings inside the surface: a solid needs
// particles only as deep as a neighbour's kernel reaches. An axis-aligned box measures the distance to its
// faces; other shapes count a point when a lattice point outside them lies within `layers` spacings.
std::vector<Eigen::Vector3d> voxelize_shell(const Shape& shape, double spacing, int layers,
                                            const Eigen::Vector3d* origin = nullptr);

}  // namespace thaw
