#pragma once
// Snapshots built by hand for the renderer's tests: particles on a lattice cell-centred like the scene
// sampler's, shaped as spheres and boxes.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "render/snapshot.h"

namespace thaw::testing {

inline void add_particle(RenderSnapshot& s, const Eigen::Vector3f& x, Phase phase) {
  s.position.push_back(x);
  s.phase.push_back(std::uint8_t(phase));
  s.bounds_min = s.position.size() == 1 ? x : s.bounds_min.cwiseMin(x);
  s.bounds_max = s.position.size() == 1 ? x : s.bounds_max.cwiseMax(x);
}

// Lattice points within `radius` spacings of `centre`.
inline void add_lattice_sphere(RenderSnapshot& s, const Eigen::Vector3f& centre, float spacing, float radius,
                               Phase phase) {
  const int n = int(std::ceil(radius));
  for (int k = -n; k < n; ++k)
    for (int j = -n; j < n; ++j)
      for (int i = -n; i < n; ++i) {
        const Eigen::Vector3f x = Eigen::Vector3f(float(i), float(j), float(k)) + Eigen::Vector3f::Constant(0.5f);
        if (x.norm() < radius) add_particle(s, centre + spacing * x, phase);
      }
}

// nx * ny * nz lattice points from `corner`: a box of (nx, ny, nz) spacings around them.
inline void add_lattice_box(RenderSnapshot& s, const Eigen::Vector3f& corner, float spacing, int nx, int ny, int nz,
                            Phase phase) {
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        add_particle(s, corner + spacing * Eigen::Vector3f(float(i), float(j), float(k)), phase);
}

}  // namespace thaw::testing
