// Meshes, the winding-number inside test, primitive shapes and their sampling on the particle lattice.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "sim/error.h"
#include "sim/geometry/mesh.h"
#include "sim/geometry/shape.h"
#include "sim/geometry/voxelize.h"
#include "sim/geometry/winding_number.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

namespace fs = std::filesystem;
using Vec3 = Eigen::Vector3d;
using testing::TempDir;
using testing::write_text;

const std::string kBunny = (fs::path(THAW_SOURCE_DIR) / "configs" / "meshes" / "bunny.obj").string();

// Every test that samples the bunny uses this size and spacing: about 100,000 lattice points in its box.
constexpr double kBunnySize = 0.06;       // [m]
constexpr double kBunnySpacing = 1.2e-3;  // [m]

const TriangleSoup& bunny() {
  static const TriangleSoup mesh = load_mesh(kBunny);
  return mesh;
}

// The bunny standing up (its y is up) at 6 cm, centred at the origin.
TriangleSoup placed_bunny() {
  return place_mesh(bunny(), rotation_from_degrees({90, 0, 0}), Vec3::Zero(), kBunnySize);
}

double sampled_volume(const Shape& shape, double spacing) {
  return double(voxelize(shape, spacing).size()) * spacing * spacing * spacing;
}

std::string error_of(const std::string& file) {
  try {
    load_mesh(file);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " loaded without error";
  return "";
}

// A unit cube [0, 1]^3 as OBJ text, triangles facing out.
std::string cube_obj() {
  return "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
         "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
         "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
}

// ---- mesh files --------------------------------------------------------------------------------------

TEST(MeshFile, TheBunnyIsClosedAndFacesOut) {
  EXPECT_EQ(bunny().size(), 3674u);
  // Each edge of a closed, consistently oriented mesh is run once in each direction.
  std::map<std::pair<std::array<double, 3>, std::array<double, 3>>, int> directed;
  auto key = [](const Vec3& v) { return std::array<double, 3>{v.x(), v.y(), v.z()}; };
  for (const Triangle& t : bunny()) {
    ++directed[{key(t.a), key(t.b)}];
    ++directed[{key(t.b), key(t.c)}];
    ++directed[{key(t.c), key(t.a)}];
  }
  for (const auto& [edge, count] : directed) {
    ASSERT_EQ(count, 1);
    ASSERT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
  EXPECT_GT(signed_volume(bunny()), 0.0);
}

TEST(MeshFile, ReadsObjStlAndPly) {
  TempDir dir("mesh-formats");
  write_text(dir / "cube.obj", cube_obj());
  write_text(dir / "tetra.stl",
             "solid t\n"
             "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
             "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
             "facet normal -1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
             "facet normal 1 1 1\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\n"
             "endsolid t\n");
  write_text(dir / "quads.ply",
             "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 6\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
             "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
  const TriangleSoup cube = load_mesh(dir / "cube.obj");
  EXPECT_EQ(cube.size(), 12u);
  EXPECT_NEAR(signed_volume(cube), 1.0, 1e-12);
  const TriangleSoup tetra = load_mesh(dir / "tetra.stl");
  EXPECT_EQ(tetra.size(), 4u);
  EXPECT_NEAR(signed_volume(tetra), 1.0 / 6.0, 1e-6);
  const TriangleSoup quads = load_mesh(dir / "quads.ply");
  EXPECT_EQ(quads.size(), 12u);  // each quad in two triangles
  EXPECT_NEAR(signed_volume(quads), 1.0, 1e-6);
}

TEST(MeshFile, MissingFileIsAnErrorNamingIt) {
  TempDir dir("mesh-missing");
  const std::string file = dir / "nowhere.obj";
  const std::string e = error_of(file);
  EXPECT_NE(e.find(file), std::string::npos) << e;
  EXPECT_NE(e.find("not found"), std::string::npos) << e;
}

TEST(MeshFile, BrokenFilesAreErrorsNamingThem) {
  TempDir dir("mesh-broken");
  // A binary STL that announces 1000 triangles and holds one.
  std::string stl(80, ' ');
  const std::uint32_t count = 1000;
  stl.append(reinterpret_cast<const char*>(&count), 4);
  stl.append(50, '\0');
  write_text(dir / "short.stl", stl);
  write_text(dir / "garbage.ply", "ply\nformat ascii 1.0\nelement vertex banana\nend_header\n1 2\n");
  write_text(dir / "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  write_text(dir / "bad-index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  write_text(dir / "empty.stl", "");
  write_text(dir / "no-number.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n");
  // A face announced but not there, and binary faces that index past the vertices.
  const std::string ply_header =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  write_text(dir / "no-face.ply", "ply\nformat ascii 1.0\n" + ply_header + "0 0 0\n1 0 0\n0 1 0\n");
  write_text(dir / "zero-faces.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
  write_text(dir / "bad-index.ply",
             "ply\nformat binary_little_endian 1.0\n" + ply_header + std::string(40, '\x01'));
  write_text(dir / "cube.fbx", cube_obj());
  for (const std::string name :
       {"short.stl", "garbage.ply", "points.obj", "bad-index.obj", "empty.stl", "no-number.stl",
        "no-face.ply", "zero-faces.ply", "bad-index.ply", "cube.fbx"}) {
    SCOPED_TRACE(name);
    const std::string e = error_of(dir / name);
    EXPECT_EQ(e.rfind(dir / name + ": ", 0), 0u) << e;  // the message starts with the file
  }
  EXPECT_NE(error_of(dir / "zero-faces.ply").find("no faces"), std::string::npos);
  // A face announced but not there: refused before Assimp reads it.
  EXPECT_NE(error_of(dir / "no-face.ply").find("truncated: the PLY header declares 3 vertex, 1 face"),
            std::string::npos)
      << error_of(dir / "no-face.ply");
  EXPECT_NE(error_of(dir / "cube.fbx").find("use an OBJ, STL or PLY file"), std::string::npos);
}

TEST(MeshFile, EveryCutOfAPlyFileIsReadOrRefusedAndNeverHangs) {
  // A 21-byte "ply\nformat ascii 1.0\n" kept Assimp's PLY reader at 99 % CPU forever. Every prefix of a
  // valid ASCII and a valid binary PLY file must now load or be refused, each naming the file.
  TempDir dir("mesh-ply-cuts");
  const std::string header =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string ascii =
      "ply\nformat ascii 1.0\n" + header + "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  std::string binary = "ply\nformat binary_little_endian 1.0\n" + header;
  const float v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  binary.append(reinterpret_cast<const char*>(v), sizeof v);
  const std::int32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& f : faces) {
    binary.push_back('\x03');
    binary.append(reinterpret_cast<const char*>(f), sizeof f);
  }
  int refused = 0, loaded = 0;
  for (const std::string* whole : std::initializer_list<const std::string*>{&ascii, &binary}) {
    for (std::size_t n = 0; n <= whole->size(); ++n) {
      const std::string file = dir / ("cut.ply");
      write_text(file, whole->substr(0, n));
      try {
        const TriangleSoup mesh = load_mesh(file);
        EXPECT_EQ(mesh.size(), 4u) << n << " bytes";
        ++loaded;
      } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()).rfind(file + ": ", 0), 0u) << e.what();
        ++refused;
      }
    }
  }
  EXPECT_GE(loaded, 2);  // at least the whole files
  EXPECT_GT(refused, 300);
  // The reported file itself.
  write_text(dir / "21.ply", "ply\nformat ascii 1.0\n");
  EXPECT_NE(error_of(dir / "21.ply").find("no end_header"), std::string::npos) << error_of(dir / "21.ply");
}

TEST(MeshFile, UnreadableFileIsAnError) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files whatever their permissions";
  TempDir dir("mesh-unreadable");
  write_text(dir / "locked.obj", cube_obj());
  fs::permissions(dir / "locked.obj", fs::perms::none);
  EXPECT_NE(error_of(dir / "locked.obj").find("cannot open"), std::string::npos);
}

// ---- placement ---------------------------------------------------------------------------------------

TEST(MeshPlacement, CentreSizeAndRotation) {
  const Eigen::AlignedBox3d raw = bounding_box(bunny());
  const TriangleSoup placed =
      place_mesh(bunny(), rotation_from_degrees({90, 0, 0}), Vec3(0.1, 0.2, 0.3), kBunnySize);
  const Eigen::AlignedBox3d box = bounding_box(placed);
  EXPECT_LT((box.center() - Vec3(0.1, 0.2, 0.3)).norm(), 1e-12);
  EXPECT_NEAR(box.sizes().maxCoeff(), kBunnySize, 1e-12);
  // 90 degrees about x turns y (the bunny's up) into z, and z into -y.
  const double scale = kBunnySize / raw.sizes().maxCoeff();
  EXPECT_NEAR(box.sizes().z(), scale * raw.sizes().y(), 1e-12);
  EXPECT_NEAR(box.sizes().y(), scale * raw.sizes().z(), 1e-12);
  EXPECT_NEAR(signed_volume(placed), std::pow(scale, 3) * signed_volume(bunny()), 1e-15);
}

TEST(MeshPlacement, RotationOrderIsXThenYThenZ) {
  const Eigen::Matrix3d r = rotation_from_degrees({90, 90, 0});
  // x first takes y to z; then y takes z to x.
  EXPECT_LT((r * Vec3::UnitY() - Vec3::UnitX()).norm(), 1e-12);
  EXPECT_TRUE(rotation_from_degrees({0, 0, 0}).isIdentity(0.0));
}

// ---- winding number ----------------------------------------------------------------------------------

TEST(WindingNumber, OneInsideZeroOutsideAClosedMesh) {
  TempDir dir("winding-cube");
  write_text(dir / "cube.obj", cube_obj());
  const TriangleSoup cube = load_mesh(dir / "cube.obj");
  EXPECT_NEAR(winding_number(cube, Vec3(0.5, 0.5, 0.5)), 1.0, 1e-12);
  EXPECT_NEAR(winding_number(cube, Vec3(0.01, 0.98, 0.5)), 1.0, 1e-12);
  EXPECT_NEAR(winding_number(cube, Vec3(1.01, 0.5, 0.5)), 0.0, 1e-12);
  EXPECT_NEAR(winding_number(cube, Vec3(3, -2, 1)), 0.0, 1e-12);
  // An open box (no lid) still tells its inside from its outside: the winding number of a point inside
  // is one minus the lid's share, here over 1/2.
  TriangleSoup no_lid;
  for (const Triangle& t : cube)
    if (t.a.z() + t.b.z() + t.c.z() < 3.0) no_lid.push_back(t);
  ASSERT_EQ(no_lid.size(), 10u);
  EXPECT_GT(winding_number(no_lid, Vec3(0.5, 0.5, 0.3)), 0.5);
  EXPECT_LT(winding_number(no_lid, Vec3(0.5, 0.5, 1.3)), 0.5);
}

TEST(WindingNumber, TheHierarchyAgreesWithTheExactSum) {
  const TriangleSoup mesh = placed_bunny();
  const WindingNumber fast(mesh);
  const Eigen::AlignedBox3d box = bounding_box(mesh);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-0.1, 1.1);  // a little beyond the box too
  double worst = 0.0, sum = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 q = box.min() + Vec3(unit(random), unit(random), unit(random)).cwiseProduct(box.sizes());
    const double error = std::abs(winding_number(mesh, q) - fast(q));
    worst = std::max(worst, error);
    sum += error;
  }
  // The far field is good to a few percent of one winding (Barill et al.'s beta = 2), far below the 1/2
  // that would change an inside test; near the surface, where w crosses 1/2, the sum is exact.
  EXPECT_LT(worst, 0.05);
  EXPECT_LT(sum / 2000, 0.01);
  // Every lattice point of the bunny at 2.5 mm is classified as the exact sum classifies it.
  const Shape shape = Shape::mesh(mesh);
  const double dx = 2.5e-3;
  std::set<std::array<double, 3>> chosen;
  for (const Vec3& p : voxelize(shape, dx)) chosen.insert({p.x(), p.y(), p.z()});
  const Eigen::Array3i cells = (shape.bounds().sizes() / dx).array().ceil().cast<int>();
  int disagreements = 0;
  for (int k = 0; k < cells.z(); ++k)
    for (int j = 0; j < cells.y(); ++j)
      for (int i = 0; i < cells.x(); ++i) {
        const Vec3 p = shape.bounds().min() + dx * Vec3(i + 0.5, j + 0.5, k + 0.5);
        disagreements += (winding_number(mesh, p) > 0.5) != (chosen.count({p.x(), p.y(), p.z()}) == 1);
      }
  EXPECT_EQ(disagreements, 0);
  EXPECT_GT(chosen.size(), 2000u);
}

TEST(WindingNumber, DoesNotDependOnTheThreadCount) {
  const Shape shape = Shape::mesh(placed_bunny());
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const std::vector<Vec3> one = voxelize(shape, 2e-3);
  omp_set_num_threads(std::max(2, threads));
  const std::vector<Vec3> many = voxelize(shape, 2e-3);
  omp_set_num_threads(threads);
  EXPECT_EQ(one, many);
}

// ---- voxelizing meshes -------------------------------------------------------------------------------

TEST(Voxelize, BunnyVolumeMatchesTheMesh) {
  const TriangleSoup mesh = placed_bunny();
  const double exact = signed_volume(mesh);
  const auto start = std::chrono::steady_clock::now();
  const Shape shape = Shape::mesh(mesh);
  const std::size_t count = voxelize(shape, kBunnySpacing).size();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const Eigen::Vector3d cells = shape.bounds().sizes() / kBunnySpacing;
  const double lattice = std::ceil(cells.x()) * std::ceil(cells.y()) * std::ceil(cells.z());
  const double sampled = double(count) * std::pow(kBunnySpacing, 3);
  std::cout << "bunny: " << mesh.size() << " triangles, " << lattice << " lattice points at "
            << kBunnySpacing * 1e3 << " mm, " << count << " inside; " << seconds << " s on "
            << omp_get_max_threads() << " threads; volume " << sampled * 1e6 << " cm^3 sampled, "
            << exact * 1e6 << " cm^3 exact (" << 100.0 * (sampled - exact) / exact << " %)\n";
  EXPECT_GT(lattice, 8e4);
  EXPECT_NEAR(sampled / exact, 1.0, 0.02);
  EXPECT_LT(seconds, 5.0);  // about 0.2 s on two cores
}

// The bunny with a patch of triangles cut out around one vertex, as OBJ text.
std::string holed_bunny_obj(int* removed) {
  std::ifstream in(kBunny);
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> faces;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      Vec3 v;
      s >> v.x() >> v.y() >> v.z();
      vertices.push_back(v);
    } else if (tag == "f") {
      std::array<int, 3> f;
      s >> f[0] >> f[1] >> f[2];
      faces.push_back(f);
    }
  }
  const Vec3 centre = vertices[100];  // on the bunny's back
  std::ostringstream out;
  for (const Vec3& v : vertices) out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  *removed = 0;
  for (const auto& f : faces) {
    const Vec3 middle = (vertices[f[0] - 1] + vertices[f[1] - 1] + vertices[f[2] - 1]) / 3.0;
    if ((middle - centre).norm() < 0.45) {
      ++*removed;
      continue;
    }
    out << "f " << f[0] << " " << f[1] << " " << f[2] << "\n";
  }
  return out.str();
}

TEST(Voxelize, BunnyWithAHoleKeepsItsVolume) {
  TempDir dir("holed-bunny");
  int removed = 0;
  write_text(dir / "holed.obj", holed_bunny_obj(&removed));
  EXPECT_GE(removed, 5);
  EXPECT_LE(removed, 40);
  const TriangleSoup holed = load_mesh(dir / "holed.obj");
  ASSERT_EQ(holed.size() + std::size_t(removed), bunny().size());
  // The same placement for both, so that the lattices coincide.
  const double scale = kBunnySize / bounding_box(bunny()).sizes().maxCoeff();
  auto scaled = [scale](TriangleSoup mesh) {
    for (Triangle& t : mesh) t = {scale * t.a, scale * t.b, scale * t.c};
    return mesh;
  };
  const double closed = sampled_volume(Shape::mesh(scaled(bunny())), kBunnySpacing);
  const double open = sampled_volume(Shape::mesh(scaled(holed)), kBunnySpacing);
  EXPECT_NEAR(open / closed, 1.0, 0.01);
  // A ray-parity test would leak through the hole; the winding number sees a nearly closed surface.
  EXPECT_NEAR(open / (std::pow(scale, 3) * signed_volume(bunny())), 1.0, 0.02);
}

// ---- primitives --------------------------------------------------------------------------------------

TEST(Voxelize, PrimitiveVolumesMatchTheirFormulas) {
  const double dx = 1e-3, r = 0.02;
  const Vec3 from(0.01, 0.02, 0.0), to(0.04, 0.05, 0.06);  // a slanted axis
  const double length = (to - from).norm();
  struct Case {
    const char* name;
    Shape shape;
    double formula;
  };
  const Case cases[] = {
      {"sphere", Shape::sphere(Vec3(0.1, 0.1, 0.1), r), 4.0 / 3.0 * M_PI * r * r * r},
      {"cylinder", Shape::cylinder(from, to, r), M_PI * r * r * length},
      {"cone", Shape::cone(from, to, r), M_PI * r * r * length / 3.0},
      {"capsule", Shape::capsule(from, to, r), M_PI * r * r * length + 4.0 / 3.0 * M_PI * r * r * r},
      {"rotated box", Shape::box(Vec3(0, 0, 0), Vec3(0.05, 0.03, 0.02), rotation_from_degrees({30, 45, 60})),
       0.05 * 0.03 * 0.02},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    EXPECT_NEAR(c.shape.volume(), c.formula, 1e-15);
    EXPECT_NEAR(sampled_volume(c.shape, dx) / c.formula, 1.0, 0.02);
  }
}

TEST(Voxelize, AxisAlignedBoxKeepsWholeCellsFromItsCorner) {
  const Shape box = Shape::box(Vec3(0.1, 0.2, 0.3), Vec3(0.117, 0.209, 0.312));
  const std::vector<Vec3> points = voxelize(box, 0.003);
  ASSERT_EQ(points.size(), std::size_t(5 * 3 * 4));  // floor(17 / 3), 9 / 3, 12 / 3
  EXPECT_LT((points.front() - Vec3(0.1015, 0.2015, 0.3015)).norm(), 1e-12);
  EXPECT_LT((points[1] - points[0] - Vec3(0.003, 0, 0)).norm(), 1e-12);  // x fastest
}

TEST(Voxelize, RotatedBoxPointsLieInTheRotatedBox) {
  const Vec3 min(0.1, 0.1, 0.1), max(0.16, 0.13, 0.11), centre = 0.5 * (min + max);
  const Eigen::Matrix3d r = rotation_from_degrees({0, 0, 30});
  const Shape box = Shape::box(min, max, r);
  const std::vector<Vec3> points = voxelize(box, 1e-3);
  ASSERT_FALSE(points.empty());
  for (const Vec3& p : points) {
    const Vec3 local = centre + r.transpose() * (p - centre);
    ASSERT_TRUE((local.array() >= min.array() - 1e-12).all() && (local.array() <= max.array() + 1e-12).all())
        << p.transpose();
  }
  // Just inside the corner (0.16, 0.1) turned 30 degrees about the centre; the unturned corner is outside.
  const Vec3 corner = centre + r * (Vec3(0.16, 0.1, 0.105) - centre);
  EXPECT_TRUE(box.contains(corner + 0.01 * (centre - corner)));
  EXPECT_FALSE(box.contains(Vec3(0.1595, 0.1005, 0.105)));
  EXPECT_NEAR(double(points.size()) * 1e-9 / (0.06 * 0.03 * 0.01), 1.0, 0.03);
}

TEST(Shape, ConeHasItsBaseAtFromAndItsApexAtTo) {
  // An icicle: base at the top, apex 10 cm below.
  const Shape icicle = Shape::cone(Vec3(0, 0, 0.2), Vec3(0, 0, 0.1), 0.01);
  EXPECT_TRUE(icicle.contains(Vec3(0.0099, 0, 0.1999)));   // the rim of the base
  EXPECT_FALSE(icicle.contains(Vec3(0.0099, 0, 0.1001)));  // as wide near the apex: outside
  EXPECT_TRUE(icicle.contains(Vec3(0, 0, 0.1001)));
  EXPECT_FALSE(icicle.contains(Vec3(0, 0, 0.0999)));  // below the apex
  EXPECT_FALSE(icicle.contains(Vec3(0, 0, 0.2001)));  // above the base
  EXPECT_NEAR(icicle.bounds().min().z(), 0.1, 1e-15);
  EXPECT_NEAR(icicle.bounds().max().x(), 0.01, 1e-15);
}

TEST(Shape, CapsuleAndCylinderEnds) {
  const Shape capsule = Shape::capsule(Vec3(0, 0, 0), Vec3(0.1, 0, 0), 0.01);
  const Shape cylinder = Shape::cylinder(Vec3(0, 0, 0), Vec3(0.1, 0, 0), 0.01);
  EXPECT_TRUE(capsule.contains(Vec3(-0.0099, 0, 0)));  // the round end
  EXPECT_FALSE(cylinder.contains(Vec3(-0.0001, 0, 0)));
  EXPECT_TRUE(cylinder.contains(Vec3(0.05, 0.0099, 0)));
  EXPECT_FALSE(cylinder.contains(Vec3(0.05, 0.0101, 0)));
  EXPECT_NEAR(capsule.bounds().min().x(), -0.01, 1e-15);
  EXPECT_NEAR(cylinder.bounds().min().x(), 0.0, 1e-15);
}

TEST(Shape, InwardFacingMeshIsTurnedOut) {
  TriangleSoup mesh = placed_bunny();
  for (Triangle& t : mesh) std::swap(t.b, t.c);
  ASSERT_LT(signed_volume(mesh), 0.0);
  const Shape shape = Shape::mesh(mesh);
  EXPECT_GT(shape.volume(), 0.0);
  EXPECT_NEAR(sampled_volume(shape, 2e-3) / shape.volume(), 1.0, 0.05);
}

TEST(Voxelize, ShellIsTheOuterLayers) {
  const double dx = 1e-3;
  const Shape sphere = Shape::sphere(Vec3::Zero(), 0.02);
  const std::vector<Vec3> shell = voxelize_shell(sphere, dx, 3);
  for (const Vec3& p : shell) ASSERT_GT(p.norm(), 0.02 - 3.5 * dx) << p.transpose();
  // Every point of the full sphere within 1.5 spacings of its surface is in the shell.
  std::set<std::array<double, 3>> in_shell;
  for (const Vec3& p : shell) in_shell.insert({p.x(), p.y(), p.z()});
  for (const Vec3& p : voxelize(sphere, dx)) {
    if (p.norm() > 0.02 - 1.5 * dx) {
      ASSERT_EQ(in_shell.count({p.x(), p.y(), p.z()}), 1u) << p.transpose();
    }
  }
  // An axis-aligned box keeps whole layers measured from its faces.
  const Shape box = Shape::box(Vec3::Zero(), Vec3(0.01, 0.01, 0.01));
  EXPECT_EQ(voxelize_shell(box, dx, 2).size(), std::size_t(1000 - 6 * 6 * 6));
}

}  // namespace
}  // namespace thaw
