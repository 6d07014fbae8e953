#include "bench/reference_density.h"

#include <algorithm>
#include <cmath>

#include "sim/kernels/sph_kernel.h"

namespace thaw {

void reference_density(const std::vector<Float4>& pos, const std::vector<std::uint8_t>& phase,
                       const std::vector<std::uint32_t>& cell_start, const ReferenceGrid& g, float H, float rho0,
                       std::vector<float>& out) {
  const long n = static_cast<long>(pos.size());
  out.resize(pos.size());
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    if (phase[i] == static_cast<std::uint8_t>(Phase::Solid)) {
      out[i] = rho0;
      continue;
    }
    const Float4 pi = pos[i];
    int c[3];
    const int dims[3] = {g.nx, g.ny, g.nz};
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(static_cast<int>(std::floor((pi[a] - g.origin[a]) * g.inv_cell)), 0, dims[a] - 1);
    const float H2 = H * H;
    const int R = g.reach;
    float rho = 0.0f;
    for (int z = std::max(c[2] - R, 0); z <= std::min(c[2] + R, g.nz - 1); ++z)
      for (int y = std::max(c[1] - R, 0); y <= std::min(c[1] + R, g.ny - 1); ++y) {
        const int row = (z * g.ny + y) * g.nx;
        const std::uint32_t jb = cell_start[row + std::max(c[0] - R, 0)];
        const std::uint32_t je = cell_start[row + std::min(c[0] + R, g.nx - 1) + 1];
        for (std::uint32_t j = jb; j < je; ++j) {
          const float dx = pi[0] - pos[j][0], dy = pi[1] - pos[j][1], dz = pi[2] - pos[j][2];
          const float r2 = dx * dx + dy * dy + dz * dz;
          if (r2 < H2) rho += pos[j][3] * sph::cubic_spline_w(std::sqrt(r2), H);
        }
      }
    out[i] = rho;
  }
}

}  // namespace thaw
