// `thaw info`: what OpenCL finds here and which device a run would use, and the renderer; `thaw scene-doc`.
#include <cstdio>

#include "render/egl_context.h"
#include "server/cli_args.h"
#include "server/commands.h"
#include "sim/cl_runtime.h"
#include "sim/error.h"
#include "sim/scene.h"

namespace thaw {

int cmd_info(int argc, char** argv) {
  CliArgs args(argc, argv, 2, {"--device"}, {});
  const auto all = list_devices();
  std::printf("OpenCL devices:\n");
  if (all.empty()) std::printf("  (none: no ICD driver found in /etc/OpenCL/vendors)\n");
  for (const auto& d : all)
    std::printf("  %d:%d  %-4s %s  [%s]  %s, %u compute units, %.1f GiB\n", d.platform, d.device,
                d.type.c_str(), d.name.c_str(), d.platform_name.c_str(), d.version.c_str(), d.compute_units,
                double(d.global_memory) / (1024.0 * 1024.0 * 1024.0));
  int status = 0;
  try {
    const auto d = choose_device(args.value("--device").value_or(""));
    std::printf("would use: %d:%d %s\n", d.platform, d.device, d.name.c_str());
  } catch (const Error& e) {
    std::printf("would use: none: %s\n", e.what());
    status = 1;
  }
  // The renderer is needed for frames and the service, not for simulating: report, do not fail on it.
  try {
    const EglContext gl;
    std::printf("renderer: %s\n", gl.description().c_str());
  } catch (const Error& e) {
    std::printf("renderer: none: %s\n", e.what());
  }
  return status;
}

int cmd_scene_doc(int argc, char** argv) {
  CliArgs args(argc, argv, 2, {}, {});
  std::fputs(scene_reference_markdown().c_str(), stdout);
  return 0;
}

}  // namespace thaw
