#include "sim/particle_export.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <numeric>
#include <system_error>

#include "sim/error.h"
#include "sim/little_endian.h"
#include "sim/state_file.h"
#include "sim/substance_stage.h"

namespace thaw {
namespace {

// Shortest text that reads back as the same double, so frame times in the .pvd are exact.
std::string exact(double v) {
  std::array<char, 32> buf{};
  const auto result = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), result.ptr);
}

std::string frame_name(std::size_t frame, const char* extension) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "frame_%06zu.%s", frame, extension);
  return buf;
}

// The device keeps particles in cell order, which changes every sort; id order is stable.
std::vector<std::size_t> id_order(const HostParticles& p) {
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
  return order;
}

void check_sizes(const HostParticles& p, const std::string& dir) {
  const std::size_t n = p.position.size();
  if (p.velocity.size() != n || p.density.size() != n || p.phase.size() != n || p.material.size() != n ||
      p.id.size() != n) {
    throw Error("export to '" + dir + "': particle array sizes inconsistent (position " + std::to_string(n) +
                ", velocity " + std::to_string(p.velocity.size()) + ", density " +
                std::to_string(p.density.size()) + ", phase " + std::to_string(p.phase.size()) +
                ", material " + std::to_string(p.material.size()) + ", id " + std::to_string(p.id.size()) +
                ")");
  }
}

float speed(const Float4& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// One VTK data array: its raw little-endian bytes in id order.
struct VtkArray {
  std::string name;
  const char* type;  // VTK type name: Float32, UInt8, UInt32, Int64
  int components;
  std::string bytes;
};

// Per-particle fields shown in ParaView; temperature when the scene has heat.
std::vector<VtkArray> point_data(const HostParticles& p, const std::vector<std::size_t>& order,
                                 const std::vector<float>& temperature) {
  const std::size_t n = order.size();
  VtkArray velocity{"velocity", "Float32", 3, {}}, speed_array{"speed", "Float32", 1, {}};
  VtkArray phase{"phase", "UInt8", 1, {}}, material{"material", "UInt8", 1, {}};
  VtkArray density{"density", "Float32", 1, {}}, mass{"mass", "Float32", 1, {}}, id{"id", "UInt32", 1, {}};
  velocity.bytes.reserve(12 * n);
  speed_array.bytes.reserve(4 * n);
  density.bytes.reserve(4 * n);
  mass.bytes.reserve(4 * n);
  id.bytes.reserve(4 * n);
  for (std::size_t i : order) {
    for (int c = 0; c < 3; ++c) put_little_endian(velocity.bytes, p.velocity[i][c]);
    put_little_endian(speed_array.bytes, speed(p.velocity[i]));
    put_little_endian(phase.bytes, p.phase[i]);
    put_little_endian(material.bytes, p.material[i]);
    put_little_endian(density.bytes, p.density[i]);
    put_little_endian(mass.bytes, p.position[i][3]);
    put_little_endian(id.bytes, p.id[i]);
  }
  std::vector<VtkArray> arrays;
  for (VtkArray* a : {&velocity, &speed_array, &phase, &material, &density, &mass, &id}) {
    arrays.push_back(std::move(*a));
  }
  if (!temperature.empty()) {
    VtkArray t{"temperature", "Float32", 1, {}};
    t.bytes.reserve(4 * n);
    for (std::size_t i : order) put_little_endian(t.bytes, temperature[i]);
    arrays.push_back(std::move(t));
  }
  // Substances (sim/substance_stage.h): each one's mass fraction, the amount over the particle's mass.
  for (const HostColumn& c : p.columns) {
    if (c.spec.name.rfind(kSubstancePrefix, 0) != 0 || c.spec.width != 2 || c.size() != p.size()) continue;
    VtkArray a{c.spec.name, "Float32", 1, {}};
    a.bytes.reserve(4 * n);
    const Float2* q = c.as<Float2>();
    for (std::size_t i : order) {
      const float m = p.position[i][3];
      put_little_endian(a.bytes,
                        m > 0.0f ? static_cast<float>((double(q[i][0]) + double(q[i][1])) / m) : 0.0f);
    }
    arrays.push_back(std::move(a));
  }
  // Surface-active substances on the surface: the surface excess, the amount over the particle's area
  // [kg/m^2].
  const HostColumn* area = p.column("surface_area");
  for (const HostColumn& c : p.columns) {
    if (c.spec.name.rfind(kAdsorbedPrefix, 0) != 0 || c.spec.width != 2 || c.size() != p.size()) continue;
    VtkArray a{c.spec.name, "Float32", 1, {}};
    a.bytes.reserve(4 * n);
    const Float2* q = c.as<Float2>();
    for (std::size_t i : order) {
      const float ai = area && area->size() == p.size() ? area->as<float>()[i] : 0.0f;
      put_little_endian(a.bytes,
                        ai > 0.0f ? static_cast<float>((double(q[i][0]) + double(q[i][1])) / ai) : 0.0f);
    }
    arrays.push_back(std::move(a));
  }
  // Coatings on solids and ice: each boundary particle's deposit [kg] (over the spacing squared, the deposit
  // per area).
  for (const HostColumn& c : p.columns) {
    if (c.spec.name.rfind(kDepositedPrefix, 0) != 0 || c.spec.width != 2 || c.size() != p.size()) continue;
    VtkArray a{c.spec.name, "Float32", 1, {}};
    a.bytes.reserve(4 * n);
    const Float2* q = c.as<Float2>();
    for (std::size_t i : order)
      put_little_endian(a.bytes, static_cast<float>(double(q[i][0]) + double(q[i][1])));
    arrays.push_back(std::move(a));
  }
  // Every field a stage declared as exported (sim/particle_fields.h), element by element in id order.
  for (const HostColumn& c : p.columns) {
    if (!c.spec.exported || c.size() != p.size()) continue;
    VtkArray a{c.spec.name, vtk_scalar(c.spec.type), c.spec.width, {}};
    const std::size_t element = c.spec.bytes(), word = scalar_bytes(c.spec.type);
    a.bytes.reserve(element * n);
    for (std::size_t i : order) {
      const std::uint8_t* e = c.bytes.data() + i * element;
      for (std::size_t k = 0; k < element; k += word)
        for (std::size_t b = 0; b < word; ++b)  // little-endian whatever the host
          a.bytes.push_back(
              static_cast<char>(std::endian::native == std::endian::little ? e[k + b] : e[k + word - 1 - b]));
    }
    arrays.push_back(std::move(a));
  }
  return arrays;
}

std::string data_array_xml(const VtkArray& a, std::uint64_t offset, const char* indent) {
  return std::string(indent) + "<DataArray type=\"" + a.type + "\" Name=\"" + a.name +
         "\" NumberOfComponents=\"" + std::to_string(a.components) + "\" format=\"appended\" offset=\"" +
         std::to_string(offset) + "\"/>\n";
}

// UnstructuredGrid of VTK_VERTEX cells with raw appended data: each block is a UInt64 byte count
// followed by the bytes, offsets counted from the byte after the '_' marker.
std::string vtu_file(const HostParticles& p, const std::vector<std::size_t>& order, double time,
                     const std::vector<float>& temperature) {
  const std::size_t n = order.size();
  const std::vector<VtkArray> point_arrays = point_data(p, order, temperature);

  VtkArray points{"position", "Float32", 3, {}};
  points.bytes.reserve(12 * n);
  for (std::size_t i : order) {
    for (int c = 0; c < 3; ++c) put_little_endian(points.bytes, p.position[i][c]);
  }
  constexpr std::uint8_t kVtkVertex = 1;
  VtkArray connectivity{"connectivity", "Int64", 1, {}}, offsets{"offsets", "Int64", 1, {}};
  VtkArray types{"types", "UInt8", 1, std::string(n, static_cast<char>(kVtkVertex))};
  connectivity.bytes.reserve(8 * n);
  offsets.bytes.reserve(8 * n);
  for (std::size_t k = 0; k < n; ++k) {
    put_little_endian(connectivity.bytes, static_cast<std::int64_t>(k));
    put_little_endian(offsets.bytes, static_cast<std::int64_t>(k + 1));
  }

  std::vector<const VtkArray*> blocks;
  std::uint64_t offset = 0;
  auto place = [&](const VtkArray& a, const char* indent) {
    std::string xml = data_array_xml(a, offset, indent);
    offset += 8 + a.bytes.size();
    blocks.push_back(&a);
    return xml;
  };

  const std::string count = std::to_string(n);
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <UnstructuredGrid>\n"
      "    <FieldData>\n"
      "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">" +
      exact(time) +
      "</DataArray>\n"
      "    </FieldData>\n"
      "    <Piece NumberOfPoints=\"" +
      count + "\" NumberOfCells=\"" + count +
      "\">\n"
      "      <PointData Scalars=\"phase\" Vectors=\"velocity\">\n";
  for (const VtkArray& a : point_arrays) xml += place(a, "        ");
  xml += "      </PointData>\n      <Points>\n";
  xml += place(points, "        ");
  xml += "      </Points>\n      <Cells>\n";
  xml += place(connectivity, "        ");
  xml += place(offsets, "        ");
  xml += place(types, "        ");
  xml +=
      "      </Cells>\n"
      "    </Piece>\n"
      "  </UnstructuredGrid>\n"
      "  <AppendedData encoding=\"raw\">\n"
      "   _";
  xml.reserve(xml.size() + offset + 64);
  for (const VtkArray* a : blocks) {
    put_little_endian(xml, static_cast<std::uint64_t>(a->bytes.size()));
    xml += a->bytes;
  }
  xml +=
      "\n"
      "  </AppendedData>\n"
      "</VTKFile>\n";
  return xml;
}

// Vertex record, 32 bytes: x y z vx vy vz density (float), phase red green blue (uchar); 36 with a
// float temperature after density.
std::string ply_file(const HostParticles& p, const std::vector<std::size_t>& order, double time,
                     const std::vector<float>& temperature) {
  const bool with_t = !temperature.empty();
  std::string out =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "comment thaw particles, time " +
      exact(time) +
      " s, ordered by particle id\n"
      "element vertex " +
      std::to_string(order.size()) +
      "\n"
      "property float x\n"
      "property float y\n"
      "property float z\n"
      "property float vx\n"
      "property float vy\n"
      "property float vz\n"
      "property float density\n" +
      std::string(with_t ? "property float temperature\n" : "") +
      "property uchar phase\n"
      "property uchar red\n"
      "property uchar green\n"
      "property uchar blue\n"
      "end_header\n";
  out.reserve(out.size() + 32 * order.size());
  for (std::size_t i : order) {
    for (int c = 0; c < 3; ++c) put_little_endian(out, p.position[i][c]);
    for (int c = 0; c < 3; ++c) put_little_endian(out, p.velocity[i][c]);
    put_little_endian(out, p.density[i]);
    if (with_t) put_little_endian(out, temperature[i]);
    put_little_endian(out, p.phase[i]);
    for (std::uint8_t c : phase_colour(p.phase[i])) put_little_endian(out, c);
  }
  return out;
}

std::string pvd_file(const std::vector<double>& times) {
  std::string out =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (std::size_t k = 0; k < times.size(); ++k) {
    out += "    <DataSet timestep=\"" + exact(times[k]) + "\" group=\"\" part=\"0\" file=\"" +
           frame_name(k, "vtu") + "\"/>\n";
  }
  out +=
      "  </Collection>\n"
      "</VTKFile>\n";
  return out;
}

}  // namespace

ParticleExporter::ParticleExporter(std::string dir) : dir_(std::move(dir)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw Error("cannot create export directory '" + dir_ + "': " + ec.message());
  if (!std::filesystem::is_directory(dir_, ec)) {
    throw Error("cannot create export directory '" + dir_ + "': exists and is not a directory");
  }
}

void ParticleExporter::write(const HostParticles& p, double time, const std::vector<float>& temperature) {
  check_sizes(p, dir_);
  if (!temperature.empty() && temperature.size() != p.size())
    throw Error("export to '" + dir_ + "': " + std::to_string(temperature.size()) + " temperatures for " +
                std::to_string(p.size()) + " particles");
  const std::vector<std::size_t> order = id_order(p);
  const std::filesystem::path dir(dir_);
  const std::size_t frame = times_.size();
  // Exports need not survive a power cut, only never be seen half-written: rename without fsync.
  write_file_atomically((dir / frame_name(frame, "vtu")).string(), vtu_file(p, order, time, temperature),
                        Durability::Visible);
  write_file_atomically((dir / frame_name(frame, "ply")).string(), ply_file(p, order, time, temperature),
                        Durability::Visible);
  // The collection goes last so it never lists a frame whose files are not complete.
  std::vector<double> times = times_;
  times.push_back(time);
  write_file_atomically((dir / "particles.pvd").string(), pvd_file(times), Durability::Visible);
  times_ = std::move(times);
}

}  // namespace thaw
