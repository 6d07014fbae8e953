#pragma once
// What the hand-written reference loops (reference_density.cpp, reference_heat.cpp) share: the grid
// cell of a coordinate as the device computes it, and eight SIMD lanes as GCC vector types, doing the
// same operations as the device's float8 code (sqrt is AVX's).
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "bench/reference_density.h"

namespace thaw::reference {

inline int cell_of(float x, float origin, float inv_cell, int n) {
  return std::clamp(static_cast<int>(std::floor((x - origin) * inv_cell)), 0, n - 1);
}

// The rows of cells around the point (x, y, z) as the device walks them (FOR_EACH_NEIGHBOUR_ROW in
// sim/kernels/grid_common.h): visit(jb, je) sees each row's range of sorted particles.
template <class Visit>
inline void for_each_row(const ReferenceGrid& g, const std::uint32_t* cell_start, float x, float y, float z,
                         Visit&& visit) {
  const int R = g.reach;
  const int cx = cell_of(x, g.origin[0], g.inv_cell, g.nx);
  const int cy = cell_of(y, g.origin[1], g.inv_cell, g.ny);
  const int cz = cell_of(z, g.origin[2], g.inv_cell, g.nz);
  for (int k = std::max(cz - R, 0); k <= std::min(cz + R, g.nz - 1); ++k)
    for (int j = std::max(cy - R, 0); j <= std::min(cy + R, g.ny - 1); ++j) {
      const int row = (k * g.ny + j) * g.nx;
      visit(cell_start[row + std::max(cx - R, 0)], cell_start[row + std::min(cx + R, g.nx - 1) + 1]);
    }
}

typedef float v8f __attribute__((vector_size(32)));
typedef int v8i __attribute__((vector_size(32)));

inline v8f load8(const float* p) {
  v8f v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline v8f sqrt8(v8f x) { return reinterpret_cast<v8f>(_mm256_sqrt_ps(reinterpret_cast<__m256>(x))); }
inline v8f splat8(float x) { return v8f{} + x; }

}  // namespace thaw::reference
