// The scene format, declared once: validation, `--set`, docs/SCENES.md and the protocol's list of
// live parameters all read these declarations.
#include "sim/scene.h"

namespace thaw {

const Field& solver_schema() {
  static const Field solver = object(
      "solver",
      {
          choice("kernel", {"cubic_spline", "wendland_c2"}, "Smoothing kernel").def("cubic_spline"),
          number("support_ratio", "Kernel support radius / particle spacing")
              .def(2.0)
              .at_least(1.2)
              .at_most(4),
          choice("eos", {"tait", "linear"}, "Equation of state: Tait (stiff) or linear in density")
              .def("tait"),
          number("gamma", "Tait exponent").def(7.0).at_least(1).at_most(10),
          number("speed_of_sound", "Numerical speed of sound; 0 = sound_speed_factor * reference_speed")
              .in("m/s")
              .def(0.0)
              .at_least(0),
          number("sound_speed_factor", "c = factor * v_ref keeps the density error near 1/factor^2")
              .def(10.0)
              .at_least(1)
              .at_most(100),
          number("reference_speed", "Largest expected flow speed; 0 = sqrt(2 g H) of the tallest fluid block")
              .in("m/s")
              .def(0.0)
              .at_least(0),
          number("artificial_viscosity", "Monaghan alpha between fluid particles")
              .def(0.02)
              .at_least(0)
              .at_most(1)
              .client_settable(),
          number("boundary_viscosity", "Monaghan alpha against static solids; 0 = free slip")
              .def(0.0)
              .at_least(0)
              .at_most(1)
              .client_settable(),
          choice("boundary_volume", {"lattice", "akinci"},
                 "Volume of a boundary particle: lattice = spacing^3; akinci = 1 / sum_k W_bk (Akinci 2012 "
                 "eq 4)")
              .def("lattice"),
          number("cfl", "Courant number: dt <= cfl * h / (c + v_max)")
              .def(0.4)
              .above(0)
              .at_most(1)
              .client_settable(),
          number("viscous_number", "Viscous limit: dt <= viscous_number * h^2 / nu")
              .def(0.125)
              .above(0)
              .at_most(1),
          number("force_number", "Force limit: dt <= force_number * sqrt(h / a_max)")
              .def(0.25)
              .above(0)
              .at_most(1),
          number("max_dt", "Upper limit of the time step")
              .in("s")
              .def(1e-3)
              .above(0)
              .at_most(1)
              .client_settable(),
          number("min_dt", "A time step below this stops the run as blown up").in("s").def(1e-8).above(0),
          number("max_speed", "A particle faster than this stops the run as blown up; 0 = 5 * c")
              .in("m/s")
              .def(0.0)
              .at_least(0),
          number("output_interval", "Simulated time between metrics and exports")
              .in("s")
              .def(0.01)
              .above(0)
              .client_settable(),
      },
      "Time stepping and SPH discretisation.");
  return solver;
}

namespace {

Field box_field(std::string key, std::string doc) {
  return object(std::move(key),
                {
                    vec3("min", "Lower corner").in("m"),
                    vec3("max", "Upper corner; above min on every axis").in("m"),
                },
                std::move(doc));
}

}  // namespace

const Field& scene_schema() {
  static const Field scene = object(
      "",
      {
          text("name", "Short name shown by the CLI and the browser; defaults to the file name").def(""),
          text("description", "What the scene shows, and any liberties it takes with physics").def(""),
          object("domain",
                 {
                     vec3("min", "Lower corner").in("m"),
                     vec3("max", "Upper corner; above min on every axis").in("m"),
                     subset("walls", {"-x", "+x", "-y", "+y", "-z", "+z"},
                            "Sides of the domain lined with solid")
                         .def(Json::array()),
                     text("wall_material", "Material of the walls, a solid; required when walls is not empty")
                         .optional(),
                     integer("wall_layers", "Layers of wall particles; 0 = enough to fill the kernel support")
                         .def(0)
                         .at_least(0)
                         .at_most(10),
                 },
                 "The simulated box; particles that leave it are clamped back and counted."),
          vec3("gravity", "Gravitational acceleration").in("m/s^2").def({0.0, 0.0, -9.81}).client_settable(),
          number("spacing", "Particle spacing; sets the resolution").in("m").above(0),
          solver_schema(),
          map_of("materials", "<name>",
                 {
                     choice("kind", {"fluid", "solid"}, "Fluid particles move; solids are static boundaries"),
                     number("density", "Rest density").in("kg/m^3").above(0).at_most(1e5),
                     number("viscosity", "Dynamic viscosity (fluids)").in("Pa s").def(0.0).at_least(0),
                 },
                 "Materials by name; objects refer to them by name.")
              .non_empty(),
          array_of("fluids",
                   {
                       text("material", "Name of a fluid material"),
                       box_field("box", "Filled with particles on a lattice of the scene's spacing"),
                       vec3("velocity", "Initial velocity").in("m/s").def({0.0, 0.0, 0.0}),
                   },
                   "Blocks of fluid particles.")
              .non_empty(),
          array_of("solids",
                   {
                       choice("shape", {"box", "plane"}, "Solid block or half-space"),
                       text("material", "Name of a solid material"),
                       box_field("box", "The solid block").when("shape", "box"),
                       vec3("point", "A point on the plane").in("m").when("shape", "plane"),
                       vec3("normal", "Plane normal, pointing into the fluid; need not be unit length")
                           .when("shape", "plane"),
                   },
                   "Static solids, sampled as boundary particles.")
              .def(Json::array()),
      });
  return scene;
}

namespace {

constexpr const char* kIntro = R"(# Scene files

A scene is a JSON file in `configs/`. A scene named `NAME` on the command line is found as the path
`NAME` or `NAME.json`, else as `configs/NAME` or `configs/NAME.json` in the source tree; the default
scene is `configs/default.json`. Comments (`//`, `/* */`) are allowed.

Every field below is checked when the scene loads: unknown keys, wrong types, values out of range and
missing required fields are errors naming the JSON path, e.g.
`solver.cfll: unknown key (did you mean 'cfl'?); allowed keys: kernel, support_ratio, ...`.
Fields with a default may be left out. Units are SI; temperatures are in °C.

`--set PATH=VALUE` changes any field before validation, e.g. `--set solver.cfl=0.3`,
`--set fluids[0].box.max=[0.3,0.2,0.4]`, `--set solver.kernel=wendland_c2` (a value that is not valid
JSON is taken as a string). Fields with *yes* in the *live* column may also be changed by a connected
client while the simulation runs.

Checked across fields:
- `domain.max` is above `domain.min` on every axis, and so is every box's `max` above its `min`;
- `spacing` is smaller than the smallest extent of the domain, and the scene stays below 20 million
  particles (an estimate from the fluid blocks and the walls);
- a fluid block's material is a fluid, a solid's and the walls' material is a solid, and every
  material name is defined in `materials`;
- `domain.wall_material` is given when `domain.walls` is not empty;
- fluid blocks lie inside the domain; plane normals are not zero;
- `solver.min_dt` is below `solver.max_dt`.

## Example

```json
)";

// Also checked by tests/sim/scene_test.cpp, so the documented example always loads.
constexpr const char* kExample = R"({
  "name": "example",
  "description": "A water column collapses in a glass tank around a steel block.",
  "domain": {"min": [0, 0, 0], "max": [0.6, 0.2, 0.4], "walls": ["-x", "+x", "-y", "+y", "-z"],
             "wall_material": "glass"},
  "spacing": 0.01,
  "solver": {"kernel": "wendland_c2", "support_ratio": 3.0, "cfl": 0.3},
  "materials": {
    "water": {"kind": "fluid", "density": 1000, "viscosity": 1.0e-3},
    "glass": {"kind": "solid", "density": 2500},
    "steel": {"kind": "solid", "density": 7850}
  },
  "fluids": [{"material": "water", "box": {"min": [0, 0, 0], "max": [0.2, 0.2, 0.3]}}],
  "solids": [{"shape": "box", "material": "steel", "box": {"min": [0.4, 0.05, 0], "max": [0.45, 0.15, 0.1]}}]
}
)";

}  // namespace

std::string scene_example_json() { return kExample; }

std::string scene_reference_markdown() {
  return std::string(kIntro) + kExample + "```\n\n" + schema_markdown(scene_schema(), "Reference: top level");
}

}  // namespace thaw
