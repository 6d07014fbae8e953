#include "sim/particles.h"

#include <algorithm>

namespace thaw {

const char* phase_name(Phase p) {
  switch (p) {
    case Phase::Water:
      return "water";
    case Phase::Ice:
      return "ice";
    case Phase::Solid:
      return "solid";
    case Phase::Air:
      return "air";
  }
  return "unknown";
}

std::array<std::uint8_t, 3> phase_colour(std::uint8_t phase) {
  switch (static_cast<Phase>(phase)) {
    case Phase::Water:
      return {40, 110, 230};
    case Phase::Ice:
      return {200, 240, 255};
    case Phase::Solid:
      return {150, 150, 150};
    case Phase::Air:
      return {255, 255, 255};
  }
  return {255, 0, 255};
}

void HostParticles::resize(std::size_t n) {
  position.resize(n);
  velocity.resize(n);
  density.resize(n);
  phase.resize(n);
  material.resize(n);
  id.resize(n);
  enthalpy.resize(n);
  anchored.resize(n);
  for (HostColumn& c : columns) c.bytes.resize(n * c.spec.bytes());
}

const HostColumn* HostParticles::column(const std::string& name) const {
  for (const HostColumn& c : columns)
    if (c.spec.name == name) return &c;
  return nullptr;
}

HostColumn* HostParticles::column(const std::string& name) {
  for (HostColumn& c : columns)
    if (c.spec.name == name) return &c;
  return nullptr;
}

const std::vector<FieldSpec>& core_fields() {
  static const std::vector<FieldSpec> fields = {
      {"position", FieldType::Float32, 4, true, false},  // x, y, z [m]; w = mass [kg]
      {"velocity", FieldType::Float32, 4, true, false},  // [m/s]; w unused
      {"density", FieldType::Float32, 1, true, false},   // [kg/m^3]
      {"phase", FieldType::UInt8, 1, true, false},       // Phase
      {"material", FieldType::UInt8, 1, true, false},    // index into Scene::materials
      {"id", FieldType::UInt32, 1, true, false},         // stable identity
  };
  return fields;
}

MemberBytes member_bytes(HostParticles& p, const std::string& name) {
  const auto of = [](auto& v) { return MemberBytes{static_cast<void*>(v.data()), sizeof(v[0]), v.size()}; };
  if (name == "position") return of(p.position);
  if (name == "velocity") return of(p.velocity);
  if (name == "density") return of(p.density);
  if (name == "phase") return of(p.phase);
  if (name == "material") return of(p.material);
  if (name == "id") return of(p.id);
  if (name == "enthalpy") return of(p.enthalpy);
  if (name == "anchored") return of(p.anchored);
  return {};
}

std::size_t HostParticles::count(Phase p) const {
  return static_cast<std::size_t>(std::count(phase.begin(), phase.end(), static_cast<std::uint8_t>(p)));
}

double HostParticles::mass(Phase p) const {
  double m = 0;
  for (std::size_t i = 0; i < size(); ++i)
    if (phase[i] == static_cast<std::uint8_t>(p)) m += double(position[i][3]);
  return m;
}

}  // namespace thaw
