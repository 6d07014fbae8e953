#pragma once
// The metaball fields the renderer ray-marches and the mesh exporter contours: for each of ice, water,
// static solids and glass (solids of a transparent material), a scalar field on one regular grid over the
// particles, about 1 inside the phase's particles and falling to 0 outside; the surface is the iso-level
// `iso` (0.5: about half a spacing beyond the outermost particle centres).
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
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

// The most a tint's full-colour concentration may be set to [g/L] (--tint-reference, view.set).
inline constexpr double kMaxTintReference = 1e4;
// The least, but for 0 (auto) [g/L]: a microgram a litre, well within a float.
inline constexpr double kMinTintReference = 1e-6;

struct FieldOptions {
  int max_cells = 128;  // nodes along the longest axis of the particles' bounds (plus margins)
  float iso = 0.5f;     // surface level
  // A substance to tint by (the surface view coloured by it): its dye and stain fields are built too.
  std::string tint;
  // The concentration [kg/m^3] at which the dye field reads 1; 0: the most any water particle holds.
  float tint_reference = 0;
  bool operator==(const FieldOptions&) const = default;
};

struct DensityFields {
  FieldGrid grid;
  float iso = 0.5f;
  std::vector<float> ice, water, solid, glass;  // grid.size() values each; glass empty when there is none
  // With a tint: the water's volume fraction times its concentration over tint_reference (so about c / c_ref
  // inside water), and a coating's deposit over its capacity (or the most any holds) times the solids' and
  // ice's volume fraction. Empty: no tint, or nothing holds any.
  std::vector<float> dye, stain;
  float tint_reference = 0;  // the reference used [kg/m^3]
  std::array<float, 3> tint_colour = {1, 1, 1};
};

DensityFields build_density_fields(const RenderSnapshot& s, const FieldOptions& options = {});

// Trilinear sample; 0 outside the grid.
float sample_field(const FieldGrid& g, const std::vector<float>& values, const Eigen::Vector3f& p);

}  // namespace thaw
