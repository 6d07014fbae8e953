#pragma once
// Colours of the particle and slice views: one per phase, and a temperature scale with its colour bar.
#include <array>
#include <cstdint>
#include <string>

#include "render/image.h"

namespace thaw {

using Rgb = std::array<std::uint8_t, 3>;

Rgb phase_rgb(std::uint8_t phase);

// A blue-white-red diverging scale (Moreland 2009's cool-warm, sampled at 9 points and interpolated):
// t = 0 blue, 0.5 near white, 1 red; clamped outside [0, 1].
Rgb cool_warm(double t);
// `base` stained by a deposit, t in [0, 1] from none to the most (clamped): toward a dark amber.
Rgb stained(const Rgb& base, double t);

// The colour bar: a vertical strip at the right edge of the image, `lo` (bottom) to `hi` (top) mapped as
// the view maps temperatures, with a one-pixel dark frame.
struct ColourBar {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the strip's pixel box, inclusive-exclusive
};
ColourBar draw_colour_bar(Image& image);

// The bar's numbers: `hi` at its top, the middle, `lo` at its bottom, as "12.3 °C" (or "0.25 m/s"),
// drawn left of the strip in a 5x7 pixel font (scaled with the image: 2x at 480 rows) on a dark plate, so
// every picture of a temperature or speed view, a PNG from `thaw render` or a streamed frame, says what
// its colours mean.
enum class BarUnit { Celsius, MetresPerSecond, GramsPerLitre };
void label_colour_bar(Image& image, const ColourBar& bar, double lo, double hi,
                      BarUnit unit = BarUnit::Celsius);
std::array<std::string, 3> colour_bar_labels(double lo, double hi,
                                             BarUnit unit = BarUnit::Celsius);  // top, middle, bottom

// Text in the 5x7 font: digits, '.', '-', '+', ' ', '°', 'C', 'm', '/', 's', 'g' and 'L' (anything else is a
// blank cell), `scale` image pixels per font pixel, its top left at (x, y); clipped to the image.
void draw_text(Image& image, const std::string& text, int x, int y, int scale, const Rgb& colour);
int text_width(const std::string& text, int scale);  // pixels, one blank column between characters

}  // namespace thaw
