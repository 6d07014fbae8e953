#pragma once
// Triangle meshes of the density fields' iso-surfaces, for other tools (Blender, ParaView) and for
// checking the fields' shape. The contouring is marching tetrahedra: every grid cube is cut into the
// same six tetrahedra around its main diagonal (the Freudenthal/Kuhn subdivision), so neighbouring cubes
// cut their shared face along the same diagonal, no case is ambiguous, and the surface has no cracks.
// Vertices on grid edges are shared, so the mesh is indexed and closed wherever the surface stays inside
// the grid (the density fields' margins see to that for particle sets).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "render/density_field.h"

namespace thaw {

struct Mesh {
  std::vector<Eigen::Vector3f> vertices;   // [m]
  std::vector<Eigen::Vector3f> normals;    // unit, outward (down the field's gradient); one per vertex
  std::vector<Eigen::Vector3i> triangles;  // vertex indices, counter-clockwise seen from outside
};

// The surface values == iso of `values` (grid.size() of them); "inside" is values > iso.
Mesh extract_isosurface(const FieldGrid& grid, const std::vector<float>& values, float iso);

// Enclosed volume [m^3] by the divergence theorem; meaningful for closed meshes.
double mesh_volume(const Mesh& m);

// Every edge shared by exactly two triangles that run along it in opposite directions (closed and
// consistently oriented); an empty mesh is closed.
bool mesh_is_closed(const Mesh& m);

// Wavefront OBJ text: a comment with the counts, object `name`, v / vn / f (1-based, f a//a b//b c//c).
std::string mesh_obj(const Mesh& m, const std::string& name);

// Binary little-endian PLY: vertex x y z nx ny nz (float), face vertex_indices (uchar count, int).
std::string mesh_ply(const Mesh& m);

}  // namespace thaw
