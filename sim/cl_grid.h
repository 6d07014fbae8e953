#pragma once
// The neighbour grid as the kernels receive it: must match `Grid` in sim/kernels/grid_common.h.
#include <CL/opencl.hpp>

namespace thaw {

struct ClGrid {
  cl_float4 origin;    // grid minimum corner; w unused
  cl_float4 inv_cell;  // 1 / cell size along x, y, z; w unused
  cl_int nx, ny, nz;
};
static_assert(sizeof(ClGrid) == 48, "ClGrid must match the OpenCL struct's layout");

}  // namespace thaw
