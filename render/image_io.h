#pragma once
// Encoding frames once for every consumer (docs/ARCHITECTURE.md, Renderer): JPEG for streams, PNG for files
// and golden images. All in memory; a failure is a thaw::Error naming the codec and its message.
#include <string>
#include <string_view>

#include "render/image.h"

namespace thaw {

// Lossless RGBA PNG (libpng's simplified API), alpha kept.
std::string encode_png(const Image& image);
// Baseline JFIF (libturbojpeg), 4:2:0 chroma, alpha dropped; quality in [1, 100].
std::string encode_jpeg(const Image& image, int quality);
// Any PNG libpng reads, converted to 8-bit RGBA.
Image decode_png(std::string_view bytes);
// encode_png, then replaced atomically so a reader never sees half a file.
void write_png(const std::string& path, const Image& image);

}  // namespace thaw
