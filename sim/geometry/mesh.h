#pragma once
// Triangle meshes read from OBJ, STL and PLY files, kept as a triangle soup: no shared vertices, no
// connectivity, nothing assumed about closedness; the generalized winding number (winding_number.h) needs
// only the triangles.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace thaw {

struct Triangle {
  Eigen::Vector3d a, b, c;  // counter-clockwise seen from outside: (b - a) x (c - a) points out
};

using TriangleSoup = std::vector<Triangle>;

// Every triangle of an OBJ, STL or PLY file (Assimp; polygons are split into fans, points and lines
// dropped, node transforms applied). Throws Error naming the file when it is missing, unreadable, of
// another format, malformed, or holds no triangles.
TriangleSoup load_mesh(const std::string& file);

Eigen::AlignedBox3d bounding_box(const TriangleSoup& mesh);

// The volume a closed mesh encloses, by the divergence theorem: sum over triangles of a . (b x c) / 6.
// Negative when the triangles face inwards; for an open mesh, the volume of the closed surface that joins
// each hole's border to the origin.
double signed_volume(const TriangleSoup& mesh);

// Rotation by `degrees` about x, then about y, then about z (fixed axes): Rz * Ry * Rx.
Eigen::Matrix3d rotation_from_degrees(const Eigen::Vector3d& degrees);

// The mesh rotated, then scaled so that the largest extent of its (rotated) bounding box is `size`, then
// moved so that the centre of that box is at `centre`. Throws Error when the mesh has no extent.
TriangleSoup place_mesh(const TriangleSoup& mesh, const Eigen::Matrix3d& rotation,
                        const Eigen::Vector3d& centre, double size);

}  // namespace thaw
