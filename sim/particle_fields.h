#pragma once
// Per-particle fields, each declared once by the stage that owns it: its name (the state file's section,
// the VTU array, the device buffer), its element type and width, and whether it is saved and exported.
// The device buffers, the neighbour sort's reorder, the host copy, the state file's sections and the
// VTU export all follow from the declarations (sim/particle_store.h), so a stage that adds a field
// declares it in its own file and touches nothing else:
//
//   fields_.heat = store.add({"enthalpy", FieldType::Float32, 2});  // the heat stage's constructor
//
// Every field is gathered into the sort's order with the others: a particle carries all its fields.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace thaw {

enum class FieldType : std::uint8_t { Float32 = 1, UInt32 = 2, UInt8 = 3 };

std::size_t scalar_bytes(FieldType t);
const char* opencl_scalar(FieldType t);  // "float", "uint", "uchar"
const char* vtk_scalar(FieldType t);     // "Float32", "UInt32", "UInt8"

struct FieldSpec {
  std::string name;
  FieldType type = FieldType::Float32;
  int width = 1;           // scalars per particle: 1, 2 or 4 (a float4 is Float32 x 4)
  bool saved = true;       // a state-file section; a reader that does not know the field refuses the file
  bool exported = false;   // an array of the VTU export
  std::uint32_t fill = 0;  // every scalar's bits where nothing was uploaded (a state without the field)

  std::size_t bytes() const { return scalar_bytes(type) * std::size_t(width); }
  std::string opencl_type() const;  // "float4", "float2", "uchar", "uint"
};

// A field's values on the host, in the particles' current order: bytes() * size bytes.
struct HostColumn {
  FieldSpec spec;
  std::vector<std::uint8_t> bytes;

  std::size_t size() const { return spec.bytes() ? bytes.size() / spec.bytes() : 0; }
  template <class T>
  const T* as() const {
    return reinterpret_cast<const T*>(bytes.data());
  }
  template <class T>
  T* as() {
    return reinterpret_cast<T*>(bytes.data());
  }
};

}  // namespace thaw
