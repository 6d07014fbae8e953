#pragma once
// Rendering: milliseconds per frame for each stage (field, upload, march, read-back, JPEG) at several
// image sizes and particle counts, with the CPU pick march over the same pixels as the reference loop.
#include <vector>

#include "sim/scene.h"

namespace thaw {

struct RenderBenchOptions {
  std::vector<std::size_t> sizes = {25000, 100000};  // ice + water particles
  std::vector<std::pair<int, int>> resolutions = {{320, 240}, {640, 480}, {1280, 720}};
  int frames = 5;                      // timed frames per case, after one untimed; the fastest is reported
  int field_cells = 128;               // FieldOptions::max_cells
  bool fast = false;                   // SurfaceRenderer::Quality::Fast
  std::vector<double> scales = {1.0};  // SurfaceRenderer::set_scale, each against the first in the same run
  bool tint = false;  // also each case coloured by a dye through the water, against the plain frame
};

// Sizes are particles of ice and water: a block of water with an ice cube standing in it.
Json bench_render(const RenderBenchOptions& o, bool print);

}  // namespace thaw
