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

// The cell-key pass's parameters: must match `KeysParams` in sim/kernels/grid_common.h.
struct ClKeysParams {
  cl_float4 dmin, dmax;  // the domain; w unused
  cl_uint open_faces;    // Scene::open_faces
  cl_uint ncells;        // the key of a particle that left through an open side
  cl_uint n;
  cl_uint intakes;  // -DTHAW_INTAKE: nonzero when some particle is taken in by an air dryer
};
static_assert(sizeof(ClKeysParams) == 48, "ClKeysParams must match the OpenCL struct's layout");

}  // namespace thaw
