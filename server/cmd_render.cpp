// `thaw render STATE --out FILE.png [--pick X,Y]`: one frame of a state file, off-screen, and the surface
// point under a pixel.
#include <cstdio>
#include <sstream>

#include "render/image_io.h"
#include "render/picking.h"
#include "server/cli_args.h"
#include "server/commands.h"
#include "server/render_options.h"
#include "sim/error.h"
#include "sim/json_text.h"
#include "sim/state_file.h"
#include "sim/thermal.h"

namespace thaw {

int cmd_render(int argc, char** argv) {
  std::vector<std::string> with_value = {"--out", "--pick"};
  for (const char* o : kRenderValueOptions) with_value.emplace_back(o);
  CliArgs args(argc, argv, 2, with_value, {"--quiet"});
  if (args.positional().size() != 1) throw Error("render takes one state file (from thaw run --state-out)");
  const auto out = args.value("--out");
  if (!out) throw Error("render needs --out FILE.png");
  const SimState state = read_state_file(args.positional()[0]);
  const Scene scene = scene_from_json(parse_json(state.scene_json));
  check_state(state, scene, args.positional()[0]);
  const RenderOptions o = render_options(args, scene.camera);
  const RenderSnapshot snap =
      make_snapshot(state.particles, temperatures_of(state.particles, scene), scene, state.time, state.step);

  if (auto v = args.value("--pick")) {
    // The surface under a pixel, as the browser will aim a dryer: X,Y in pixels from the top left.
    double px = 0, py = 0;
    char comma = 0, rest = 0;
    std::istringstream in(*v);
    if (!(in >> px >> comma >> py) || comma != ',' || (in >> rest) || px < 0 || py < 0 || px >= o.width ||
        py >= o.height)
      throw Error("--pick: expected X,Y inside the " + std::to_string(o.width) + "x" +
                  std::to_string(o.height) + " image, got '" + *v + "'");
    Eigen::Vector3d hit, normal;
    const DensityFields fields = build_density_fields(snap, o.field);
    if (pick(fields, camera_for(o, snap), px, py, hit, normal))
      std::printf("pick %g,%g: hit (%.6g, %.6g, %.6g) m, normal (%.4f, %.4f, %.4f)\n", px, py, hit.x(),
                  hit.y(), hit.z(), normal.x(), normal.y(), normal.z());
    else
      std::printf("pick %g,%g: no surface\n", px, py);
  }
  FrameRenderer renderer(o);
  write_png(*out, renderer.render(snap));
  if (!args.flag("--quiet")) {
    const auto& t = renderer.last_times();
    std::printf("thaw render: %s, t = %.6g s, %dx%d %s view -> %s (", args.positional()[0].c_str(),
                state.time, o.width, o.height, o.view.c_str(), out->c_str());
    if (o.view == "surface")
      std::printf("field %.1f ms, upload %.1f ms, march %.1f ms, read-back %.1f ms", t.field_ms, t.upload_ms,
                  t.march_ms, t.readback_ms);
    else
      std::printf("draw %.1f ms", t.draw_ms);
    std::printf(") on %s\n", renderer.description().c_str());
  }
  return 0;
}

}  // namespace thaw
