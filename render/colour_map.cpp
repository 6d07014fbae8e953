#include "render/colour_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

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

namespace {

// 5x7 glyphs, a row per byte, the leftmost pixel in bit 4.
struct Glyph {
  const char* utf8;
  std::uint8_t rows[7];
};
constexpr Glyph kGlyphs[] = {
    {"0", {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {"1", {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {"2", {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {"3", {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {"4", {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {"5", {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {"6", {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {"7", {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {"8", {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {"9", {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {".", {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {"-", {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {"+", {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}}, {"\u00B0", {0x0C, 0x12, 0x12, 0x0C, 0x00, 0x00, 0x00}},
    {"C", {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}}, {"m", {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}},
    {"/", {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}}, {"s", {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}},
    {"g", {0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E}}, {"L", {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
};
constexpr int kGlyphW = 5, kGlyphH = 7;

// The glyphs of `text` in order (nullptr: a blank cell); '°' is two bytes in UTF-8.
std::vector<const Glyph*> glyphs_of(const std::string& text) {
  std::vector<const Glyph*> out;
  for (std::size_t i = 0; i < text.size();) {
    const Glyph* found = nullptr;
    std::size_t used = 1;
    for (const Glyph& g : kGlyphs) {
      const std::size_t n = std::strlen(g.utf8);
      if (text.compare(i, n, g.utf8) == 0) {
        found = &g;
        used = n;
        break;
      }
    }
    out.push_back(found);
    i += used;
  }
  return out;
}

void fill(Image& image, int x0, int y0, int x1, int y1, const Rgb& c) {
  for (int y = std::max(0, y0); y < std::min(image.height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(image.width, x1); ++x) {
      std::uint8_t* px = &image.rgba[(std::size_t(y) * image.width + x) * 4];
      px[0] = c[0];
      px[1] = c[1];
      px[2] = c[2];
      px[3] = 255;
    }
}

}  // namespace

int text_width(const std::string& text, int scale) {
  const int n = static_cast<int>(glyphs_of(text).size());
  return n == 0 ? 0 : scale * (n * (kGlyphW + 1) - 1);
}

void draw_text(Image& image, const std::string& text, int x, int y, int scale, const Rgb& colour) {
  int left = x;
  for (const Glyph* g : glyphs_of(text)) {
    if (g)
      for (int r = 0; r < kGlyphH; ++r)
        for (int c = 0; c < kGlyphW; ++c)
          if (g->rows[r] & (0x10 >> c))
            fill(image, left + c * scale, y + r * scale, left + (c + 1) * scale, y + (r + 1) * scale, colour);
    left += (kGlyphW + 1) * scale;
  }
}

std::array<std::string, 3> colour_bar_labels(double lo, double hi, BarUnit unit) {
  std::array<std::string, 3> out;
  const double values[3] = {hi, 0.5 * (lo + hi), lo};
  const bool speed = unit == BarUnit::MetresPerSecond, grams = unit == BarUnit::GramsPerLitre;
  for (int k = 0; k < 3; ++k) {
    char text[48];
    // "-0.0" reads as a different temperature from "0.0"; it is the same one.
    const double v = std::abs(values[k]) < (speed ? 0.005 : grams ? 1e-9 : 0.05) ? 0.0 : values[k];
    if (speed)
      std::snprintf(text, sizeof text, "%.2f m/s", v);
    else if (grams)  // 3 significant figures: a dye's fractions of a g/L and a brine's hundreds alike
      std::snprintf(text, sizeof text, "%.3g g/L", v);
    else
      std::snprintf(text, sizeof text, "%.1f \u00B0C", v);
    out[std::size_t(k)] = text;
  }
  return out;
}

void label_colour_bar(Image& image, const ColourBar& bar, double lo, double hi, BarUnit unit) {
  const int scale = std::max(1, image.height / 240), pad = scale;
  const auto labels = colour_bar_labels(lo, hi, unit);
  const int ys[3] = {bar.y0, (bar.y0 + bar.y1) / 2, bar.y1 - 1};
  for (int k = 0; k < 3; ++k) {
    const std::string& text = labels[std::size_t(k)];
    const int w = text_width(text, scale), h = kGlyphH * scale;
    const int right = bar.x0 - 1 - 2 * scale, x = right - w, y = ys[k] - h / 2;
    fill(image, x - pad, y - pad, right + pad, y + h + pad, Rgb{30, 30, 30});
    draw_text(image, text, x, y, scale, Rgb{235, 235, 235});
  }
}

Rgb stained(const Rgb& base, double t) {
  const double f = 0.85 * std::clamp(t, 0.0, 1.0);
  const Rgb amber = {115, 70, 12};
  Rgb out{};
  for (std::size_t k = 0; k < 3; ++k)
    out[k] = static_cast<std::uint8_t>(std::lround(base[k] + f * (double(amber[k]) - base[k])));
  return out;
}

}  // namespace thaw
