#pragma once
// Iso-surface meshes of ice and water per frame, for other tools (Blender, ParaView): ice_%06d.<fmt>
// and water_%06d.<fmt> in one directory, each replaced atomically so a reader never sees half a file.
#include <cstddef>
#include <string>

#include "render/density_field.h"
#include "render/snapshot.h"

namespace thaw {

class MeshExporter {
 public:
  // `format` is "obj" or "ply"; creates `dir` and its parents. Throws thaw::Error naming the format or
  // the directory when either will not do.
  MeshExporter(std::string dir, std::string format);

  // Contours the snapshot's ice and water fields at options.iso and writes frame frames(). A phase with
  // no surface writes no file, but the frame is counted, so file numbers stay frame numbers.
  void write(const RenderSnapshot& s, const FieldOptions& options = {});

  std::size_t frames() const { return frames_; }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_, format_;
  std::size_t frames_ = 0;
};

}  // namespace thaw
