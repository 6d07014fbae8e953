#include "sim/geometry/mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "sim/error.h"

namespace thaw {

namespace {

Eigen::Vector3d vec(const aiVector3D& v) { return {double(v.x), double(v.y), double(v.z)}; }

std::string lower_extension(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace

TriangleSoup load_mesh(const std::string& file) {
  namespace fs = std::filesystem;
  const std::string ext = lower_extension(file);
  if (ext != ".obj" && ext != ".stl" && ext != ".ply")
    throw Error(file + ": unsupported mesh format '" + ext + "'; use an OBJ, STL or PLY file");
  std::error_code ec;
  if (!fs::exists(file, ec)) throw Error(file + ": mesh file not found");
  if (!fs::is_regular_file(file, ec)) throw Error(file + ": not a file");
  if (!std::ifstream(file, std::ios::binary)) throw Error(file + ": cannot open mesh file");

  Assimp::Importer importer;
  // Only the importer and its validation run: Debian's Assimp is built with its assertions on, and its
  // post-processing steps abort the process on some malformed faces instead of reporting them.
  const aiScene* scene = importer.ReadFile(file, aiProcess_ValidateDataStructure);
  if (scene == nullptr) throw Error(file + ": cannot read mesh: " + importer.GetErrorString());
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mRootNode == nullptr)
    throw Error(file + ": cannot read mesh: incomplete file");

  TriangleSoup soup;
  // The meshes the node tree places, each through its node's transform; polygons as fans, which is exact
  // for the convex polygons these formats hold; points and lines dropped.
  auto visit = [&](auto& self, const aiNode& node, const aiMatrix4x4& parent) -> void {
    const aiMatrix4x4 transform = parent * node.mTransformation;
    for (unsigned m = 0; m < node.mNumMeshes; ++m) {
      const aiMesh& mesh = *scene->mMeshes[node.mMeshes[m]];
      auto vertex = [&](unsigned i) { return vec(transform * mesh.mVertices[i]); };
      for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
        const aiFace& face = mesh.mFaces[f];
        for (unsigned k = 2; k < face.mNumIndices; ++k) {
          const Triangle t{vertex(face.mIndices[0]), vertex(face.mIndices[k - 1]), vertex(face.mIndices[k])};
          if (!t.a.allFinite() || !t.b.allFinite() || !t.c.allFinite())
            throw Error(file + ": cannot read mesh: a vertex of face " + std::to_string(f + 1) +
                        " is not a finite number");
          soup.push_back(t);
        }
      }
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) self(self, *node.mChildren[c], transform);
  };
  visit(visit, *scene->mRootNode, aiMatrix4x4());
  if (soup.empty()) throw Error(file + ": the mesh has no triangles");
  return soup;
}

Eigen::AlignedBox3d bounding_box(const TriangleSoup& mesh) {
  Eigen::AlignedBox3d box;
  for (const Triangle& t : mesh) box.extend(t.a).extend(t.b).extend(t.c);
  return box;
}

double signed_volume(const TriangleSoup& mesh) {
  double six_v = 0.0;
  for (const Triangle& t : mesh) six_v += t.a.dot(t.b.cross(t.c));
  return six_v / 6.0;
}

Eigen::Matrix3d rotation_from_degrees(const Eigen::Vector3d& degrees) {
  const Eigen::Vector3d r = degrees * (M_PI / 180.0);
  return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TriangleSoup place_mesh(const TriangleSoup& mesh, const Eigen::Matrix3d& rotation,
                        const Eigen::Vector3d& centre, double size) {
  TriangleSoup out = mesh;
  for (Triangle& t : out) t = {rotation * t.a, rotation * t.b, rotation * t.c};
  const Eigen::AlignedBox3d box = bounding_box(out);
  const double extent = box.sizes().maxCoeff();
  if (!(extent > 0.0)) throw Error("the mesh is a single point: its bounding box has no extent");
  const double scale = size / extent;
  const Eigen::Vector3d middle = box.center();
  for (Triangle& t : out)
    t = {centre + scale * (t.a - middle), centre + scale * (t.b - middle), centre + scale * (t.c - middle)};
  return out;
}

}  // namespace thaw
