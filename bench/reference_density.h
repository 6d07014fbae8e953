#pragma once
// The density pass written by hand in C++ with OpenMP over the solver's own sorted particles and cell
// starts: the yardstick the OpenCL density stage is measured against.
#include <cstdint>
#include <vector>

#include "sim/particles.h"

namespace thaw {

struct ReferenceGrid {
  float origin[3];
  float inv_cell;
  int nx, ny, nz;
  int reach;  // cells visited on each side: the cell size is H / reach
};

// rho_i = sum_j m_j W(|x_i - x_j|, H) for every non-solid particle (solids get rho0), cubic spline.
void reference_density(const std::vector<Float4>& pos, const std::vector<std::uint8_t>& phase,
                       const std::vector<std::uint32_t>& cell_start, const ReferenceGrid& g, float H, float rho0,
                       std::vector<float>& out);

}  // namespace thaw
