#pragma once
// Scenes: JSON files in configs/ validated against one declared schema (sim/scene_schema.cpp).
// The schema — every field's name, type, unit, default, range and meaning — drives validation,
// error messages with JSON paths, `--set` overrides and docs/SCENES.md.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/schema.h"

namespace thaw {

struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();

  // The largest u . x over the box (at the corner u points to); -max_along(-u) is the smallest.
  double max_along(const Eigen::Vector3d& u) const {
    return u.dot(0.5 * (min + max)) + u.cwiseAbs().dot(0.5 * (max - min));
  }
};

struct Material {
  std::string name;
  std::string kind;         // "fluid" or "solid"
  double density = 1000.0;  // rest density rho0 [kg/m^3]
  double viscosity = 0.0;   // dynamic viscosity mu [Pa s] (fluids)
};

struct FluidBlock {
  int material = 0;  // index into Scene::materials
  Box box;           // filled with particles on a lattice of the scene's spacing
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

struct Solid {
  enum class Shape { Box, Plane };
  Shape shape = Shape::Box;
  int material = 0;
  Box box;                                            // Shape::Box: the solid block
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // Shape::Plane: a point on the surface
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // Shape::Plane: points into the fluid
};

struct SolverSettings {
  std::string kernel = "cubic_spline";      // "cubic_spline" | "wendland_c2"
  double support_ratio = 2.0;               // kernel support radius / particle spacing
  std::string eos = "tait";                 // "tait" | "linear"
  double gamma = 7.0;                       // Tait exponent
  double speed_of_sound = 0.0;              // [m/s]; 0 = sound_speed_factor * reference_speed
  double sound_speed_factor = 10.0;         // c = factor * v_ref keeps density error near 1/factor^2
  double reference_speed = 0.0;             // [m/s]; 0 = sqrt(2 g H) from the tallest fluid block
  double artificial_viscosity = 0.02;       // Monaghan alpha
  double boundary_viscosity = 0.0;          // alpha against static solids (0 = free slip)
  std::string boundary_volume = "lattice";  // "lattice": dx^3; "akinci": Akinci 2012 eq. 4, 1 / sum_k W_bk
  double cfl = 0.4;                         // dt <= cfl * h / (c + v_max)
  double viscous_number = 0.125;            // dt <= viscous_number * h^2 / nu
  double force_number = 0.25;               // dt <= force_number * sqrt(h / a_max)
  double max_dt = 1e-3;                     // [s] user cap
  double min_dt = 1e-8;                     // [s] below this the run stops as blown up
  double max_speed = 0.0;                   // [m/s]; 0 = 5 * c; faster particles stop the run as blown up
  double output_interval = 0.01;            // [s] metrics / export cadence in sim time
};

struct Scene {
  std::string name;
  std::string description;
  Box domain;                      // particles leaving it are clamped back and counted
  std::vector<std::string> walls;  // domain sides lined with solid: any of -x +x -y +y -z +z
  int wall_material = -1;          // material of the domain walls (index), -1 when there are none
  int wall_layers = 0;             // 0 = enough layers to fill the kernel support
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  double spacing = 0.01;  // particle spacing [m]
  SolverSettings solver;
  std::vector<Material> materials;
  std::vector<FluidBlock> fluids;
  std::vector<Solid> solids;
  Json source;  // the validated document with every default filled in
};

// Loads a scene file: reads, applies `--set` overrides, validates, converts.
// Throws SceneError (with a JSON path) or Error (missing/unreadable file).
Scene load_scene(const std::string& file, const std::vector<std::string>& overrides = {});

// Same from an in-memory document (used by validation cases and tests).
Scene scene_from_json(Json doc, const std::vector<std::string>& overrides = {});

// Applies one "path=value" override; value is JSON, or a bare string when it is not valid JSON.
// Paths: "solver.cfl", "fluids[0].box.max", "fluids.0.box.max", "gravity[2]".
void apply_override(Json& doc, const std::string& assignment);

// The same for a document of another schema (a validation case's parameters): keys the document
// leaves out start from `schema`'s defaults.
void apply_override(Json& doc, const std::string& assignment, const Field& schema);

// Markdown reference of the scene format, generated from the schema (docs/SCENES.md).
std::string scene_reference_markdown();

// Resolves a scene name: a path as given, else configs/NAME(.json) under the source tree.
// Throws Error naming the file and every place it looked.
std::string resolve_scene_path(const std::string& name);

// The declared scene format (sim/scene_schema.cpp), and its "solver" section on its own so that a
// validation case can embed it in its own parameter object.
const Field& scene_schema();
const Field& solver_schema();

// The typed settings of a "solver" object that has passed validate() against solver_schema().
SolverSettings solver_settings_from_json(const Json& solver);

// A small valid scene document: the example in docs/SCENES.md.
std::string scene_example_json();

// Reads a JSON file (comments allowed); a syntax error is an Error with file, line and column.
Json read_json_file(const std::string& file);

}  // namespace thaw
