#include "bench/render_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "render/density_field.h"
#include "render/egl_context.h"
#include "render/image_io.h"
#include "render/picking.h"
#include "render/snapshot.h"
#include "render/surface_renderer.h"
#include "sim/solver.h"

namespace thaw {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Water 2 x 1 x 1 with an ice cube of half its height standing in it, on a floor and two walls.
RenderSnapshot bench_snapshot(std::size_t particles) {
  const double dx = std::cbrt(0.2 * 0.1 * 0.1 / double(particles));
  const Json doc = {
      {"name", "bench/render"},
      {"domain", {{"min", {0, 0, 0}}, {"max", {0.2, 0.1, 0.12}}}},
      {"spacing", dx},
      {"materials",
       {{"water", {{"kind", "fluid"}, {"density", 1000}, {"conductivity", 0.56}, {"specific_heat", 4217}}},
        {"ice",
         {{"kind", "ice"},
          {"density", 917},
          {"conductivity", 2.22},
          {"specific_heat", 2050},
          {"melts_into", "water"}}}}},
      {"fluids", {{{"material", "water"}, {"box", {{"min", {0, 0, 0}}, {"max", {0.2, 0.1, 0.1}}}}}}},
      {"ice", {{{"material", "ice"}, {"box", {{"min", {0.07, 0.025, 0.04}}, {"max", {0.12, 0.075, 0.11}}}}}}},
  };
  const Scene scene = scene_from_json(doc);
  RenderSnapshot s = make_snapshot(sample_scene(scene), {}, scene, 0.0, 0);
  // A dye for the tinted frames: 0 to 2 g/L along x through the water, a red from the scene's palette.
  std::vector<float> dye(s.position.size(), 0.0f);
  for (std::size_t p = 0; p < dye.size(); ++p)
    if (static_cast<Phase>(s.phase[p]) == Phase::Water) dye[p] = 10.0f * s.position[p].x();
  s.substances.push_back({"dye", std::move(dye)});
  s.substance_colours.push_back(Substance{}.colour);
  return s;
}

}  // namespace

Json bench_render(const RenderBenchOptions& o, bool print) {
  EglContext gl;
  SurfaceRenderer renderer(gl);
  renderer.set_quality(o.fast ? SurfaceRenderer::Quality::Fast : SurfaceRenderer::Quality::Full);
  Json out;
  out["quality"] = o.fast ? "fast" : "full";
  out["renderer"] = gl.description();
  out["unit"] = "milliseconds per frame, fastest of the timed frames";
  Json rows = Json::array();
  if (print) {
    std::printf("renderer: %s, quality %s\n", gl.description().c_str(), o.fast ? "fast" : "full");
    std::printf("%-9s %-10s %5s %4s %8s %8s %8s %9s %8s %8s | %10s\n", "particles", "image", "scale", "tint",
                "field", "upload", "march", "readback", "jpeg", "total", "cpu march");
  }
  for (std::size_t n : o.sizes) {
    const RenderSnapshot snap = bench_snapshot(n);
    for (const auto& [w, h] : o.resolutions)
      for (const double scale : o.scales)
        for (const bool tinted : o.tint ? std::vector<bool>{false, true} : std::vector<bool>{false}) {
          FieldOptions fo;
          fo.max_cells = o.field_cells;
          if (tinted) fo.tint = "dye";
          renderer.set_scale(scale);
          OrbitCamera cam = OrbitCamera::framing(snap.domain_min.cast<double>(),
                                                 snap.domain_max.cast<double>(), 30, 25, w, h);
          double field = 1e300, upload = 1e300, march = 1e300, readback = 1e300, jpeg = 1e300, total = 1e300;
          std::size_t jpeg_bytes = 0;
          DensityFields fields;
          for (int f = 0; f <= o.frames; ++f) {
            const auto t0 = Clock::now();
            fields = build_density_fields(snap, fo);
            const double tf = ms_since(t0);
            const Image img = renderer.render(fields, cam);
            const auto t1 = Clock::now();
            const std::string bytes = encode_jpeg(img, 80);
            const double tj = ms_since(t1);
            const double tt = ms_since(t0);
            if (f == 0) continue;  // the first frame compiles shaders and allocates textures
            const auto t = renderer.last_times();
            field = std::min(field, tf);
            upload = std::min(upload, t.upload_ms);
            march = std::min(march, t.march_ms);
            readback = std::min(readback, t.readback_ms);
            jpeg = std::min(jpeg, tj);
            total = std::min(total, tt);
            jpeg_bytes = bytes.size();
          }
          // The reference: the same surface search on the CPU, one pick per pixel (single thread, no
          // shading), at the smallest image only: it is slow by design.
          double cpu = -1;
          if (w == o.resolutions.front().first && h == o.resolutions.front().second &&
              scale == o.scales.front() && !tinted) {
            const auto t0 = Clock::now();
            long hits = 0;
            for (int y = 0; y < h; ++y)
              for (int x = 0; x < w; ++x) {
                Eigen::Vector3d p, nrm;
                hits += pick(fields, cam, x, y, p, nrm);
              }
            cpu = ms_since(t0);
            (void)hits;
          }
          Json row = {{"particles", snap.position.size()},
                      {"width", w},
                      {"height", h},
                      {"scale", scale},
                      {"tint", tinted},
                      {"field_grid", {fields.grid.nx, fields.grid.ny, fields.grid.nz}},
                      {"field_ms", field},
                      {"upload_ms", upload},
                      {"march_ms", march},
                      {"readback_ms", readback},
                      {"jpeg_ms", jpeg},
                      {"jpeg_bytes", jpeg_bytes},
                      {"total_ms", total}};
          if (cpu >= 0) row["reference_cpu_march_ms"] = cpu;
          rows.push_back(row);
          if (print) {
            char image[32];
            std::snprintf(image, sizeof image, "%dx%d", w, h);
            char reference[32] = "";
            if (cpu >= 0) std::snprintf(reference, sizeof reference, "%10.2f", cpu);
            std::printf("%-9zu %-10s %5.2f %4s %8.2f %8.2f %8.2f %9.2f %8.2f %8.2f | %10s\n",
                        snap.position.size(), image, scale, tinted ? "dye" : "-", field, upload, march,
                        readback, jpeg, total, reference);
          }
          std::fflush(stdout);
        }
  }
  if (print)
    std::printf(
        "(field: metaball fields on the CPU; upload: max field, phases, blocks, textures; march: the GL draw "
        "to completion;\n scale: the fraction of width and height marched; readback: the stretch below 1, "
        "glReadPixels; jpeg: libturbojpeg q80; cpu march: one CPU pick per pixel, "
        "single thread, the reference;\n tint dye: coloured by a dye of 0 to 2 g/L through the water, "
        "against the plain frame above it)\n");
  out["runs"] = rows;
  return out;
}

}  // namespace thaw
