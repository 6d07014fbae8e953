#pragma once
// What the hand-written reference loops (reference_density.cpp, reference_heat.cpp) share: the grid
// cell of a coordinate as the device computes it, and eight SIMD lanes as GCC vector types, doing the
// same operations as the device's float8 code (sqrt is AVX's).
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace thaw::reference {

inline int cell_of(float x, float origin, float inv_cell, int n) {
  return std::clamp(static_cast<int>(std::floor((x - origin) * inv_cell)), 0, n - 1);
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
