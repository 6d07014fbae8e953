// The scene format, declared once: validation, `--set`, docs/SCENES.md and the protocol's list of
// live parameters all read these declarations.
#include <algorithm>
#include <utility>

#include "sim/scene.h"

namespace thaw {

const Field& solver_schema() {
  static const Field solver = object(
      "solver",
      {
          choice("kernel", choice_names<KernelFunction>(), "Smoothing kernel").def("cubic_spline"),
          number("support_ratio", "Kernel support radius / particle spacing")
              .def(2.0)
              .at_least(1.2)
              .at_most(4),
          choice("pressure", choice_names<PressureSolver>(),
                 "Pressure solver: wcsph = weakly compressible, an equation of state (eos) and a sound-speed "
                 "time step; dfsph = divergence-free SPH (Bender & Koschier 2015, 2017), constant density by "
                 "iteration and a velocity time step")
              .def("wcsph"),
          number("density_tolerance",
                 "dfsph: the density solve stops when the mean compression (rho - rho0) / rho0 is below this")
              .def(0.001)
              .above(0)
              .at_most(0.1),
          number("divergence_tolerance",
                 "dfsph: the divergence solve stops when the mean compression rate (D rho / Dt) dt / rho0 is "
                 "below this")
              .def(0.001)
              .above(0)
              .at_most(0.1),
          integer("max_pressure_iterations", "dfsph: the most iterations of each solve per step")
              .def(100)
              .at_least(2)
              .at_most(10000),
          number("pressure_relaxation",
                 "dfsph: relaxed Jacobi omega, the share of each particle's own correction a sweep applies "
                 "(0.5 as IISPH; 1 is Bender & Koschier's plain Jacobi)")
              .def(0.5)
              .above(0)
              .at_most(1),
          flag(
              "divergence_warm_start",
              "dfsph: start each divergence solve from half of the last step's divergence pressure (Bender & "
              "Koschier 2017's warm start); false (the default) starts it from zero: fewer iterations in "
              "flowing water, the same results (docs/BENCHMARKS.md)")
              .def(false),
          choice(
              "boundary_pressure", choice_names<DfsphBoundary>(),
              "dfsph: the pressure of wall, solid and ice particles in the solves: adami2012 = extrapolated "
              "from the fluid next to them each sweep (Adami et al. 2012), so a wall carries the full load; "
              "akinci2012 = none, the fluid's own pressure one-sided (Akinci et al. 2012, as Bender & "
              "Koschier 2017 use it), which carries half and lets water sink into walls (for comparison)")
              .def("adami2012"),
          choice(
              "multiphase", choice_names<Multiphase>(),
              "dfsph, fluids of several rest densities (air beside water): hu_adams2006 = each particle's "
              "density from its neighbours' rest volumes and a pair pressure weighted by the other's "
              "density (Hu & Adams 2006's inter-particle pressure), so the water's pressure does not push "
              "the light air, with the harmonic mean of the viscosities; holds air still over water at the "
              "real ratio (thaw validate air-water). domaradzki_martyn = the paper's choices (Domaradzki & "
              "Martyn sec. 6.1): the pair's mean pressure, the viscosities' arithmetic mean (eq 5) and no "
              "suction at the interface (eq 6); meant for their air 10x lighter than water, for comparison")
              .def("hu_adams2006"),
          choice("eos", choice_names<Eos>(), "Equation of state: Tait (stiff) or linear in density")
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
          choice("no_slip", choice_names<NoSlip>(),
                 "adami2012: walls, solids and ice hold the fluid still at their surface (Adami et al. 2012 "
                 "eqs 22-23: in the viscous term each boundary particle moves with 2 v_wall minus the fluid "
                 "velocity around it, with the fluid's own viscosity; boundary_viscosity is then unused); "
                 "none: walls resist only through boundary_viscosity")
              .def("none"),
          number("boundary_viscosity", "Monaghan alpha against static solids; 0 = free slip")
              .def(0.0)
              .at_least(0)
              .at_most(1)
              .client_settable(),
          choice("boundary_volume", choice_names<BoundaryVolume>(),
                 "Volume of a boundary particle: lattice = spacing^3; akinci = 1 / sum_k W_bk (Akinci 2012 "
                 "eq 4)")
              .def("lattice"),
          number("cfl", "Courant number: dt <= cfl * h / (c + v_max)")
              .def(0.4)
              .above(0)
              .at_most(1)
              .client_settable(),
          number("viscous_number", "Viscous limit: dt <= viscous_number * min(h, spacing)^2 / nu")
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
              .at_most(3600)
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
          flag("flow",
               "Move the fluid (density, forces, integration); false = particles stay where they are and "
               "only heat "
               "flows, at the diffusion time step (conduction studies, the Stefan problem)")
              .def(true),
          subset(
              "periodic", {"x", "y", "z"},
              "Axes along which the domain wraps around (no walls or open sides on those axes, a domain at "
              "least 3 kernel supports long along them; with flow only y and z, and no free ice)")
              .def(Json::array()),
          number("diffusion_number",
                 "Heat diffusion limit: dt <= diffusion_number * h^2 / (heat.time_scale * alpha_max)")
              .def(0.1)
              .above(0)
              .at_most(0.5),
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

// " (shape sphere, mesh; required there)": which shapes take a field that several share.
std::string shared_note(const std::string& key) {
  for (const SharedShapeField& f : shared_shape_fields()) {
    if (f.key != key) continue;
    std::string shapes;
    for (const std::string& shape : f.shapes) shapes += (shapes.empty() ? "" : ", ") + shape;
    return " (shape " + shapes + (f.required ? "; required there)" : ")");
  }
  return "";
}

// The fields after `shape` that say where a shape is and how big; `box` keeps its meaning from before
// shapes (fill the block).
std::vector<Field> shape_fields(const std::string& box_doc) {
  return {
      box_field("box", box_doc).when("shape", "box"),
      vec3("centre", "Centre of the sphere; for a mesh, where the centre of its bounding box goes" +
                         shared_note("centre"))
          .in("m")
          .optional(),
      number("radius",
             "Radius of the sphere, cylinder or capsule, or of the cone's base" + shared_note("radius"))
          .in("m")
          .above(0)
          .optional(),
      vec3("from",
           "Centre of one end of the cylinder or capsule, or of the cone's base" + shared_note("from"))
          .in("m")
          .optional(),
      vec3("to", "Centre of the other end, or the cone's apex; not equal to from" + shared_note("to"))
          .in("m")
          .optional(),
      text("mesh",
           "OBJ, STL or PLY file: relative to the scene file's folder, else to configs/; the inside is "
           "where the generalized winding number exceeds 1/2, so small holes do no harm")
          .when("shape", "mesh"),
      number("size", "Largest extent of the mesh's bounding box after rotation")
          .in("m")
          .above(0)
          .when("shape", "mesh"),
      vec3("rotation",
           "Degrees about x, then y, then z; a box turns about its centre, a mesh before it is "
           "placed; default [0, 0, 0]" +
               shared_note("rotation"))
          .in("deg")
          .optional(),
  };
}

// A fluid block's or an emitter's `substances`: each substance's concentration, by the name the scene's
// `substances` gives it (docs/SUBSTANCES.md).
Field dissolved_substances(const std::string& doc) {
  return map_of("substances", "<substance>",
                {
                    number("concentration", "Mass of substance per volume of fluid; 1 kg/m^3 is 1 g/L")
                        .in("kg/m^3")
                        .at_least(0)
                        .at_most(1e4),
                },
                doc + ", by the name the scene's `substances` gives them")
      .def(Json::object());
}

// An ice or solid entry: its shape, its material, the shape's fields, then `rest`.
std::vector<Field> shaped_entry(Field shape, Field material, const std::string& box_doc,
                                std::vector<Field> rest) {
  std::vector<Field> fields = {std::move(shape), std::move(material)};
  for (Field& f : shape_fields(box_doc)) fields.push_back(std::move(f));
  for (Field& f : rest) fields.push_back(std::move(f));
  return fields;
}

}  // namespace

const std::vector<SharedShapeField>& shared_shape_fields() {
  static const std::vector<SharedShapeField> fields = {
      {"centre", {"sphere", "mesh"}, true},
      {"radius", {"sphere", "cylinder", "cone", "capsule"}, true},
      {"from", {"cylinder", "cone", "capsule"}, true},
      {"to", {"cylinder", "cone", "capsule"}, true},
      {"rotation", {"box", "mesh"}, false},
  };
  return fields;
}

const Field& scene_schema() {
  static const Field scene = object(
      "",
      {
          text("name", "Short name shown by the CLI and the browser; defaults to the file name").def(""),
          text("description", "What the scene shows, and any liberties it takes with physics").def(""),
          object(
              "domain",
              {
                  vec3("min", "Lower corner").in("m"),
                  vec3("max",
                       "Upper corner; above min on every axis, and a whole number of spacings from it "
                       "along an axis with a wall on its upper side")
                      .in("m"),
                  subset("walls", {"-x", "+x", "-y", "+y", "-z", "+z"},
                         "Sides of the domain lined with solid")
                      .def(Json::array()),
                  subset("open", {"-x", "+x", "-y", "+y", "-z", "+z"},
                         "Sides water may leave through: a fluid particle past one is removed and its mass, "
                         "momentum and enthalpy counted as outflow (metrics), rather than held at the face; "
                         "not a side with a wall. With air particles an open side is the room beyond: air "
                         "leaves through it, and the room's air (at rest, at ambient.temperature) comes "
                         "back in where a spacing next to the side has emptied, counted as inflow")
                      .def(Json::array()),
                  text("wall_material", "Material of the walls, a solid; required when walls is not empty")
                      .optional(),
                  integer("wall_layers",
                          "Layers of wall particles; 0 = enough to hold water: one more than the support "
                          "ratio above 2 spacings (4 at 3), else as many as the support reaches (2 at 2)")
                      .def(0)
                      .at_least(0)
                      .at_most(10),
                  object(
                      "wall_heat",
                      {
                          number("coefficient",
                                 "U of the heat flux U (T_outside - T_wall) through the walls' outer face; "
                                 "0 = insulated")
                              .in("W/m^2/K")
                              .def(0.0)
                              .at_least(0)
                              .at_most(1e5)
                              .client_settable(),
                          number("temperature", "Temperature outside the tank")
                              .in("°C")
                              .def(20.0)
                              .above(-273.15)
                              .at_most(1000)
                              .client_settable(),
                      },
                      "Heat exchange of the tank walls with the outside (Domaradzki & Martyn sec. 7)."),
              },
              "The simulated box; particles that leave it are clamped back and counted (a free ice body is "
              "moved back whole)."),
          vec3("gravity", "Gravitational acceleration").in("m/s^2").def({0.0, 0.0, -9.81}).client_settable(),
          number("spacing", "Particle spacing; sets the resolution").in("m").above(0),
          solver_schema(),
          object(
              "heat",
              {
                  flag("enabled",
                       "Run the thermal stages (conduction, heat sources, phase change) when the scene needs "
                       "them: particles at different temperatures, air or tank walls at another temperature, "
                       "or a dryer or lamp. A scene without any of these builds no heat stage (`thaw run` "
                       "says which stages it built); false: never")
                      .def(true),
                  number("time_scale",
                         "Heat flows this many times faster than the water moves: 1 is physical; interactive "
                         "scenes may raise it and say so in their description")
                      .def(1.0)
                      .above(0)
                      .at_most(1e6)
                      .client_settable(),
                  integer(
                      "max_substeps",
                      "Heat steps one flow step may hold. Where conduction (times time_scale) sets the time "
                      "step, as in air with a raised time_scale, the heat pass runs up to this many "
                      "sub-steps with the particles where they are, and the flow takes one step as long "
                      "as all of them (operator splitting). 1: heat and flow share every step. Lamps "
                      "need 1 (their photons are traced once a step)")
                      .def(1)
                      .at_least(1)
                      .at_most(64),
                  choice("exposed_area", choice_names<ExposedArea>(),
                         "Model of each particle's surface exposed to air (the surface stage, "
                         "docs/SURFACE.md): brackbill1992 = the colour gradient's surface delta |grad c| "
                         "(Brackbill et al. 1992), scaled so a flat face sums to its area, with Orthmann et "
                         "al. 2013's thin-sheet handling; orthmann2013 = Orthmann et al. 2013 eqs 2-9 as the "
                         "paper has them; iwasaki2010 = (6 - n_i) / 6 of a voxel's six faces, n_i the "
                         "particles within 1.2 spacings (Iwasaki et al. 2010 sec. 4)")
                      .def("brackbill1992"),
                  integer("area_interval",
                          "Flow steps between updates of the surface stage's areas (brackbill1992, "
                          "orthmann2013; docs/SURFACE.md): a step moves the surface a fraction of a spacing, "
                          "and the areas stay with their particles in between (saved in state files, so a "
                          "resumed run goes on as it was). 1: every step. Orthmann's eq 9 relaxes once an "
                          "update")
                      .def(4)
                      .at_least(1)
                      .at_most(64),
              },
              "Heat transfer and phase change (Iwasaki et al. 2010; docs/ARCHITECTURE.md Numerics)."),
          object(
              "tension",
              {
                  choice(
                      "model", choice_names<TensionModel>(),
                      "Interfacial tension of water (docs/TENSION.md): brackbill1992 = Brackbill, Kothe & "
                      "Zemach 1992's continuum surface force sigma kappa n on each surface particle's "
                      "area, kappa from a quadric fitted to the surface near it, with Akinci et al. 2013's "
                      "adhesion to solids and ice; akinci2013 = Akinci et al. 2013's "
                      "cohesion and curvature between water particles and adhesion to solids and ice; "
                      "iwasaki2010 = Iwasaki et al. 2010 eq. 4, an attraction k (x_j - x_i) / r^2 to water "
                      "and ice neighbours (and here solids). Both are calibrated from `coefficient` and "
                      "the contact angles below, so that a flat surface of uniformly spread particles "
                      "has that tension; docs/TENSION.md has how near the simulated drops come. none: no "
                      "tension stage is built")
                      .def("none")
                      .client_settable(),
                  number("coefficient",
                         "Water-air surface tension sigma; 0.0756 at 0 °C, 0.0728 at 20 °C. A scene that "
                         "scales it says so in its description")
                      .in("N/m")
                      .def(0.0756)
                      .above(0)
                      .at_most(10)
                      .client_settable(),
                  flag("curvature", "akinci2013: include its curvature (surface-minimising) term")
                      .def(true)
                      .client_settable(),
                  number("solid_contact_angle",
                         "Contact angle water makes on the solids and walls; sets their adhesion by "
                         "Young-Dupre, W = sigma (1 + cos theta); 180 = none")
                      .in("deg")
                      .def(90.0)
                      .at_least(0)
                      .at_most(180)
                      .client_settable(),
                  number("ice_contact_angle", "Contact angle water makes on ice (about 12, Knight 1967)")
                      .in("deg")
                      .def(12.0)
                      .at_least(0)
                      .at_most(180)
                      .client_settable(),
              },
              "Surface tension of water and its adhesion to solids and ice; needs solver.flow."),
          object(
              "camera",
              {
                  number("azimuth", "Angle about the vertical axis, from +x towards +y")
                      .in("deg")
                      .def(30.0)
                      .at_least(-360)
                      .at_most(360),
                  number("elevation", "Angle above the horizontal").in("deg").def(25.0).above(-90).below(90),
                  number("distance", "From the target; 0 = the distance that frames the whole domain")
                      .in("m")
                      .def(0.0)
                      .at_least(0)
                      .at_most(1e3),
                  vec3("target", "The point looked at; default the domain's centre").in("m").optional(),
                  number("fov", "Vertical field of view").in("deg").def(40.0).at_least(5).at_most(120),
              },
              "How a viewer first sees the scene: the browser on load and on 'reset view', `thaw run "
              "--frames` and `thaw render` unless given --camera, --target or --fov. Frame the subject, not "
              "the whole domain, where the domain is much larger."),
          object(
              "ambient",
              {
                  number("temperature", "Air around the scene; objects without a temperature start at it")
                      .in("°C")
                      .def(20.0)
                      .above(-273.15)
                      .at_most(1000)
                      .client_settable(),
                  number(
                      "heat_transfer_coefficient",
                      "h in Newton's cooling h (T_air - T) dA through the exposed surface of ice and water; "
                      "0 = insulated")
                      .in("W/m^2/K")
                      .def(10.0)
                      .at_least(0)
                      .at_most(1e4)
                      .client_settable(),
              },
              "Still air around the scene (the mode without air particles)."),
          map_of(
              "substances", "<name>",
              {
                  number("diffusivity",
                         "Its molecular diffusivity D in water: about 1e-9 for a dye or a salt at 20 °C "
                         "(NaCl 1.5e-9), 0 for none")
                      .in("m^2/s")
                      .def(1e-9)
                      .at_least(0)
                      .at_most(1e-2),
                  number("molar_mass",
                         "Its molar mass, which under the blagden liquidus makes it lower the melting point "
                         "of the water it is dissolved in by the fluid's cryoscopic_constant times "
                         "dissociation times its molality (Blagden's law with van 't Hoff's factor): NaCl "
                         "0.05844. 0 with blagden: it does not (a dye)")
                      .in("kg/mol")
                      .def(0.0)
                      .at_least(0)
                      .at_most(100),
                  number("dissociation",
                         "van 't Hoff's factor i: the particles one formula unit makes in solution (NaCl "
                         "2, sugar 1)")
                      .def(1.0)
                      .at_least(1)
                      .at_most(10),
                  choice(
                      "liquidus", choice_names<LiquidusLaw>(),
                      "How far below the water's melting point a melt holding it freezes, by its mass "
                      "fraction (docs/SUBSTANCES.md): blagden, the dilute law from molar_mass and "
                      "dissociation, capped at 40 K, with no eutectic (it overestimates NaCl's freezing "
                      "point depression); crc_nacl, NaCl's measured freezing points (CRC Handbook) to its eutectic, "
                      "-21.1 °C at 23.3 %, below which brine freezes through, with NaCl's solubility "
                      "26.3 %; table, liquidus_table")
                      .def("blagden"),
                  array_of("liquidus_table",
                           {number("mass_fraction", "kg of it per kg of melt").above(0).below(1),
                            number("depression", "How far below the water's melting point that melt freezes")
                                .in("K")
                                .above(0)
                                .at_most(200)},
                           "Measured points of the liquidus, rising; the last is the eutectic, past which no "
                           "melt stays liquid. Between points the slope depression / mass_fraction is "
                           "interpolated linearly")
                      .at_most(THAW_LIQUIDUS_POINTS)
                      .when("liquidus", "table"),
                  number("solubility",
                         "The most a melt dissolves, kg of it per kg of solution (NaCl 0.263); more stays "
                         "undissolved with the particle that holds it and dissolves as water comes. 0: "
                         "unlimited, or NaCl's with crc_nacl")
                      .def(0.0)
                      .at_least(0)
                      .below(1),
                  flag("enters_ice",
                       "Whether water that freezes keeps it; false (salt, dye): the freezing water gives "
                       "it up to the water around it")
                      .def(false),
                  text("colour",
                       "The colour it gives the water in the surface view coloured by it (and a coating's "
                       "stain on solids and ice), as #rrggbb: what white light looks like through a thick "
                       "layer of it. Empty: red, blue, green or amber by its place among the scene's "
                       "substances")
                      .def(""),
                  choice("kind", choice_names<SubstanceKind>(),
                         "bulk: it stays dissolved in the water; surface_active (a detergent): it also "
                         "gathers on the water's free surface, adsorbing from and desorbing to the water "
                         "under it and diffusing along the surface (Orthmann et al. 2013 sec. 5-6.2); "
                         "coating (paint, a staining dye, grease): it also sticks to the solids and ice "
                         "the water touches, and a cleanser takes it back (sec. 6.3-6.4)")
                      .def("bulk"),
                  choice(
                      "tension_law", choice_names<TensionLaw>(),
                      "How it lowers the water's surface tension where the surface holds it (where "
                      "tension.model is on): szyszkowski, sigma0 + E ln(1 - Gamma / Gamma_max) (Langmuir's "
                      "equation of state); linear, sigma0 - E Gamma / Gamma_max; none")
                      .def("szyszkowski")
                      .when("kind", "surface_active"),
                  number(
                      "tension_scale",
                      "E in the tension law: R T Gamma_inf, Gamma_inf the surface's capacity in mol/m^2 (SDS "
                      "at 25 °C: 7.9e-3)")
                      .in("N/m")
                      .def(7.9e-3)
                      .at_least(0)
                      .at_most(1)
                      .when("kind", "surface_active"),
                  number("coating_rate",
                         "k_c in dGamma_R/dt = k_c c (1 - Gamma_R / Gamma_R,max) - k_r c_D Gamma_R: the "
                         "speed at which it deposits from the water onto a solid or ice surface")
                      .in("m/s")
                      .def(1e-5)
                      .at_least(0)
                      .at_most(1)
                      .when("kind", "coating"),
                  number("coating_capacity", "Gamma_R,max, the most that sticks per area; 0: no limit")
                      .in("kg/m^2")
                      .def(1e-4)
                      .at_least(0)
                      .at_most(1)
                      .when("kind", "coating"),
                  text("cleansed_by",
                       "The substance (a detergent) whose concentration c_D in the water takes the deposit "
                       "back into the water; empty: none")
                      .def("")
                      .when("kind", "coating"),
                  number("cleansing_rate", "k_r, the rate of cleansing per concentration of the cleanser")
                      .in("m^3/(kg s)")
                      .def(0.0)
                      .at_least(0)
                      .at_most(1e6)
                      .when("kind", "coating"),
                  number("surface_diffusivity", "Its diffusivity D_s along the free surface")
                      .in("m^2/s")
                      .def(1e-9)
                      .at_least(0)
                      .at_most(1e-2)
                      .when("kind", "surface_active"),
                  number("adsorption_rate",
                         "k_a in Langmuir's dGamma/dt = k_a c (1 - Gamma / Gamma_max) - k_d Gamma: the "
                         "speed at which the surface takes it from the water under it")
                      .in("m/s")
                      .def(1e-4)
                      .at_least(0)
                      .at_most(1)
                      .when("kind", "surface_active"),
                  number("desorption_rate", "k_d: the rate at which the surface gives it back to the water")
                      .in("1/s")
                      .def(0.1)
                      .at_least(0)
                      .at_most(1e4)
                      .when("kind", "surface_active"),
                  number("surface_capacity",
                         "Gamma_max, the most the surface holds per area (a detergent such as SDS: about "
                         "1.2e-6); 0: no limit (Henry's law)")
                      .in("kg/m^2")
                      .def(1.2e-6)
                      .at_least(0)
                      .at_most(1)
                      .when("kind", "surface_active"),
              },
              "Substances the water carries (docs/SUBSTANCES.md), at most 4: each water particle holds "
              "its amount of each, which moves with it and diffuses to the water around it; fluids' "
              "`substances` say where they start")
              .def(Json::object()),
          map_of("materials", "<name>",
                 {
                     choice("kind", choice_names<MaterialKind>(),
                            "Fluid particles move; solids are static boundaries; ice is rigid (held where it "
                            "starts with motion fixed, a floating body with motion free) and melts into its "
                            "melts_into fluid; air is a gas that flows and carries heat (the `air` fill)"),
                     number("density",
                            "Rest density; 0.01 is below any real gas (1e-300 gave particles no mass)")
                         .in("kg/m^3")
                         .at_least(0.01)
                         .at_most(1e5),
                     number("viscosity", "Dynamic viscosity (fluids)").in("Pa s").def(0.0).at_least(0),
                     number("conductivity", "Thermal conductivity k").in("W/m/K").at_least(0).at_most(1e4),
                     number("specific_heat", "Specific heat capacity c; real materials have 100 or more")
                         .in("J/kg/K")
                         .at_least(1)
                         .at_most(1e6),
                     flag("transparent",
                          "Drawn as glass: clear and slightly tinted, with Fresnel reflection, so what it "
                          "holds shows through (solids; rendering only)")
                         .def(false)
                         .when("kind", "solid"),
                     flag("adiabatic",
                          "An ideal insulator: no heat crosses its surface, and the fluid or ice beside it "
                          "conducts along it as in bulk (its particles take the temperature and conductivity "
                          "of what is around them, the heat that takes booked as `held`); conductivity is "
                          "then unused. A solid of conductivity 0 insulates too, but the conduction along "
                          "it runs short of neighbours within a kernel's reach (solids)")
                         .def(false)
                         .when("kind", "solid"),
                     number("cryoscopic_constant",
                            "K_f of a fluid: how far a mole of dissolved particles per kg lowers its melting "
                            "point (substances with a molar_mass); water 1.86")
                         .in("K kg/mol")
                         .def(1.86)
                         .at_least(0)
                         .at_most(100)
                         .when("kind", "fluid"),
                     text("melts_into", "The fluid material this ice becomes; it freezes back into this ice")
                         .when("kind", "ice"),
                     number("latent_heat", "Latent heat of fusion L")
                         .in("J/kg")
                         .def(334000.0)
                         .above(0)
                         .at_most(1e8)
                         .when("kind", "ice"),
                     number("melting_point", "Melting temperature T_m")
                         .in("°C")
                         .def(0.0)
                         .above(-273.15)
                         .at_most(3000)
                         .when("kind", "ice"),
                 },
                 "Materials by name; objects refer to them by name.")
              .non_empty(),
          array_of("fluids",
                   shaped_entry(
                       choice("shape", {"box", "sphere", "cylinder", "cone", "capsule", "mesh"},
                              "What the fluid fills: an axis-aligned box (turned by rotation), a sphere (a "
                              "drop), a cylinder, a cone, a capsule or a mesh file")
                           .def("box"),
                       text("material", "Name of a fluid material"),
                       "Filled with particles on a lattice of the scene's spacing",
                       {
                           vec3("velocity", "Initial velocity").in("m/s").def({0.0, 0.0, 0.0}),
                           number("temperature", "Initial temperature; default ambient.temperature")
                               .in("°C")
                               .above(-273.15)
                               .at_most(3000)
                               .optional(),
                           dissolved_substances("Substances dissolved in this fluid at the start"),
                       }),
                   "Bodies of fluid particles (lattice points inside solids, ice or earlier fluid are left "
                   "out).")
              .def(Json::array()),
          object(
              "air",
              {
                  text("material", "Name of an air material"),
                  box_field("region", "Filled with air; default the whole domain").optional(),
                  number("temperature", "Initial temperature; default ambient.temperature")
                      .in("°C")
                      .above(-273.15)
                      .at_most(3000)
                      .optional(),
                  choice("buoyancy", choice_names<Buoyancy>(),
                         "boussinesq: warm air rises, feeling -beta (T - T0) g (its own weight is left to a "
                         "hydrostatic pressure of a few pascals); ideal_gas: Domaradzki & Martyn's eq 7, "
                         "each particle's rest density rho0 (1 + theta T0) / (1 + theta T) follows its "
                         "temperature: warm air expands, and rises by its weight less that of air at T0 "
                         "(needs solver.pressure dfsph); "
                         "none: air feels no gravity")
                      .def("boussinesq"),
                  number("theta",
                         "ideal_gas: eq 7's theta, how fast the rest density falls with temperature; "
                         "1/273.15 K is the ideal gas (Charles's law), the paper chose 0.005 by experiment")
                      .in("1/K")
                      .def(1.0 / 273.15)
                      .above(0)
                      .at_most(0.01),
                  number("reference_temperature",
                         "T0, where air has its rest density; default its temperature")
                      .in("°C")
                      .above(-273.15)
                      .at_most(3000)
                      .optional(),
                  number("expansion",
                         "Thermal expansion coefficient beta; default 1 / (T0 + 273.15 K), an "
                         "ideal gas's")
                      .in("1/K")
                      .at_least(0)
                      .at_most(1)
                      .optional(),
                  number("artificial_buoyancy",
                         "sigma of Domaradzki & Martyn's artificial force (eq 8): every air particle also "
                         "feels sigma / (max_temperature - T) upward, per unit mass (T_max - T no less than "
                         "1 K). 0: off, the default; the paper added it where its eq 7 rose too slowly, for "
                         "comparison with Boussinesq buoyancy")
                      .in("K m/s^2")
                      .def(0.0)
                      .at_least(0)
                      .at_most(1e6),
                  number("max_temperature", "T_max of eq 8, the highest temperature the scene allows")
                      .in("°C")
                      .def(100.0)
                      .above(-273.15)
                      .at_most(3000),
                  number("face_exchange_time",
                         "Air within face_exchange_depth of a side of the domain that is not periodic "
                         "relaxes toward heat.ambient_temperature with this time constant, as if the room "
                         "went on beyond it (Domaradzki & Martyn sec. 7); booked as ambient exchange. 0: "
                         "off")
                      .in("s")
                      .def(0.0)
                      .at_least(0)
                      .at_most(1e6),
                  number("face_exchange_depth",
                         "How far from the sides the exchange reaches; 0: one kernel support")
                      .in("m")
                      .def(0.0)
                      .at_least(0)
                      .at_most(100),
              },
              "Air as particles (Domaradzki & Martyn sec. 6): the domain, or a region of it, filled with an "
              "air material on the particle lattice, except where fluid, ice or solids are. Warm air rises; "
              "heat crosses it by conduction and is carried with it.")
              .optional(),
          array_of(
              "ice",
              shaped_entry(
                  choice("shape", {"box", "sphere", "cylinder", "cone", "capsule", "mesh"},
                         "What the ice fills: an axis-aligned box (turned by rotation), a sphere, a "
                         "cylinder, a cone, a capsule or a mesh file")
                      .def("box"),
                  text("material", "Name of an ice material"),
                  "The block, filled with particles on a lattice of the scene's spacing",
                  {
                      choice("motion", {"fixed", "free"},
                             "fixed: held where it starts (its particles are anchored); free: moves as one "
                             "rigid body")
                          .def("fixed"),
                      number("temperature",
                             "Initial temperature, at most the melting point; default "
                             "ambient.temperature or the melting point, whichever is lower")
                          .in("°C")
                          .above(-273.15)
                          .at_most(3000)
                          .optional(),
                  }),
              "Pieces of ice of any shape, sampled on the particle lattice (lattice points inside solids or "
              "earlier ice are left out); they melt into water.")
              .def(Json::array()),
          array_of(
              "solids",
              shaped_entry(
                  choice("shape", {"box", "sphere", "cylinder", "cone", "capsule", "mesh", "plane"},
                         "Solid of one of the ice shapes, or the half-space behind a plane"),
                  text("material", "Name of a solid material"), "The solid block",
                  {
                      vec3("point", "A point on the plane").in("m").when("shape", "plane"),
                      vec3("normal", "Plane normal, pointing into the fluid; need not be unit length")
                          .when("shape", "plane"),
                      number("temperature", "Initial temperature; default ambient.temperature")
                          .in("°C")
                          .above(-273.15)
                          .at_most(3000)
                          .optional(),
                      flag("hold_temperature",
                           "Hold the solid at its temperature, like a heater or a cooling plate; the heat "
                           "that takes is reported as `held` in the energy budget")
                          .def(false),
                      map_of("deposits", "<substance>",
                             {
                                 number("deposit", "Mass of it per area of the solid's surface")
                                     .in("kg/m^2")
                                     .at_least(0)
                                     .at_most(1),
                             },
                             "What sticks to its surface at the start (a dirty plate's grease), by the name "
                             "the scene's `substances` gives a coating")
                          .def(Json::object()),
                  }),
              "Static solids, sampled as boundary particles as deep as the kernel reaches; they conduct "
              "heat.")
              .def(Json::array()),
          array_of(
              "lamps",
              {
                  flag("on", "Emitting").def(true).live_in_place(),
                  vec3("centre", "Centre of the emitting rectangle").in("m").live_in_place(),
                  vec3("normal", "The way the emitting face looks; need not be unit length").live_in_place(),
                  number("width", "Extent of the rectangle across the normal (horizontal where it can be)")
                      .in("m")
                      .above(0)
                      .at_most(100),
                  number("height", "Extent of the rectangle along the third axis")
                      .in("m")
                      .above(0)
                      .at_most(100),
                  number("temperature", "Emitter temperature T_s")
                      .in("°C")
                      .above(-273.15)
                      .at_most(3000)
                      .live_in_place(),
                  number("emissivity", "Emissivity factor").def(0.9).above(0).at_most(1).live_in_place(),
                  integer("photons", "Thermal photons emitted per step")
                      .def(4096)
                      .at_least(1)
                      .at_most(1 << 22),
              },
              "Radiant heaters, as thermal photons traced through the ice and solids (Iwasaki et al. 2010 "
              "sec. 4 and 6): the first ice or solid voxel a photon meets absorbs it.")
              .def(Json::array())
              .at_most(kMaxAddressable),
          array_of(
              "dryers",
              {
                  choice("model", choice_names<DryerModel>(),
                         "cone: an analytic cone of warm air heats the exposed ice and water inside it "
                         "(scenes without air particles); air: the nozzle blows air particles at `speed` "
                         "and `temperature` and draws in the air behind it (scenes with `air`)")
                      .def("cone"),
                  flag("on", "Blowing").def(true).live_in_place(),
                  vec3("position", "Nozzle position").in("m").live_in_place(),
                  vec3("direction", "Where the air blows; need not be unit length").live_in_place(),
                  number("half_angle", "Half-angle of the cone of warm air (model cone)")
                      .in("deg")
                      .def(15.0)
                      .above(0)
                      .at_most(60)
                      .live_in_place(),
                  number("reach", "Length of the cone; nothing beyond it feels the dryer (model cone)")
                      .in("m")
                      .def(0.3)
                      .above(0)
                      .at_most(10)
                      .live_in_place(),
                  number("temperature", "Air temperature at the nozzle")
                      .in("°C")
                      .def(60.0)
                      .above(-100)
                      .at_most(500)
                      .live_in_place(),
                  number("speed", "Air speed at the nozzle")
                      .in("m/s")
                      .def(10.0)
                      .at_least(0)
                      .at_most(100)
                      .live_in_place(),
                  number("nozzle_diameter",
                         "cone: sets the jet's core length (6 diameters) and the length scale of its "
                         "heat-transfer coefficient; air: the nozzle the particles leave through")
                      .in("m")
                      .def(0.04)
                      .above(0)
                      .at_most(1),
              },
              "Hair dryers: without air particles a cone of warm, fast air that heats the exposed surface "
              "inside it (sim/kernels/dryer_model.h has the model); with `air`, a nozzle that blows warm air "
              "particles (model air, sim/emitters.h).")
              .def(Json::array())
              .at_most(kMaxAddressable),
          array_of(
              "emitters",
              {
                  flag("open", "The tap: pouring while open (between start and stop)")
                      .def(true)
                      .live_in_place(),
                  text("material", "Name of the fluid material poured"),
                  vec3("position", "Centre of the nozzle").in("m").live_in_place(),
                  vec3("direction", "Where the fluid leaves the nozzle; need not be unit length")
                      .def({0.0, 0.0, -1.0})
                      .live_in_place(),
                  number("radius",
                         "Radius of the nozzle; at least one particle spacing, its disc inside the domain "
                         "and clear of solids and ice")
                      .in("m")
                      .def(0.005)
                      .above(0)
                      .at_most(1)
                      .live_in_place(),
                  number("speed", "Exit speed; default 0.5 m/s unless rate is given")
                      .in("m/s")
                      .above(0)
                      .at_most(50)
                      .optional()
                      .live_in_place(),
                  number("rate", "Volume flow instead of speed: the exit speed is rate / (pi radius^2)")
                      .in("L/s")
                      .above(0)
                      .at_most(1000)
                      .optional()
                      .live_in_place(),
                  number("temperature", "Temperature of the fluid poured; default ambient.temperature")
                      .in("°C")
                      .above(-273.15)
                      .at_most(3000)
                      .optional()
                      .live_in_place(),
                  dissolved_substances(
                      "Substances dissolved in the fluid poured (fixed while the scene runs)"),
                  number("start", "Pours from this time on").in("s").def(0.0).at_least(0).live_in_place(),
                  number("stop", "Stops pouring at this time; 0: never")
                      .in("s")
                      .def(0.0)
                      .at_least(0)
                      .live_in_place(),
              },
              "Nozzles that pour fluid (Iwasaki et al. 2010, Fig. 7): layers of particles on the nozzle's "
              "disc leave it along the direction at the exit speed, spaced so that the mass flow is "
              "rho pi radius^2 speed. A tap a client can open and close (`emitter.set`).")
              .def(Json::array())
              .at_most(kMaxAddressable),
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
JSON is taken as a string). Fields with an entry in the *live* column may also be changed by a connected
client while the simulation runs (`param.set`): *in place* between two steps, as `dryer.set` does; *rebuild*
by rebuilding the simulation from the particles as they are.

Checked across fields:
- `domain.max` is above `domain.min` on every axis, and so is every box's `max` above its `min`;
- `spacing` is smaller than the smallest extent of the domain, and the scene stays below 20 million
  particles (an estimate from the fluid blocks and the walls);
- a fluid block's material is a fluid, a solid's and the walls' material is a solid, and every
  material name is defined in `materials`;
- `domain.wall_material` is given when `domain.walls` is not empty;
- fluid blocks and the bounding boxes of ice lie inside the domain; plane normals, lamp normals and dryer
  directions are not zero; the scene has at least one fluid or ice block;
- an ice or solid entry has exactly the fields its `shape` takes (below); a cylinder's, cone's or
  capsule's `to` differs from its `from`; a mesh file is found, reads, and has triangles;
- an ice material's `melts_into` names a fluid, and no two ice materials melt into the same fluid; ice
  starts at or below its melting point, and a fluid that freezes starts at or above it;
- `solver.min_dt` is below `solver.max_dt`;
- `solver.periodic` axes have no walls and no open sides, and a domain at least three kernel supports long
  along them; with `solver.flow` only y and z can be periodic (particles that leave through one side come
  back through the other), and ice is fixed.

Temperatures are in °C. Each particle carries its specific enthalpy; an ice particle turns to water when
it has taken its whole latent heat, and water freezes when it has given it all back
(`sim/kernels/thermal_law.h`).

## Shapes

Ice and solids take a `shape`, with these fields:

)";

// What each shape is, for the table in docs/SCENES.md; its fields come from the declarations.
constexpr std::pair<const char*, const char*> kShapeMeaning[] = {
    {"box", "the box, turned about its centre; ice's default shape"},
    {"sphere", "the ball of `radius` about `centre`"},
    {"cylinder", "flat ends at `from` and `to`"},
    {"cone", "base circle at `from`, apex at `to`: an icicle runs from root to tip"},
    {"capsule", "the points within `radius` of the segment"},
    {"mesh",
     "an OBJ, STL or PLY file, turned by `rotation`, scaled so that the largest side of its bounding box "
     "is `size`, moved so that the box's centre is at `centre`"},
    {"plane", "the half-space behind the plane (solids only)"},
};

constexpr const char* kShapes = R"(
`rotation` is in degrees about x, then y, then z, and defaults to none. An axis-aligned box is filled
with the lattice points `min + (i + 1/2) spacing` of its own corner and keeps its whole cells, as blocks
always have; every other shape takes the points `domain.min + (i + 1/2) spacing` that lie inside it, so
it meets water sampled on that lattice a spacing apart. Inside a mesh is where its generalized winding number exceeds 1/2
(Jacobson et al. 2013), so a mesh with small holes still fills. Ice leaves out lattice points inside
solids and earlier ice; fluids leave out points inside solids and ice; solids are sampled only as deep as
the walls (`domain.wall_layers`). Ice is `fixed` (held where it starts; its particles are anchored) or
`free`: each connected piece of ice is a rigid body that the water and contacts move, fixed when any of
its particles is anchored; a piece that melting cuts loose becomes a body of its own, and bodies that
come to touch stay apart. Shipped meshes live in `configs/meshes/`.

Floating ice that must turn under small torques (a block righting itself, a narrow one capsizing) or
rise through water needs `"solver": {"kernel": "wendland_c2", "support_ratio": 3.0}`. With the default
cubic spline over 2 spacings the water holds it like a jelly: it stops a few degrees into the turn (the
`floating` case in docs/VALIDATION-RESULTS.md), and a 2 cm ice cube let go 4 cm under water rises
0.5 mm in 0.3 s (2.5 mm spacing), where with Wendland it has risen 5.8 mm and moves at 29 mm/s.
Wendland costs more per step and its walls take 4 layers instead of 2, but its steps are longer: the
`ice-bunny` scene took 335 s of wall time for 1.5 s (56,698 particles, 11,448 steps) against 243 s with
the cubic spline (40,232 particles, 17,143 steps).

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
    "water": {"kind": "fluid", "density": 1000, "viscosity": 1.0e-3, "conductivity": 0.56, "specific_heat": 4217},
    "ice": {"kind": "ice", "density": 917, "conductivity": 2.22, "specific_heat": 2050, "melts_into": "water"},
    "glass": {"kind": "solid", "density": 2500, "conductivity": 1.0, "specific_heat": 840},
    "steel": {"kind": "solid", "density": 7850, "conductivity": 45, "specific_heat": 490}
  },
  "ambient": {"temperature": 20, "heat_transfer_coefficient": 10},
  "fluids": [{"material": "water", "box": {"min": [0, 0, 0], "max": [0.2, 0.2, 0.3]}, "temperature": 15}],
  "ice": [{"material": "ice", "box": {"min": [0.4, 0.05, 0.1], "max": [0.45, 0.1, 0.15]}, "temperature": -10}],
  "solids": [{"shape": "box", "material": "steel", "box": {"min": [0.4, 0.05, 0], "max": [0.45, 0.15, 0.1]}}],
  "dryers": [{"position": [0.55, 0.075, 0.3], "direction": [-1, 0, -1], "temperature": 60, "speed": 10}]
}
)";

// One row per shape: the fields the solids' declarations tie to it (solids take every shape).
std::string shapes_table() {
  const Field& entry = *find_field(scene_schema(), "solids[0]");
  std::string table = "| shape | fields | the volume |\n|---|---|---|\n";
  for (const auto& [shape, meaning] : kShapeMeaning) {
    std::string fields;
    for (const Field& f : entry.fields) {
      bool takes = f.when_key == "shape" && f.when_value == shape;
      for (const SharedShapeField& shared : shared_shape_fields())
        takes = takes || (shared.key == f.key && std::find(shared.shapes.begin(), shared.shapes.end(),
                                                           shape) != shared.shapes.end());
      if (takes) fields += (fields.empty() ? "`" : ", `") + f.key + "`";
    }
    table += "| `" + std::string(shape) + "` | " + fields + " | " + meaning + " |\n";
  }
  return table;
}

}  // namespace

std::string scene_example_json() { return kExample; }

std::string scene_reference_markdown() {
  return std::string(kIntro) + shapes_table() + kShapes + kExample + "```\n\n" +
         schema_markdown(scene_schema(), "Reference: top level");
}

}  // namespace thaw
