#pragma once
// The metaball fields the renderer ray-marches and the mesh exporter contours: for each of ice, water,
// static solids and glass (solids of a transparent material), a scalar field on one regular grid over the
// particles, about 1 inside the phase's particles and falling to 0 outside; the surface is the iso-level
// `iso` (0.5: about half a spacing beyond the outermost particle centres).
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "render/snapshot.h"

namespace thaw {

// Node (i, j, k) sits at origin + cell * (i, j, k); values are stored x-fastest.
struct FieldGrid {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  float cell = 0;
  int nx = 0, ny = 0, nz = 0;
  std::size_t size() const { return std::size_t(nx) * ny * nz; }
  std::size_t index(int i, int j, int k) const { return (std::size_t(k) * ny + j) * nx + i; }
};

struct FieldOptions {
  int max_cells = 128;  // nodes along the longest axis of the particles' bounds (plus margins)
  float iso = 0.5f;     // surface level
};

struct DensityFields {
  FieldGrid grid;
  float iso = 0.5f;
  std::vector<float> ice, water, solid, glass;  // grid.size() values each; glass empty when there is none
};

DensityFields build_density_fields(const RenderSnapshot& s, const FieldOptions& options = {});

// Trilinear sample; 0 outside the grid.
float sample_field(const FieldGrid& g, const std::vector<float>& values, const Eigen::Vector3f& p);

}  // namespace thaw
