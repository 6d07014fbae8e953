#include "render/marching_cubes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <sstream>

#include "render/mesh_export.h"
#include "sim/error.h"
#include "tests/render/lattice_snapshot.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

constexpr float kSpacing = 0.01f;
const Eigen::Vector3f kCentre(-0.05f, 0.12f, 0.2f);

void add_sphere(RenderSnapshot& s, float radius, Phase phase) {
  testing::add_lattice_sphere(s, kCentre, kSpacing, radius, phase);
}
void add_box(RenderSnapshot& s, const Eigen::Vector3f& corner, int nx, int ny, int nz, Phase phase) {
  testing::add_lattice_box(s, corner, kSpacing, nx, ny, nz, phase);
}

RenderSnapshot snapshot() {
  RenderSnapshot s;
  s.spacing = kSpacing;
  return s;
}

// A field sampled from f(x) on a grid of n^3 nodes over [-1, 1]^3.
template <typename F>
std::pair<FieldGrid, std::vector<float>> analytic(int n, F f) {
  FieldGrid g;
  g.nx = g.ny = g.nz = n;
  g.cell = 2.0f / float(n - 1);
  g.origin = Eigen::Vector3f::Constant(-1);
  std::vector<float> v(g.size());
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        v[g.index(i, j, k)] = f(g.origin + g.cell * Eigen::Vector3f(float(i), float(j), float(k)));
  return {g, v};
}

// Share of vertices whose normal points away from `centre`.
double outward_share(const Mesh& m, const Eigen::Vector3f& centre) {
  std::size_t out = 0;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) out += m.normals[v].dot(m.vertices[v] - centre) > 0;
  return double(out) / double(m.vertices.size());
}

// Share of the surface area whose winding (counter-clockwise from outside) agrees with the vertex
// normals. By area, because marching tetrahedra makes slivers whose winding rounding can turn.
double winding_share(const Mesh& m) {
  double agree = 0, total = 0;
  for (const Eigen::Vector3i& t : m.triangles) {
    const Eigen::Vector3f n =
        (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    total += n.norm();
    if (n.dot(m.normals[t[0]] + m.normals[t[1]] + m.normals[t[2]]) > 0) agree += n.norm();
  }
  return agree / total;
}

TEST(MarchingCubes, AnalyticSphereIsClosedWithItsVolume) {
  const float r = 0.6f;
  const auto [g, v] = analytic(41, [&](const Eigen::Vector3f& x) { return r - x.norm(); });
  const Mesh m = extract_isosurface(g, v, 0.0f);
  ASSERT_FALSE(m.triangles.empty());
  EXPECT_TRUE(mesh_is_closed(m));
  EXPECT_EQ(m.normals.size(), m.vertices.size());
  const double exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  EXPECT_NEAR(mesh_volume(m), exact, 0.01 * exact);
  EXPECT_EQ(outward_share(m, Eigen::Vector3f::Zero()), 1.0);
  EXPECT_GT(winding_share(m), 0.999);
  for (const Eigen::Vector3f& x : m.vertices) EXPECT_NEAR(x.norm(), r, 0.01f);
}

TEST(MarchingCubes, TorusAndTouchingCornersStayClosed) {
  // A torus (genus 1) and a field that is inside on a checkerboard of nodes: the worst case for
  // ambiguous faces, which tetrahedra do not have.
  const auto [g, v] = analytic(33, [](const Eigen::Vector3f& x) {
    const float q = std::hypot(x.x(), x.y()) - 0.55f;
    return 0.25f - std::hypot(q, x.z());
  });
  const Mesh torus = extract_isosurface(g, v, 0.0f);
  EXPECT_TRUE(mesh_is_closed(torus));
  // Euler characteristic V - E + F = 0 for a torus; E = 3F/2 on a closed triangle mesh.
  EXPECT_EQ(2 * std::int64_t(torus.vertices.size()) - std::int64_t(torus.triangles.size()), 0);

  FieldGrid cg;
  cg.nx = cg.ny = cg.nz = 8;
  cg.cell = 1;
  std::vector<float> checker(cg.size(), 0.0f);
  for (int k = 1; k < 7; ++k)
    for (int j = 1; j < 7; ++j)
      for (int i = 1; i < 7; ++i) checker[cg.index(i, j, k)] = float((i + j + k) % 2);
  const Mesh m = extract_isosurface(cg, checker, 0.5f);
  EXPECT_FALSE(m.triangles.empty());
  EXPECT_TRUE(mesh_is_closed(m));
}

TEST(MarchingCubes, ParticleSphereMeshIsClosedOutwardWithItsVolume) {
  const float R = 10;
  RenderSnapshot s = snapshot();
  add_sphere(s, R, Phase::Ice);
  const DensityFields f = build_density_fields(s, {});
  const Mesh m = extract_isosurface(f.grid, f.ice, f.iso);
  ASSERT_FALSE(m.triangles.empty());
  EXPECT_TRUE(mesh_is_closed(m));
  EXPECT_GT(outward_share(m, kCentre), 0.999);
  EXPECT_GT(winding_share(m), 0.999);
  const double exact = 4.0 / 3.0 * std::numbers::pi * std::pow(R * kSpacing, 3);
  const double volume = mesh_volume(m);
  EXPECT_NEAR(volume, exact, 0.05 * exact);
  std::printf("[ info ] particle sphere R = %g spacings: mesh volume %+.2f %% of 4/3 pi R^3, %zu triangles\n",
              R, 100 * (volume / exact - 1), m.triangles.size());
  EXPECT_TRUE(extract_isosurface(f.grid, f.water, f.iso).triangles.empty());
}

TEST(MarchingCubes, ParticleBoxMeshHasItsVolume) {
  RenderSnapshot s = snapshot();
  add_box(s, Eigen::Vector3f(0.3f, -0.1f, 0.05f), 20, 10, 15, Phase::Water);
  const DensityFields f = build_density_fields(s, {});
  const Mesh m = extract_isosurface(f.grid, f.water, f.iso);
  EXPECT_TRUE(mesh_is_closed(m));
  const double exact = 20.0 * 10.0 * 15.0 * std::pow(double(kSpacing), 3);
  const double volume = mesh_volume(m);
  EXPECT_NEAR(volume, exact, 0.05 * exact);
  std::printf("[ info ] particle box 20x10x15 spacings: mesh volume %+.2f %% of the box\n",
              100 * (volume / exact - 1));
  EXPECT_TRUE(extract_isosurface(f.grid, f.ice, f.iso).triangles.empty());
}

TEST(MarchingCubes, ClosedCheckSeesHolesAndFlips) {
  const auto [g, v] = analytic(17, [](const Eigen::Vector3f& x) { return 0.5f - x.norm(); });
  Mesh m = extract_isosurface(g, v, 0.0f);
  ASSERT_TRUE(mesh_is_closed(m));
  Mesh flipped = m;
  std::swap(flipped.triangles[7][0], flipped.triangles[7][1]);
  EXPECT_FALSE(mesh_is_closed(flipped));
  m.triangles.pop_back();
  EXPECT_FALSE(mesh_is_closed(m));
  EXPECT_TRUE(mesh_is_closed(Mesh{}));
  EXPECT_EQ(mesh_volume(Mesh{}), 0.0);
}

TEST(MarchingCubes, WritersHeadersMatchContents) {
  const auto [g, v] = analytic(9, [](const Eigen::Vector3f& x) { return 0.7f - x.norm(); });
  const Mesh m = extract_isosurface(g, v, 0.0f);
  ASSERT_FALSE(m.triangles.empty());

  const std::string obj = mesh_obj(m, "ice");
  std::istringstream lines(obj);
  std::string line;
  std::size_t nv = 0, nn = 0, nf = 0;
  bool named = false;
  while (std::getline(lines, line)) {
    nv += line.rfind("v ", 0) == 0;
    nn += line.rfind("vn ", 0) == 0;
    nf += line.rfind("f ", 0) == 0;
    named = named || line == "o ice";
  }
  EXPECT_TRUE(named);
  EXPECT_EQ(nv, m.vertices.size());
  EXPECT_EQ(nn, m.vertices.size());
  EXPECT_EQ(nf, m.triangles.size());
  EXPECT_NE(obj.find("# thaw iso-surface: " + std::to_string(nv) + " vertices, " + std::to_string(nf) +
                     " triangles"),
            std::string::npos);

  const std::string ply = mesh_ply(m);
  const std::size_t end = ply.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = ply.substr(0, end);
  EXPECT_EQ(ply.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(header.find("element vertex " + std::to_string(m.vertices.size()) + "\n"), std::string::npos);
  EXPECT_NE(header.find("element face " + std::to_string(m.triangles.size()) + "\n"), std::string::npos);
  EXPECT_NE(header.find("property list uchar int vertex_indices\n"), std::string::npos);
  const std::size_t body = end + std::strlen("end_header\n");
  ASSERT_EQ(ply.size() - body, 24 * m.vertices.size() + 13 * m.triangles.size());
  float x0;
  std::memcpy(&x0, ply.data() + body, 4);
  EXPECT_EQ(x0, m.vertices[0].x());
  std::int32_t last;
  std::memcpy(&last, ply.data() + ply.size() - 4, 4);
  EXPECT_EQ(last, m.triangles.back()[2]);
}

TEST(MeshExport, WritesIceAndWaterPerFrame) {
  testing::TempDir dir("mesh-export");
  const std::string out = dir / "meshes";
  for (const char* format : {"obj", "ply"}) {
    MeshExporter e(out + "/" + format, format);
    RenderSnapshot both = snapshot();
    add_sphere(both, 5, Phase::Ice);
    add_box(both, kCentre + Eigen::Vector3f(0.1f, 0, 0), 8, 6, 5, Phase::Water);
    e.write(both);
    RenderSnapshot water = snapshot();
    add_box(water, kCentre, 8, 6, 5, Phase::Water);
    e.write(water);
    EXPECT_EQ(e.frames(), 2u);
    const std::filesystem::path d(out + "/" + format);
    const std::string ext = std::string(".") + format;
    EXPECT_TRUE(std::filesystem::is_regular_file(d / ("ice_000000" + ext)));
    EXPECT_TRUE(std::filesystem::is_regular_file(d / ("water_000000" + ext)));
    EXPECT_FALSE(std::filesystem::exists(d / ("ice_000001" + ext)));
    EXPECT_TRUE(std::filesystem::is_regular_file(d / ("water_000001" + ext)));
    const std::string bytes = testing::read_file_bytes(d / ("water_000001" + ext));
    EXPECT_EQ(bytes.rfind(std::string(format) == "obj" ? "# thaw iso-surface" : "ply\n", 0), 0u);
    std::size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(d)) files += entry.is_regular_file();
    EXPECT_EQ(files, 3u);  // no temporary files left behind
  }
}

TEST(MeshExport, RefusesBadFormatAndDirectory) {
  testing::TempDir dir("mesh-export-bad");
  try {
    MeshExporter e(dir / "x", "stl");
    FAIL() << "accepted format stl";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'stl'"), std::string::npos) << e.what();
  }
  testing::write_text(dir.path() / "file", "not a directory");
  const std::string blocked = dir / "file/meshes";
  try {
    MeshExporter e(blocked, "obj");
    FAIL() << "created a directory under a file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(blocked), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace thaw
