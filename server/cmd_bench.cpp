// `thaw bench`: throughput per stage against a hand-written reference loop, and accuracy sweeps.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "bench/accuracy.h"
#include "bench/bodies_bench.h"
#include "bench/render_bench.h"
#include "bench/throughput.h"
#include "render/surface_renderer.h"
#include "server/cli_args.h"
#include "server/commands.h"
#include "sim/error.h"

namespace thaw {
namespace {

template <class T>
std::vector<T> list_of(const std::string& text, const char* option) {
  std::vector<T> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0' || v <= 0)
      throw Error(std::string(option) + ": bad item '" + item + "'");
    out.push_back(static_cast<T>(v));
  }
  if (out.empty()) throw Error(std::string(option) + ": empty list");
  return out;
}

}  // namespace

int cmd_bench(int argc, char** argv) {
  if (argc < 3) throw Error("bench needs a kind: throughput, accuracy, render or bodies");
  const std::string kind = argv[2];
  if (kind == "throughput") {
    CliArgs args(argc, argv, 3, {"--sizes", "--steps", "--device"}, {"--json"});
    // Its scene is its own (a dam break sized by --sizes, WCSPH against hand-written loops): a --set would
    // be silently ignored, so it is refused. DFSPH against WCSPH is measured with `thaw run` on the same
    // scene (docs/BENCHMARKS.md).
    if (!args.sets().empty())
      throw Error("bench throughput takes no --set ('" + args.sets().front() +
                  "'): it times its own dam-break scene against reference loops; to compare solvers, time "
                  "`thaw run dam-break --set solver.pressure=dfsph` against wcsph");
    ThroughputOptions o;
    if (auto s = args.value("--sizes")) o.sizes = list_of<std::size_t>(*s, "--sizes");
    o.steps = static_cast<int>(args.integer("--steps", o.steps));
    if (o.steps < 1) throw Error("--steps: must be >= 1");
    ClRuntime cl(args.value("--device").value_or(""));
    const Json r = bench_throughput(cl, o, !args.flag("--json"));
    if (args.flag("--json")) std::printf("%s\n", r.dump(2).c_str());
    return 0;
  }
  if (kind == "accuracy") {
    CliArgs args(argc, argv, 3, {"--res", "--out", "--device"}, {"--json"});
    if (args.positional().size() != 1)
      throw Error("bench accuracy needs one CASE (see thaw validate --list)");
    AccuracyOptions o;
    o.case_name = args.positional()[0];
    if (auto r = args.value("--res")) o.resolutions = list_of<int>(*r, "--res");
    o.out_dir = args.value("--out").value_or("bench-results");
    o.overrides = args.sets();
    ClRuntime cl(args.value("--device").value_or(""));
    const Json r = bench_accuracy(cl, o, !args.flag("--json"));
    if (args.flag("--json")) std::printf("%s\n", r.dump(2).c_str());
    return 0;
  }
  if (kind == "render") {
    CliArgs args(argc, argv, 3, {"--sizes", "--frames", "--field-cells", "--quality", "--scales"},
                 {"--json", "--tint"});
    RenderBenchOptions o;
    o.tint = args.flag("--tint");
    if (auto s = args.value("--scales")) o.scales = list_of<double>(*s, "--scales");
    for (const double s : o.scales)
      if (!(s >= SurfaceRenderer::kMinScale && s <= 1.0)) throw Error("--scales: each must be 0.25..1");
    if (auto s = args.value("--sizes")) o.sizes = list_of<std::size_t>(*s, "--sizes");
    o.frames = static_cast<int>(args.integer("--frames", o.frames));
    if (o.frames < 1) throw Error("--frames: must be >= 1");
    o.field_cells = static_cast<int>(args.integer("--field-cells", o.field_cells));
    if (o.field_cells < 16 || o.field_cells > 512) throw Error("--field-cells: expected 16..512");
    const std::string quality = args.value("--quality").value_or("full");
    if (quality != "full" && quality != "fast")
      throw Error("--quality: expected full or fast, got '" + quality + "'");
    o.fast = quality == "fast";
    const Json r = bench_render(o, !args.flag("--json"));
    if (args.flag("--json")) std::printf("%s\n", r.dump(2).c_str());
    return 0;
  }
  if (kind == "bodies") {
    CliArgs args(argc, argv, 3, {"--size", "--radius", "--reps", "--device"}, {"--json"});
    BodiesBenchOptions o;
    const long long size = args.integer("--size", static_cast<long long>(o.particles));
    if (size < 1000) throw Error("--size: must be >= 1000 particles");
    o.particles = static_cast<std::size_t>(size);
    if (auto r = args.value("--radius")) {
      const auto v = list_of<double>(*r, "--radius");
      if (v.size() != 1) throw Error("--radius: expected one value [particle spacings]");
      o.radius = v[0];
    }
    o.reps = static_cast<int>(args.integer("--reps", o.reps));
    if (o.reps < 1) throw Error("--reps: must be >= 1");
    ClRuntime cl(args.value("--device").value_or(""));
    const Json r = bench_bodies(cl, o, !args.flag("--json"));
    if (args.flag("--json")) std::printf("%s\n", r.dump(2).c_str());
    return 0;
  }
  throw Error("unknown bench '" + kind + "' (throughput, accuracy, render, bodies)");
}

}  // namespace thaw
