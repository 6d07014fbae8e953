#include "render/mesh_export.h"

#include <cstdio>
#include <filesystem>
#include <system_error>

#include "render/marching_cubes.h"
#include "sim/error.h"
#include "sim/state_file.h"

namespace thaw {

MeshExporter::MeshExporter(std::string dir, std::string format)
    : dir_(std::move(dir)), format_(std::move(format)) {
  if (format_ != "obj" && format_ != "ply")
    throw Error("mesh export: unknown format '" + format_ + "' (expected obj or ply)");
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw Error("cannot create mesh export directory '" + dir_ + "': " + ec.message());
  if (!std::filesystem::is_directory(dir_, ec))
    throw Error("cannot create mesh export directory '" + dir_ + "': exists and is not a directory");
}

void MeshExporter::write(const RenderSnapshot& s, const FieldOptions& options) {
  const DensityFields f = build_density_fields(s, options);
  const std::filesystem::path dir(dir_);
  for (const auto& [name, values] : {std::pair<const char*, const std::vector<float>*>{"ice", &f.ice},
                                     std::pair<const char*, const std::vector<float>*>{"water", &f.water}}) {
    const Mesh m = extract_isosurface(f.grid, *values, f.iso);
    if (m.triangles.empty()) continue;
    char file[64];
    std::snprintf(file, sizeof file, "%s_%06zu.%s", name, frames_, format_.c_str());
    // Exports need not survive a power cut, only never be seen half-written: rename without fsync.
    write_file_atomically((dir / file).string(), format_ == "obj" ? mesh_obj(m, name) : mesh_ply(m),
                          Durability::Visible);
  }
  ++frames_;
}

}  // namespace thaw
