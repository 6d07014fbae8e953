#include "sim/particle_export.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "sim/error.h"

namespace thaw {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::uint64_t load_u64(const std::string& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t{static_cast<unsigned char>(b[at + i])} << (8 * i);
  return v;
}

std::uint32_t load_u32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t{static_cast<unsigned char>(b[at + i])} << (8 * i);
  return v;
}

float load_f32(const std::string& b, std::size_t at) { return std::bit_cast<float>(load_u32(b, at)); }

// Particles in a scrambled (device-sorted) order; position x and velocity y encode the id so tests
// can see the order the files use.
HostParticles scrambled_particles() {
  const std::uint32_t ids[] = {3, 0, 4, 1, 2};
  HostParticles p;
  p.resize(5);
  for (std::size_t i = 0; i < 5; ++i) {
    const float id = static_cast<float>(ids[i]);
    p.position[i] = {0.1f * id, 1.0f, 2.0f, 0.001f * (id + 1)};
    p.velocity[i] = {3.0f, -id, 4.0f, 0.0f};
    p.density[i] = 1000.0f + id;
    p.phase[i] = static_cast<std::uint8_t>(ids[i] % kPhaseCount);
    p.material[i] = static_cast<std::uint8_t>(ids[i] + 10);
    p.id[i] = ids[i];
  }
  return p;
}

std::size_t vtk_type_size(const std::string& type) {
  if (type == "Float32" || type == "UInt32" || type == "Int32") return 4;
  if (type == "Int64" || type == "UInt64" || type == "Float64") return 8;
  if (type == "UInt8") return 1;
  ADD_FAILURE() << "unexpected VTK type " << type;
  return 0;
}

struct AppendedArray {
  std::string type;
  int components;
  std::uint64_t offset;
};

class ParticleExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("thaw_export_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

TEST_F(ParticleExportTest, CreatesDirectoryAndFrames) {
  const fs::path out = dir_ / "nested" / "export";
  ParticleExporter exporter(out.string());
  EXPECT_TRUE(fs::is_directory(out));
  EXPECT_EQ(exporter.frames(), 0u);
  const HostParticles p = scrambled_particles();
  exporter.write(p, 0.0);
  exporter.write(p, 0.25);
  EXPECT_EQ(exporter.frames(), 2u);

  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(out)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  // No temp files left behind.
  EXPECT_EQ(names, (std::vector<std::string>{"frame_000000.ply", "frame_000000.vtu", "frame_000001.ply",
                                             "frame_000001.vtu", "particles.pvd"}));
}

TEST_F(ParticleExportTest, VtuHeaderAndAppendedBlocksMatchTheParticleCount) {
  ParticleExporter exporter(dir_.string());
  const HostParticles p = scrambled_particles();
  const std::size_t n = p.size();
  exporter.write(p, 1.5);
  const std::string vtu = read_bytes(dir_ / "frame_000000.vtu");

  const std::size_t marker = vtu.find("<AppendedData encoding=\"raw\">");
  ASSERT_NE(marker, std::string::npos);
  const std::string xml = vtu.substr(0, marker);
  EXPECT_EQ(xml.rfind("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\"", 0), 0u);
  EXPECT_NE(xml.find("header_type=\"UInt64\""), std::string::npos);
  EXPECT_NE(xml.find("byte_order=\"LittleEndian\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPoints=\"5\" NumberOfCells=\"5\""), std::string::npos);
  EXPECT_NE(xml.find(">1.5</DataArray>"), std::string::npos);  // TimeValue

  const std::regex array_re(
      "<DataArray type=\"(\\w+)\" Name=\"(\\w+)\" NumberOfComponents=\"(\\d+)\" format=\"appended\" "
      "offset=\"(\\d+)\"/>");
  std::map<std::string, AppendedArray> arrays;
  std::vector<std::uint64_t> offsets;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), array_re); it != std::sregex_iterator(); ++it) {
    const auto& m = *it;
    arrays[m[2]] = {m[1], std::stoi(m[3]), std::stoull(m[4])};
    offsets.push_back(std::stoull(m[4]));
  }
  for (const char* name : {"velocity", "speed", "phase", "material", "density", "mass", "id", "position",
                           "connectivity", "offsets", "types"}) {
    EXPECT_TRUE(arrays.count(name)) << name;
  }
  EXPECT_EQ(arrays["velocity"].components, 3);
  EXPECT_EQ(arrays["position"].components, 3);
  EXPECT_EQ(arrays["phase"].type, "UInt8");
  EXPECT_EQ(arrays["id"].type, "UInt32");

  const std::size_t base = vtu.find('_', marker) + 1;
  std::uint64_t expected_offset = 0;
  for (std::uint64_t offset : offsets) {
    // Blocks follow one another in the order the XML declares them.
    EXPECT_EQ(offset, expected_offset);
    const auto it =
        std::find_if(arrays.begin(), arrays.end(), [&](auto& a) { return a.second.offset == offset; });
    const AppendedArray& a = it->second;
    const std::uint64_t bytes = load_u64(vtu, base + offset);
    EXPECT_EQ(bytes, n * static_cast<std::size_t>(a.components) * vtk_type_size(a.type)) << it->first;
    expected_offset = offset + 8 + bytes;
  }
  EXPECT_EQ(vtu.substr(base + expected_offset), "\n  </AppendedData>\n</VTKFile>\n");

  // Point data is in id order: id 0..4, position x = 0.1 id, velocity y = -id, mass = 0.001 (id + 1).
  const std::size_t ids = base + arrays["id"].offset + 8;
  const std::size_t xs = base + arrays["position"].offset + 8;
  const std::size_t vs = base + arrays["velocity"].offset + 8;
  const std::size_t ms = base + arrays["mass"].offset + 8;
  const std::size_t ss = base + arrays["speed"].offset + 8;
  for (std::size_t k = 0; k < n; ++k) {
    const float id = static_cast<float>(k);
    EXPECT_EQ(load_u32(vtu, ids + 4 * k), k);
    EXPECT_EQ(load_f32(vtu, xs + 12 * k), 0.1f * id);
    EXPECT_EQ(load_f32(vtu, vs + 12 * k + 4), -id);
    EXPECT_EQ(load_f32(vtu, ms + 4 * k), 0.001f * (id + 1));
    EXPECT_FLOAT_EQ(load_f32(vtu, ss + 4 * k), std::sqrt(25.0f + id * id));
  }
  const std::size_t types = base + arrays["types"].offset + 8;
  for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(vtu[types + k], 1) << "VTK_VERTEX";
}

TEST_F(ParticleExportTest, PvdListsFramesInOrderWithTimes) {
  ParticleExporter exporter(dir_.string());
  const HostParticles p = scrambled_particles();
  const double times[] = {0.0, 0.001, 0.1 + 0.2, 2.5};
  for (double t : times) exporter.write(p, t);
  const std::string pvd = read_bytes(dir_ / "particles.pvd");
  EXPECT_EQ(pvd.rfind("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\"", 0), 0u);
  const std::regex dataset_re("<DataSet timestep=\"([^\"]+)\" group=\"\" part=\"0\" file=\"([^\"]+)\"/>");
  std::size_t k = 0;
  for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), dataset_re); it != std::sregex_iterator();
       ++it, ++k) {
    ASSERT_LT(k, 4u);
    EXPECT_EQ(std::stod((*it)[1]), times[k]);  // exactly: the times are written round-trip exact
    EXPECT_EQ((*it)[2], "frame_00000" + std::to_string(k) + ".vtu");
    EXPECT_TRUE(fs::exists(dir_ / (*it)[2].str()));
  }
  EXPECT_EQ(k, 4u);
  EXPECT_NE(pvd.find("</Collection>\n</VTKFile>\n"), std::string::npos);
}

TEST_F(ParticleExportTest, PlyIsWellFormedAndInIdOrder) {
  ParticleExporter exporter(dir_.string());
  const HostParticles p = scrambled_particles();
  exporter.write(p, 0.5);
  const std::string ply = read_bytes(dir_ / "frame_000000.ply");

  const std::string end = "end_header\n";
  const std::size_t header_end = ply.find(end);
  ASSERT_NE(header_end, std::string::npos);
  const std::size_t header_size = header_end + end.size();
  std::istringstream header(ply.substr(0, header_end));
  std::vector<std::string> lines;
  for (std::string line; std::getline(header, line);) {
    if (line.rfind("comment ", 0) != 0) lines.push_back(line);
  }
  EXPECT_EQ(lines, (std::vector<std::string>{
                       "ply", "format binary_little_endian 1.0", "element vertex 5", "property float x",
                       "property float y", "property float z", "property float vx", "property float vy",
                       "property float vz", "property float density", "property uchar phase",
                       "property uchar red", "property uchar green", "property uchar blue"}));
  constexpr std::size_t kRecord = 7 * 4 + 4;
  ASSERT_EQ(ply.size(), header_size + p.size() * kRecord);

  const std::uint8_t water_blue[] = {40, 110, 230};
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::size_t r = header_size + k * kRecord;
    const float id = static_cast<float>(k);
    EXPECT_EQ(load_f32(ply, r), 0.1f * id) << "records in id order";
    EXPECT_EQ(load_f32(ply, r + 16), -id);
    EXPECT_EQ(load_f32(ply, r + 24), 1000.0f + id);
    EXPECT_EQ(static_cast<std::uint8_t>(ply[r + 28]), k % kPhaseCount);
    if (k % kPhaseCount == 0) {
      EXPECT_EQ(std::memcmp(ply.data() + r + 29, water_blue, 3), 0);
    }
  }
}

TEST_F(ParticleExportTest, EmptyParticleSetGivesValidFiles) {
  ParticleExporter exporter(dir_.string());
  exporter.write(HostParticles{}, 0.0);
  const std::string ply = read_bytes(dir_ / "frame_000000.ply");
  EXPECT_NE(ply.find("element vertex 0\n"), std::string::npos);
  EXPECT_EQ(ply.substr(ply.size() - 11), "end_header\n");
  EXPECT_NE(read_bytes(dir_ / "frame_000000.vtu").find("NumberOfPoints=\"0\""), std::string::npos);
}

TEST_F(ParticleExportTest, DirectoryThatIsAFileIsAnError) {
  fs::create_directories(dir_);
  const fs::path file = dir_ / "plain_file";
  std::ofstream(file) << "x";
  try {
    ParticleExporter exporter(file.string());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
}

TEST_F(ParticleExportTest, InconsistentArraysAreRefused) {
  ParticleExporter exporter(dir_.string());
  HostParticles p = scrambled_particles();
  p.density.pop_back();
  EXPECT_THROW(exporter.write(p, 0.0), Error);
  EXPECT_EQ(exporter.frames(), 0u);
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
}  // namespace thaw
