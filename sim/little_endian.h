#pragma once
// Appending values to a little-endian binary file (VTK, PLY): through memory, so the exact bits (NaN
// payloads included) reach the file, byte-swapped on a big-endian host.
#include <algorithm>
#include <bit>
#include <cstring>
#include <string>

namespace thaw {

template <typename T>
void put_little_endian(std::string& out, const T& v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  if constexpr (std::endian::native != std::endian::little) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

}  // namespace thaw
