#include "sim/geometry/mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/error.h"

namespace thaw {

namespace {

Eigen::Vector3d vec(const aiVector3D& v) { return {double(v.x), double(v.y), double(v.z)}; }

std::string lower_extension(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// The bytes of one value of a PLY scalar type, 0 for a name that is not one.
std::size_t ply_type_bytes(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

// Checks a PLY file's header before Assimp reads it. Assimp's PLY reader looks for `end_header` without
// a bound (a 21-byte "ply\nformat ascii 1.0\n" kept it at 99 % CPU forever) and trusts the element
// counts; a hang cannot be interrupted from outside the importer (a thread cannot be cancelled, and a
// deadline would leave it spinning), so a file is handed over only when its header is complete, well
// formed, and the body is long enough for what it declares: at least 2 bytes a value in ASCII (a digit
// and a separator), the exact sizes in binary (a list at least its count).
void check_ply_header(const std::string& file) {
  constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
  std::ifstream in(file, std::ios::binary);
  std::string head(kMaxHeaderBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  const auto bad = [&file](const std::string& what) { return Error(file + ": cannot read mesh: " + what); };

  std::size_t at = 0, line_number = 0;
  auto next_line = [&](std::string& line) {
    const std::size_t end = head.find('\n', at);
    if (end == std::string::npos) return false;
    line = head.substr(at, end - at);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    at = end + 1;
    ++line_number;
    return true;
  };
  std::string line;
  if (!next_line(line) || line != "ply") throw bad("not a PLY file (its first line is not 'ply')");
  std::string format;
  struct Element {
    std::string name;
    unsigned long long count = 0;
    double min_bytes = 0;  // per element
  };
  std::vector<Element> elements;
  bool ended = false;
  while (!ended && next_line(line)) {
    std::istringstream words(line);
    std::string word;
    words >> word;
    const std::string where = "PLY header line " + std::to_string(line_number) + ": ";
    if (word == "end_header") {
      ended = true;
    } else if (word == "format") {
      std::string version;
      words >> format >> version;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        throw bad(where + "unknown format '" + format + "'");
    } else if (word == "element") {
      Element e;
      std::string count;
      words >> e.name >> count;
      if (count.empty() || count.size() > 12 || count.find_first_not_of("0123456789") != std::string::npos)
        throw bad(where + "element '" + e.name + "' has no count of at most 12 digits");
      e.count = std::stoull(count);
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) throw bad(where + "a property before any element");
      std::string type;
      words >> type;
      const bool list = type == "list";
      if (list) words >> type;  // the count's type; the item type follows
      const std::size_t bytes = ply_type_bytes(type);
      std::string item;
      if (list) words >> item;
      if (bytes == 0 || (list && ply_type_bytes(item) == 0))
        throw bad(where + "unknown property type in '" + line + "'");
      elements.back().min_bytes += format == "ascii" ? 2.0 : double(bytes);
    } else if (word != "comment" && word != "obj_info" && !word.empty()) {
      throw bad(where + "unknown keyword '" + word + "'");
    }
  }
  if (!ended)
    throw bad(head.size() >= kMaxHeaderBytes ? "no end_header line in the first 64 KiB"
                                             : "the PLY header has no end_header line (truncated?)");
  if (format.empty()) throw bad("the PLY header has no format line");
  double needed = 0;
  for (const Element& e : elements) needed += double(e.count) * e.min_bytes;
  if (format == "ascii") needed -= 1;  // the last value needs no separator after it
  const double body = ec ? 0.0 : double(size) - double(at);
  if (needed > body) {
    std::string declared;
    for (const Element& e : elements)
      declared += (declared.empty() ? "" : ", ") + std::to_string(e.count) + " " + e.name;
    throw bad("truncated: the PLY header declares " + declared + ", at least " +
              std::to_string(static_cast<unsigned long long>(needed)) + " bytes, but " +
              std::to_string(static_cast<long long>(body)) + " follow the header");
  }
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
  if (ext == ".ply") check_ply_header(file);

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
