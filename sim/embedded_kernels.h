#pragma once
// OpenCL C sources embedded at build time (cmake/embed_kernels.cmake), keyed by file name.
#include <map>
#include <string>
#include <string_view>

namespace thaw {
const std::map<std::string, std::string_view>& embedded_kernel_files();
}
