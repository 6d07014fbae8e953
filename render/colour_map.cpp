#include "render/colour_map.h"

#include <algorithm>
#include <cmath>

#include "sim/particles.h"

namespace thaw {

Rgb phase_rgb(std::uint8_t phase) { return phase_colour(phase); }

Rgb cool_warm(double t) {
  // Moreland, "Diverging Color Maps for Scientific Visualization" (2009), cool-warm at t = 0, 1/8, ..., 1.
  static constexpr double kTable[9][3] = {{59, 76, 192},   {98, 130, 234},  {141, 176, 254},
                                          {184, 208, 249}, {221, 221, 221}, {245, 196, 173},
                                          {244, 154, 123}, {222, 96, 77},   {180, 4, 38}};
  if (!std::isfinite(t)) t = 0.5;
  t = std::clamp(t, 0.0, 1.0) * 8.0;
  const int k = std::min(static_cast<int>(t), 7);
  const double f = t - k;
  Rgb out;
  for (int c = 0; c < 3; ++c)
    out[static_cast<std::size_t>(c)] =
        static_cast<std::uint8_t>(std::lround(kTable[k][c] + f * (kTable[k + 1][c] - kTable[k][c])));
  return out;
}

ColourBar draw_colour_bar(Image& image) {
  ColourBar bar;
  const int w = std::max(6, image.width / 40), margin = std::max(4, image.width / 80);
  bar.x1 = image.width - margin;
  bar.x0 = bar.x1 - w;
  bar.y0 = image.height / 8;
  bar.y1 = image.height - image.height / 8;
  for (int y = bar.y0 - 1; y <= bar.y1; ++y)
    for (int x = bar.x0 - 1; x <= bar.x1; ++x) {
      if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
      std::uint8_t* px = &image.rgba[(std::size_t(y) * image.width + x) * 4];
      const bool frame = x < bar.x0 || x >= bar.x1 || y < bar.y0 || y >= bar.y1;
      // Top of the strip is the hot end.
      const Rgb c = frame ? Rgb{30, 30, 30} : cool_warm(double(bar.y1 - 1 - y) / double(bar.y1 - bar.y0 - 1));
      px[0] = c[0];
      px[1] = c[1];
      px[2] = c[2];
      px[3] = 255;
    }
  return bar;
}

}  // namespace thaw
