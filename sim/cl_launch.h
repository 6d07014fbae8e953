#pragma once
// Setting a kernel's arguments and launching it one work-item per element, shared by every stage.
#include <CL/opencl.hpp>
#include <algorithm>
#include <cstddef>

namespace thaw {

// Work-group size of the one-work-item-per-element kernels. Left to itself pocl picks a divisor of the
// global size (15 for 135645 particles), which made the simple kernels a third slower.
inline constexpr std::size_t kWorkGroup = 64;

// Sets a kernel's arguments in order: buffers, scalars and argument structs alike.
template <class... Args>
void set_args(cl::Kernel& k, const Args&... args) {
  cl_uint i = 0;
  (k.setArg(i++, args), ...);
}

// n work-items in groups of kWorkGroup; the kernels ignore ids >= n.
inline void launch(cl::CommandQueue& q, cl::Kernel& k, std::size_t n) {
  const std::size_t global = (std::max<std::size_t>(n, 1) + kWorkGroup - 1) / kWorkGroup * kWorkGroup;
  q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(kWorkGroup));
}

}  // namespace thaw
