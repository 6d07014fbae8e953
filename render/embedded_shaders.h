#pragma once
// The GLSL files of render/shaders/, embedded at build time (cmake/embed_kernels.cmake) so `thaw`
// renders from any directory.
#include <map>
#include <string>
#include <string_view>

namespace thaw {

const std::map<std::string, std::string_view>& embedded_shader_files();

}  // namespace thaw
