#include "render/marching_cubes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <unordered_map>

#include "sim/little_endian.h"

namespace thaw {
namespace {

// Cube corners are numbered dx + 2 dy + 4 dz. Tetrahedron p walks from corner 0 to corner 7 one axis at
// a time in the order of the p-th permutation of (x, y, z); its vertices are nested bit sets, so of any
// two of them one is the other plus some axes, and every tetrahedron edge runs "upward" from a corner
// `lo` to a corner `hi` with lo a subset of hi. An edge is then named by its lower node and the axis
// bits hi ^ lo, the same name from every cube that shares it.
constexpr std::array<std::array<int, 4>, 6> kTets = {{
    {0, 1, 3, 7},  // x y z
    {0, 1, 5, 7},  // x z y
    {0, 2, 3, 7},  // y x z
    {0, 2, 6, 7},  // y z x
    {0, 4, 5, 7},  // z x y
    {0, 4, 6, 7},  // z y x
}};

struct Edge {
  std::uint8_t lo = 0, hi = 0;  // cube corners
};

struct TetCase {
  int count = 0;  // triangles
  std::array<std::array<Edge, 3>, 2> tri{};
};

Eigen::Vector3i corner_offset(int c) { return {c & 1, (c >> 1) & 1, (c >> 2) & 1}; }

Edge edge(int a, int b) {
  if ((a & b) != a) std::swap(a, b);
  return {std::uint8_t(a), std::uint8_t(b)};
}

// Twice the edge's midpoint, in corner units: exact integers for the orientation tests below.
Eigen::Vector3i mid2(const Edge& e) { return corner_offset(e.lo) + corner_offset(e.hi); }

// True when triangle (a, b, c), with these midpoints, faces along `outward`. The polygon in a
// tetrahedron keeps its orientation wherever its vertices slide along their edges, so deciding it at
// the midpoints, in integers, decides it for every field and never disagrees between neighbours.
bool faces(const Edge& a, const Edge& b, const Edge& c, const Eigen::Vector3i& outward) {
  const Eigen::Vector3i n = (mid2(b) - mid2(a)).cross(mid2(c) - mid2(a));
  return n.dot(outward) > 0;
}

// Triangles for each tetrahedron and each set of inside vertices (bit v: kTets[t][v] inside), oriented
// so that their normals point from the inside corners to the outside ones.
using CaseTable = std::array<std::array<TetCase, 16>, 6>;

CaseTable make_case_table() {
  CaseTable table{};
  for (int t = 0; t < 6; ++t) {
    for (int mask = 1; mask < 15; ++mask) {
      std::array<int, 4> in{}, out{};
      int n_in = 0, n_out = 0;
      Eigen::Vector3i in_sum = Eigen::Vector3i::Zero(), out_sum = Eigen::Vector3i::Zero();
      for (int v = 0; v < 4; ++v) {
        const int c = kTets[t][v];
        if (mask >> v & 1) {
          in[n_in++] = c;
          in_sum += corner_offset(c);
        } else {
          out[n_out++] = c;
          out_sum += corner_offset(c);
        }
      }
      // From the centroid of the inside corners to that of the outside ones, scaled to integers.
      const Eigen::Vector3i outward = n_in * out_sum - n_out * in_sum;
      TetCase& tc = table[t][mask];
      if (n_in == 1 || n_out == 1) {
        const int apex = n_in == 1 ? in[0] : out[0];
        const std::array<int, 3> rest =
            n_in == 1 ? std::array<int, 3>{out[0], out[1], out[2]} : std::array<int, 3>{in[0], in[1], in[2]};
        std::array<Edge, 3> tri = {edge(apex, rest[0]), edge(apex, rest[1]), edge(apex, rest[2])};
        if (!faces(tri[0], tri[1], tri[2], outward)) std::swap(tri[1], tri[2]);
        tc.count = 1;
        tc.tri[0] = tri;
      } else {
        // Two inside (a, b), two outside (c, d): the quad ac, ad, bd, bc, each step across one face.
        std::array<Edge, 4> quad = {edge(in[0], out[0]), edge(in[0], out[1]), edge(in[1], out[1]),
                                    edge(in[1], out[0])};
        if (!faces(quad[0], quad[1], quad[2], outward)) std::reverse(quad.begin(), quad.end());
        tc.count = 2;
        tc.tri[0] = {quad[0], quad[1], quad[2]};
        tc.tri[1] = {quad[0], quad[2], quad[3]};
      }
    }
  }
  return table;
}

const CaseTable& case_table() {
  static const CaseTable table = make_case_table();
  return table;
}

// The field's gradient at a node in index units, central where both neighbours exist.
Eigen::Vector3f gradient(const FieldGrid& g, const std::vector<float>& v, int i, int j, int k) {
  auto diff = [&](int lo_i, int lo_j, int lo_k, int hi_i, int hi_j, int hi_k) {
    return (v[g.index(hi_i, hi_j, hi_k)] - v[g.index(lo_i, lo_j, lo_k)]) /
           float(std::max(1, (hi_i - lo_i) + (hi_j - lo_j) + (hi_k - lo_k)));
  };
  return {diff(std::max(i - 1, 0), j, k, std::min(i + 1, g.nx - 1), j, k),
          diff(i, std::max(j - 1, 0), k, i, std::min(j + 1, g.ny - 1), k),
          diff(i, j, std::max(k - 1, 0), i, j, std::min(k + 1, g.nz - 1))};
}

// Shortest text that reads back as the same float.
void put_text(std::string& out, float v) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, result.ptr);
}

void put_text(std::string& out, int v) {
  char buf[16];
  const auto result = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, result.ptr);
}

}  // namespace

Mesh extract_isosurface(const FieldGrid& g, const std::vector<float>& values, float iso) {
  Mesh m;
  if (g.nx < 2 || g.ny < 2 || g.nz < 2 || values.size() < g.size()) return m;
  const CaseTable& table = case_table();
  std::array<std::size_t, 8> corner_step{};
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3i o = corner_offset(c);
    corner_step[c] = g.index(o.x(), o.y(), o.z());
  }
  // Edge name (lower node * 8 + axis bits) -> vertex index. Cubes are visited in a fixed order, so the
  // vertex and triangle order is deterministic.
  std::unordered_map<std::uint64_t, int> vertex_of;
  auto vertex = [&](std::size_t base, int i, int j, int k, const Edge& e) {
    const std::size_t lo = base + corner_step[e.lo], hi = base + corner_step[e.hi];
    const std::uint64_t key = std::uint64_t(lo) * 8 + std::uint64_t(e.hi ^ e.lo);
    const auto [it, fresh] = vertex_of.try_emplace(key, int(m.vertices.size()));
    if (!fresh) return it->second;
    const float a = values[lo], b = values[hi];
    const float t = std::clamp((iso - a) / (b - a), 0.0f, 1.0f);  // one is > iso, the other not: b != a
    const Eigen::Vector3i o_lo = Eigen::Vector3i(i, j, k) + corner_offset(e.lo);
    const Eigen::Vector3i o_hi = Eigen::Vector3i(i, j, k) + corner_offset(e.hi);
    const Eigen::Vector3f p = o_lo.cast<float>() + t * (o_hi - o_lo).cast<float>();
    m.vertices.push_back(g.origin + g.cell * p);
    const Eigen::Vector3f grad = (1 - t) * gradient(g, values, o_lo.x(), o_lo.y(), o_lo.z()) +
                                 t * gradient(g, values, o_hi.x(), o_hi.y(), o_hi.z());
    m.normals.push_back(-grad);  // normalised at the end, where a vanishing gradient can be replaced
    return it->second;
  };

  for (int k = 0; k + 1 < g.nz; ++k) {
    for (int j = 0; j + 1 < g.ny; ++j) {
      for (int i = 0; i + 1 < g.nx; ++i) {
        const std::size_t base = g.index(i, j, k);
        unsigned cube = 0;
        for (int c = 0; c < 8; ++c) cube |= unsigned(values[base + corner_step[c]] > iso) << c;
        if (cube == 0 || cube == 255) continue;
        for (int t = 0; t < 6; ++t) {
          int mask = 0;
          for (int v = 0; v < 4; ++v) mask |= int(cube >> kTets[t][v] & 1) << v;
          const TetCase& tc = table[t][mask];
          for (int n = 0; n < tc.count; ++n) {
            const std::array<Edge, 3>& e = tc.tri[n];
            m.triangles.emplace_back(vertex(base, i, j, k, e[0]), vertex(base, i, j, k, e[1]),
                                     vertex(base, i, j, k, e[2]));
          }
        }
      }
    }
  }

  // Where the field is flat (a plateau exactly at iso), fall back to the surface's own normals.
  std::vector<Eigen::Vector3f> area_normal;
  for (std::size_t v = 0; v < m.normals.size(); ++v) {
    if (m.normals[v].squaredNorm() > 1e-20f) {
      m.normals[v].normalize();
      continue;
    }
    if (area_normal.empty()) {
      area_normal.assign(m.vertices.size(), Eigen::Vector3f::Zero());
      for (const Eigen::Vector3i& tri : m.triangles) {
        const Eigen::Vector3f n =
            (m.vertices[tri[1]] - m.vertices[tri[0]]).cross(m.vertices[tri[2]] - m.vertices[tri[0]]);
        for (int c = 0; c < 3; ++c) area_normal[tri[c]] += n;
      }
    }
    m.normals[v] = area_normal[v].normalized();
  }
  return m;
}

double mesh_volume(const Mesh& m) {
  double six_v = 0;
  for (const Eigen::Vector3i& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices[t[0]].cast<double>(), b = m.vertices[t[1]].cast<double>(),
                          c = m.vertices[t[2]].cast<double>();
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6;
}

bool mesh_is_closed(const Mesh& m) {
  const std::uint64_t n = m.vertices.size();
  // Directed edges a -> b as a * n + b, sorted: closed and consistently oriented means each appears once
  // and so does its reverse.
  std::vector<std::uint64_t> directed;
  directed.reserve(3 * m.triangles.size());
  for (const Eigen::Vector3i& t : m.triangles) {
    for (int c = 0; c < 3; ++c) {
      const int a = t[c], b = t[(c + 1) % 3];
      if (a < 0 || b < 0 || std::uint64_t(a) >= n || std::uint64_t(b) >= n || a == b) return false;
      directed.push_back(std::uint64_t(a) * n + std::uint64_t(b));
    }
  }
  std::sort(directed.begin(), directed.end());
  if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return false;
  for (const std::uint64_t e : directed) {
    if (!std::binary_search(directed.begin(), directed.end(), (e % n) * n + e / n)) return false;
  }
  return true;
}

std::string mesh_obj(const Mesh& m, const std::string& name) {
  std::string out = "# thaw iso-surface: " + std::to_string(m.vertices.size()) + " vertices, " +
                    std::to_string(m.triangles.size()) + " triangles\no " + name + "\n";
  out.reserve(out.size() + 70 * m.vertices.size() + 40 * m.triangles.size());
  for (const Eigen::Vector3f& v : m.vertices) {
    out += "v";
    for (int c = 0; c < 3; ++c) (out += ' ', put_text(out, v[c]));
    out += '\n';
  }
  for (const Eigen::Vector3f& v : m.normals) {
    out += "vn";
    for (int c = 0; c < 3; ++c) (out += ' ', put_text(out, v[c]));
    out += '\n';
  }
  for (const Eigen::Vector3i& t : m.triangles) {
    out += "f";
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      put_text(out, t[c] + 1);
      out += "//";
      put_text(out, t[c] + 1);
    }
    out += '\n';
  }
  return out;
}

std::string mesh_ply(const Mesh& m) {
  std::string out =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "comment thaw iso-surface\n"
      "element vertex " +
      std::to_string(m.vertices.size()) +
      "\n"
      "property float x\n"
      "property float y\n"
      "property float z\n"
      "property float nx\n"
      "property float ny\n"
      "property float nz\n"
      "element face " +
      std::to_string(m.triangles.size()) +
      "\n"
      "property list uchar int vertex_indices\n"
      "end_header\n";
  out.reserve(out.size() + 24 * m.vertices.size() + 13 * m.triangles.size());
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    for (int c = 0; c < 3; ++c) put_little_endian(out, m.vertices[v][c]);
    for (int c = 0; c < 3; ++c) put_little_endian(out, m.normals[v][c]);
  }
  for (const Eigen::Vector3i& t : m.triangles) {
    put_little_endian(out, std::uint8_t{3});
    for (int c = 0; c < 3; ++c) put_little_endian(out, std::int32_t{t[c]});
  }
  return out;
}

}  // namespace thaw
