// thaw: SPH ice-melting simulation. One executable, one subcommand per job.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "server/commands.h"
#include "sim/cl_runtime.h"
#include "sim/error.h"

namespace {

// One entry per command: its lines of the usage, which `thaw --help` lists together and
// `thaw COMMAND --help` prints alone.
struct CommandHelp {
  const char* name;
  const char* text;
};
constexpr CommandHelp kCommands[] = {
    {"serve",
     "  serve [SCENE]    the live service: --host 127.0.0.1, --port 8080, --token T, --state-dir DIR,\n"
     "                   --state-out FILE, --set PATH=VALUE, --device D\n"},
    {"ctl", "  ctl URL JSON...  send commands to a running service and print the replies (--token T)\n"},
    {"run",
     "  run SCENE        headless run: --until S | --steps N, --set PATH=VALUE, --metrics FILE.jsonl,\n"
     "                   --export DIR, --frames DIR, --export-mesh DIR [--mesh-format obj|ply], every\n"
     "                   --every K steps; --state-out FILE, --state-in FILE, --device D, --quiet,\n"
     "                   --no-progress. Prints the stages it built and per-stage timers.\n"},
    {"validate",
     "  validate CASE    a validation case against its reference: --res R, --set, --json; --list;\n"
     "                   --all: every case at its default resolution, one table; --twice [--steps N]:\n"
     "                   two runs (each stopped after N steps) that must leave the same bits\n"},
    {"bench",
     "  bench throughput µs per particle-step per stage, with a hand-written reference loop (--json)\n"
     "  bench accuracy CASE  error against run time over resolutions (--res 10,15,20 --out DIR)\n"
     "  bench render     ms per frame by stage (field, upload, march, read-back, JPEG) (--sizes, --quality,\n"
     "                   --scales 1,0.75,0.5, --tint: also coloured by a dye, --json)\n"
     "  bench bodies     ice labelling and per-body sums against union-find and a plain loop (--size, "
     "--json)\n"},
    {"render",
     "  render STATE     one frame of a state file: --out FILE.png, --view surface|particles|slice,\n"
     "                   --size WxH, --camera AZ,EL[,DIST], --target X,Y,Z, --fov DEG, --colour-by\n"
     "                   phase|temperature|speed|substance:NAME, --slice AXIS[,FRACTION], --field-cells N,\n"
     "                   --quality full|fast, --tint-reference G/L (surface by a substance: the\n"
     "                   concentration of full colour; default the first frame's most), --pick X,Y\n"},
    {"info",
     "  info             OpenCL platforms and devices, and the one that would be used; the renderer\n"},
    {"scene-doc", "  scene-doc        the scene file reference (docs/SCENES.md)\n"},
};

const char* kFooter =
    "\n"
    "Scenes are JSON files in configs/ (see docs/SCENES.md); --device or THAW_DEVICE picks the OpenCL\n"
    "device: gpu, cpu, P:D, or part of its name.\n";

std::string usage() {
  std::string out = "usage: thaw <command> [options]\n\ncommands:\n";
  for (const CommandHelp& c : kCommands) out += c.text;
  return out + kFooter;
}

bool is_help(const char* a) { return !std::strcmp(a, "--help") || !std::strcmp(a, "-h"); }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || is_help(argv[1]) || !std::strcmp(argv[1], "help")) {
    std::fputs(usage().c_str(), argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  // `thaw COMMAND --help` anywhere on the line: that command's usage, and nothing run.
  for (int a = 2; a < argc; ++a) {
    if (!is_help(argv[a])) continue;
    for (const CommandHelp& c : kCommands) {
      if (cmd != c.name) continue;
      std::printf("usage: thaw %s\n%s%s", c.name, c.text, kFooter);
      return 0;
    }
  }
  try {
    if (cmd == "run") return thaw::cmd_run(argc, argv);
    if (cmd == "validate") return thaw::cmd_validate(argc, argv);
    if (cmd == "bench") return thaw::cmd_bench(argc, argv);
    if (cmd == "info") return thaw::cmd_info(argc, argv);
    if (cmd == "scene-doc") return thaw::cmd_scene_doc(argc, argv);
    if (cmd == "render") return thaw::cmd_render(argc, argv);
    if (cmd == "serve") return thaw::cmd_serve(argc, argv);
    if (cmd == "ctl") return thaw::cmd_ctl(argc, argv);
    std::fprintf(stderr, "thaw: unknown command '%s'\n\n%s", cmd.c_str(), usage().c_str());
    return 2;
  } catch (const thaw::BlowUpError& e) {
    std::fprintf(stderr, "thaw %s: simulation stopped: %s\n", cmd.c_str(), e.what());
    return 3;
  } catch (const thaw::Error& e) {
    std::fprintf(stderr, "thaw %s: %s\n", cmd.c_str(), e.what());
    return 2;
  } catch (const cl::Error& e) {
    std::fprintf(stderr, "thaw %s: OpenCL error in %s: %s (%d)\n", cmd.c_str(), e.what(),
                 thaw::cl_error_name(e.err()), e.err());
    return 4;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "thaw %s: %s\n", cmd.c_str(), e.what());
    return 4;
  }
}
