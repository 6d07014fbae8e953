// `thaw info`: what OpenCL finds here and which device a run would use; `thaw scene-doc`.
#include <cstdio>

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
    std::printf("  %d:%d  %-4s %s  [%s]  %s, %u compute units, %.1f GiB\n", d.platform, d.device, d.type.c_str(),
                d.name.c_str(), d.platform_name.c_str(), d.version.c_str(), d.compute_units,
                double(d.global_memory) / (1024.0 * 1024.0 * 1024.0));
  try {
    const auto d = choose_device(args.value("--device").value_or(""));
    std::printf("would use: %d:%d %s\n", d.platform, d.device, d.name.c_str());
  } catch (const Error& e) {
    std::printf("would use: none: %s\n", e.what());
    return 1;
  }
  return 0;
}

int cmd_scene_doc(int argc, char** argv) {
  CliArgs args(argc, argv, 2, {}, {});
  std::fputs(scene_reference_markdown().c_str(), stdout);
  return 0;
}

}  // namespace thaw
