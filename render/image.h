#pragma once
// A frame as the renderer hands it out: 8-bit RGBA, rows top to bottom (row 0 is the top of the
// picture, as image files and browsers expect; OpenGL's bottom-up rows are flipped at read-back).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace thaw {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4 bytes, x fastest

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(std::size_t(w) * std::size_t(h) * 4, 0) {}
  std::uint8_t* pixel(int x, int y) { return rgba.data() + (std::size_t(y) * std::size_t(width) + x) * 4; }
  const std::uint8_t* pixel(int x, int y) const {
    return rgba.data() + (std::size_t(y) * std::size_t(width) + x) * 4;
  }
};

}  // namespace thaw
