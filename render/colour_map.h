#pragma once
// Colours of the particle and slice views: one per phase, and a temperature scale with its colour bar.
#include <array>
#include <cstdint>

#include "render/image.h"

namespace thaw {

using Rgb = std::array<std::uint8_t, 3>;

Rgb phase_rgb(std::uint8_t phase);

// A blue-white-red diverging scale (Moreland 2009's cool-warm, sampled at 9 points and interpolated):
// t = 0 blue, 0.5 near white, 1 red; clamped outside [0, 1].
Rgb cool_warm(double t);

// The colour bar: a vertical strip at the right edge of the image, `lo` (bottom) to `hi` (top) mapped as
// the view maps temperatures, with a one-pixel dark frame.
struct ColourBar {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the strip's pixel box, inclusive-exclusive
};
ColourBar draw_colour_bar(Image& image);

}  // namespace thaw
