#pragma once
// Host copy of the per-particle state, structure of arrays, in the device's current (sorted) order.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/particle_fields.h"

namespace thaw {

enum class Phase : std::uint8_t { Water = 0, Ice = 1, Solid = 2, Air = 3 };
inline constexpr int kPhaseCount = 4;
const char* phase_name(Phase p);

// The colour each phase is shown in (RGB): the PLY export's vertex colours (Blender reads them) and the
// renderer's particle view. A phase byte out of range is magenta, so it stands out.
std::array<std::uint8_t, 3> phase_colour(std::uint8_t phase);

using Float4 = std::array<float, 4>;  // layout-compatible with cl_float4
using Float2 = std::array<float, 2>;  // layout-compatible with cl_float2

struct HostParticles {
  std::vector<Float4> position;        // x, y, z [m]; w = mass [kg] (static solids: rho0 * Psi, Akinci 2012)
  std::vector<Float4> velocity;        // x, y, z [m/s]; w unused (0)
  std::vector<float> density;          // [kg/m^3], from the last density pass
  std::vector<std::uint8_t> phase;     // Phase
  std::vector<std::uint8_t> material;  // index into Scene::materials
  std::vector<std::uint32_t> id;       // stable identity: index at creation, survives sorting
  // Specific enthalpy [J/kg] as a compensated pair (hi, lo), h = hi + lo: small heat increments on a
  // large enthalpy (latent heat is 334 kJ/kg) would otherwise be rounded away step after step.
  std::vector<Float2> enthalpy;
  // 1 for ice held in place (an ice entry with motion "fixed"), 0 for every other particle.
  std::vector<std::uint8_t> anchored;
  // Fields a stage declares beyond the members above (rigid ice's "body" and "body_offset"), as the
  // device store downloads them and state files carry them (sim/particle_fields.h).
  std::vector<HostColumn> columns;

  std::size_t size() const { return position.size(); }
  void resize(std::size_t n);  // every member and column
  std::size_t count(Phase p) const;
  double mass(Phase p) const;  // of the particles of phase p [kg], summed in index order
  const HostColumn* column(const std::string& name) const;
  HostColumn* column(const std::string& name);
};

// The fields every run has on the device (position, velocity, density, phase, material, id), declared
// once; the heat stage adds enthalpy. Each is a member of HostParticles (member_bytes).
const std::vector<FieldSpec>& core_fields();

// A member of HostParticles by its field name (the core fields, "enthalpy" and "anchored"): its bytes,
// its element size and count; {nullptr, 0, 0} for any other name.
struct MemberBytes {
  void* data = nullptr;
  std::size_t element = 0, count = 0;
};
MemberBytes member_bytes(HostParticles& p, const std::string& name);
inline MemberBytes member_bytes(const HostParticles& p, const std::string& name) {
  return member_bytes(const_cast<HostParticles&>(p), name);
}

}  // namespace thaw
