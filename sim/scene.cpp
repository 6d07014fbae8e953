// Loading a scene: file lookup, JSON reading, `--set` overrides, the checks that span several fields,
// and the conversion of the validated document into the typed Scene. The fields themselves are
// declared in sim/scene_schema.cpp.
#include "sim/scene.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "sim/error.h"
#include "sim/geometry/mesh.h"
#include "sim/json_text.h"
#include "sim/kernels/tension_params.h"

namespace thaw {

std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

namespace {
// A choice the schema has already checked, as its enum.
template <Choice E>
E choice_of(const Json& value) {
  const std::string text = value.get<std::string>();
  for (const auto& [e, spelling] : Choices<E>::names)
    if (text == spelling) return e;
  throw Error("'" + text + "' is not one of the choices (the schema should have refused it)");
}
}  // namespace

namespace {

// A substance's colour from "#rrggbb"; empty: the index-th of red, blue, green and amber, so the scene's
// substances differ without being told.
std::array<float, 3> substance_colour(const std::string& text, std::size_t index, const std::string& path) {
  static constexpr std::array<std::array<float, 3>, 4> kPalette = {
      {{0.78f, 0.08f, 0.30f}, {0.10f, 0.30f, 0.85f}, {0.10f, 0.62f, 0.22f}, {0.85f, 0.55f, 0.10f}}};
  if (text.empty()) return kPalette[index % kPalette.size()];
  const bool hex = text.size() == 7 && text[0] == '#' &&
                   std::all_of(text.begin() + 1, text.end(), [](char c) { return std::isxdigit(c) != 0; });
  if (!hex) throw SceneError(path, "expected a colour as #rrggbb, e.g. #c8144c, got '" + text + "'");
  std::array<float, 3> rgb{};
  for (std::size_t c = 0; c < 3; ++c)
    rgb[c] = float(std::stoi(text.substr(1 + 2 * c, 2), nullptr, 16)) / 255.0f;
  return rgb;
}

// A sanity limit: beyond this a typo in `spacing` would exhaust memory before any error appears.
constexpr double kMaxParticles = 20e6;
constexpr std::array<char, 3> kAxis = {'x', 'y', 'z'};

// 25000000 -> "25,000,000": particle counts are read by people deciding on a spacing.
std::string format_count(double v) {
  // Past a long long (a spacing of 1e-9 m asks for ~1e21 particles): three digits and an exponent.
  if (!(std::abs(v) < 1e15)) {
    std::ostringstream s;
    s.precision(3);
    s << v;
    return s.str();
  }
  std::string digits = std::to_string(static_cast<long long>(std::llround(v)));
  for (int i = static_cast<int>(digits.size()) - 3; i > 0; i -= 3)
    digits.insert(static_cast<std::size_t>(i), ",");
  return digits;
}

Eigen::Vector3d vec(const Json& v) { return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()}; }

Box box(const Json& v) { return {vec(v["min"]), vec(v["max"])}; }

void check_box(const Box& b, const std::string& path, const std::string& what) {
  for (int a = 0; a < 3; ++a) {
    if (b.max[a] <= b.min[a]) {
      throw SceneError(path, what + ": max must be above min on every axis, but " + kAxis[a] + " runs from " +
                                 format_number(b.min[a]) + " m to " + format_number(b.max[a]) + " m");
    }
  }
}

void check_inside(const Box& domain, const Box& b, const std::string& path) {
  for (int a = 0; a < 3; ++a) {
    if (b.min[a] < domain.min[a] || b.max[a] > domain.max[a]) {
      throw SceneError(
          path, std::string("lies outside the domain along ") + kAxis[static_cast<std::size_t>(a)] + ": " +
                    format_number(b.min[a]) + " m to " + format_number(b.max[a]) + " m, the domain spans " +
                    format_number(domain.min[a]) + " m to " + format_number(domain.max[a]) + " m");
    }
  }
}

std::string names_of(const Json& materials, const std::string& kind) {
  std::string out;
  for (const auto& [name, m] : materials.items()) {
    if (kind.empty() || m["kind"] == kind) out += (out.empty() ? "" : ", ") + name;
  }
  return out.empty() ? "none" : out;
}

// Index of a material in document order, checked to be of the wanted kind.
int material_index(const Json& materials, const Json& name_value, const std::string& path,
                   const std::string& kind, const std::string& user) {
  const std::string name = name_value.get<std::string>();
  int index = 0;
  for (const auto& [defined, m] : materials.items()) {
    if (defined == name) {
      if (m["kind"] != kind) {
        throw SceneError(path, "material '" + name + "' is a " + m["kind"].get<std::string>() + "; " + user +
                                   " needs a " + kind + " (" + kind +
                                   " materials: " + names_of(materials, kind) + ")");
      }
      return index;
    }
    ++index;
  }
  throw SceneError(path, "unknown material '" + name + "'; defined: " + names_of(materials, ""));
}

// Fluid lattices plus boundary particles: enough to stop a spacing typo, not a promise of the count.
double estimated_particles(const Scene& s, double wall_layers) {
  const double h = s.spacing;
  const Eigen::Vector3d extent = s.domain.max - s.domain.min;
  auto lattice_count = [h](const Box& b) { return ((b.max - b.min) / h).array().floor().prod(); };
  double n = 0.0;
  for (const FluidBlock& f : s.fluids) n += lattice_count(f.box);
  if (s.has_air()) n += lattice_count(s.air.region);
  for (const IceBlock& f : s.ice)
    n += f.shape.axis_aligned_box() ? lattice_count(f.box) : f.shape.volume() / (h * h * h);
  const double face_area[3] = {extent.y() * extent.z(), extent.x() * extent.z(), extent.x() * extent.y()};
  for (const std::string& side : s.walls) n += face_area[side[1] - 'x'] * wall_layers / (h * h);
  for (const Solid& solid : s.solids) {
    if (solid.plane) {
      n += *std::max_element(face_area, face_area + 3) * wall_layers / (h * h);
    } else {
      const Eigen::Vector3d e = solid.box.max - solid.box.min;
      const double shell = 2.0 * (e.x() * e.y() + e.y() * e.z() + e.x() * e.z()) * wall_layers / (h * h);
      n += std::min(shell, e.prod() / (h * h * h));
    }
  }
  return n;
}

bool listed(const std::vector<std::string>& items, const std::string& item) {
  return std::find(items.begin(), items.end(), item) != items.end();
}

// "'sphere', 'cylinder' or 'cone'"
std::string one_of(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i)
    out += (i == 0 ? "" : i + 1 == items.size() ? " or " : ", ") + ("'" + items[i] + "'");
  return out;
}

// The fields that several shapes share are optional in the schema; here they are held to their shapes.
void check_shared_shape_fields(const Json& entry, const std::string& path) {
  const std::string shape = entry["shape"].get<std::string>();
  for (const SharedShapeField& f : shared_shape_fields()) {
    const bool wanted = listed(f.shapes, shape);
    if (entry.contains(f.key) && !wanted)
      throw SceneError(join_path(path, f.key), "only allowed when shape is " + one_of(f.shapes));
    if (!entry.contains(f.key) && wanted && f.required)
      throw SceneError(join_path(path, f.key), "missing: required when shape is '" + shape + "'");
  }
}

// A mesh file: as written when absolute, else in the scene's folder, else in configs/ of the source tree.
std::string resolve_mesh_path(const std::string& name, const std::string& folder, const std::string& path) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates = {fs::path(name)};
  if (!fs::path(name).is_absolute())
    candidates = {fs::path(folder) / name, fs::path(THAW_SOURCE_DIR) / "configs" / name};
  std::string looked;
  for (const fs::path& p : candidates) {
    std::error_code ec;
    const fs::path full = fs::absolute(p, ec).lexically_normal();
    if (fs::exists(full, ec)) return full.string();
    if (looked.find(full.string()) == std::string::npos)
      looked += (looked.empty() ? "" : ", ") + full.string();
  }
  throw SceneError(path, "mesh file '" + name + "' not found; looked for " + looked);
}

// The shape of an ice or solid entry that has passed validation (any shape but "plane"). A mesh's path
// is replaced in `entry` by the file it was found at, so the scene's source reloads from anywhere.
Shape shape_of(Json& entry, const std::string& path, const std::string& folder) {
  check_shared_shape_fields(entry, path);
  const std::string kind = entry["shape"].get<std::string>();
  const Eigen::Matrix3d rotation = entry.contains("rotation") ? rotation_from_degrees(vec(entry["rotation"]))
                                                              : Eigen::Matrix3d::Identity();
  if (kind == "box") {
    const Box b = box(entry["box"]);
    check_box(b, path + ".box", "empty box");
    return Shape::box(b.min, b.max, rotation);
  }
  if (kind == "sphere") return Shape::sphere(vec(entry["centre"]), entry["radius"].get<double>());
  if (kind == "mesh") {
    const std::string file = resolve_mesh_path(entry["mesh"].get<std::string>(), folder, path + ".mesh");
    entry["mesh"] = file;
    try {
      return Shape::mesh(
          place_mesh(load_mesh(file), rotation, vec(entry["centre"]), entry["size"].get<double>()));
    } catch (const Error& e) {
      throw SceneError(path + ".mesh", e.what());
    }
  }
  const Eigen::Vector3d from = vec(entry["from"]), to = vec(entry["to"]);
  if (from == to) throw SceneError(path + ".to", "equals from: the " + kind + " has no length");
  const double radius = entry["radius"].get<double>();
  if (kind == "cylinder") return Shape::cylinder(from, to, radius);
  if (kind == "cone") return Shape::cone(from, to, radius);
  return Shape::capsule(from, to, radius);
}

Box box_of(const Shape& shape) { return {shape.bounds().min(), shape.bounds().max()}; }

// Checks that span several fields; `doc` has passed validation, so every field is present and typed.
// `folder` is where relative mesh paths are looked for first.
// ---- one converter per scene struct (lamps, dryers, emitters and the solver settings have theirs below,
// being live or read on their own) ----------------------------------------------------------------------

Material material_from_json(const std::string& name, const Json& m) {
  Material mat;
  mat.name = name;
  mat.kind = choice_of<MaterialKind>(m["kind"]);
  mat.density = m["density"].get<double>();
  mat.viscosity = m["viscosity"].get<double>();
  mat.conductivity = m["conductivity"].get<double>();
  mat.specific_heat = m["specific_heat"].get<double>();
  mat.transparent = m.contains("transparent") && m["transparent"].get<bool>();  // solids only
  mat.adiabatic = m.contains("adiabatic") && m["adiabatic"].get<bool>();        // solids only
  if (m.contains("cryoscopic_constant")) mat.cryoscopic_constant = m["cryoscopic_constant"].get<double>();
  return mat;
}

// Heat, from the document's heat, ambient and domain.wall_heat blocks.
HeatSettings heat_settings_from_json(const Json& doc) {
  HeatSettings h;
  h.enabled = doc["heat"]["enabled"].get<bool>();
  h.time_scale = doc["heat"]["time_scale"].get<double>();
  h.max_substeps = doc["heat"]["max_substeps"].get<int>();
  h.exposed_area = choice_of<ExposedArea>(doc["heat"]["exposed_area"]);
  h.area_interval = doc["heat"]["area_interval"].get<int>();
  h.ambient_temperature = doc["ambient"]["temperature"].get<double>();
  h.ambient_coefficient = doc["ambient"]["heat_transfer_coefficient"].get<double>();
  h.wall_coefficient = doc["domain"]["wall_heat"]["coefficient"].get<double>();
  h.wall_temperature = doc["domain"]["wall_heat"]["temperature"].get<double>();
  return h;
}

TensionSettings tension_settings_from_json(const Json& t) {
  TensionSettings s;
  s.model = choice_of<TensionModel>(t["model"]);
  s.coefficient = t["coefficient"].get<double>();
  s.curvature = t["curvature"].get<bool>();
  s.solid_contact_angle = t["solid_contact_angle"].get<double>();
  s.ice_contact_angle = t["ice_contact_angle"].get<double>();
  return s;
}

double temperature_or(const Json& object, double fallback) {
  return object.contains("temperature") ? object["temperature"].get<double>() : fallback;
}

// Phase-changing materials start on their own side of the melting point (no supercooled water here).
// A fluid holding `concentrations` of the scene's substances freezes that much lower (the melting point
// drop the substance stage gives it, docs/SUBSTANCES.md).
void check_start(const Scene& s, int material, double T, const std::string& path,
                 const std::vector<double>& concentrations = {}) {
  const Material& m = s.materials[static_cast<std::size_t>(material)];
  if (m.partner < 0) return;
  if (m.kind == MaterialKind::Ice && T > m.melting_point)
    throw SceneError(path, format_number(T) + " °C is above the melting point of '" + m.name + "' (" +
                               format_number(m.melting_point) + " °C)");
  const double drop = melting_point_drop(s, material, concentrations);
  if (m.kind == MaterialKind::Fluid && T < m.melting_point - drop)
    throw SceneError(path, format_number(T) + " °C is below the freezing point of '" + m.name + "' (" +
                               format_number(m.melting_point - drop) + " °C" +
                               (drop > 0 ? " with what is dissolved in it" : "") +
                               "); supercooled fluid is not modelled");
}

// A substance's liquidus and solubility from its entry `d` at `path`: CRC's NaCl table and solubility (which
// `solubility` may override), or the scene's own table, checked to rise and to stay a rising curve between
// its points as liquidus.h interpolates it.
void liquidus_from_json(Substance& sub, const Json& d, const std::string& path) {
  sub.liquidus = choice_of<LiquidusLaw>(d["liquidus"]);
  sub.solubility = d["solubility"].get<double>();
  if (sub.liquidus == LiquidusLaw::CrcNaCl) {
    sub.liquidus_points.assign(kCrcNaCl.begin(), kCrcNaCl.end());
    if (sub.solubility == 0) sub.solubility = kCrcNaClSolubility;
  }
  if (sub.liquidus != LiquidusLaw::Table) return;
  const std::string at = path + ".liquidus_table";
  if (!d.contains("liquidus_table") || d["liquidus_table"].empty())
    throw SceneError(at,
                     "a table liquidus needs its points: [{\"mass_fraction\": w, \"depression\": K}, ...], "
                     "the last the eutectic");
  double w0 = 0, d0 = 0;
  for (std::size_t p = 0; p < d["liquidus_table"].size(); ++p) {
    const Json& point = d["liquidus_table"][p];
    const double w = point["mass_fraction"].get<double>(), dep = point["depression"].get<double>();
    const std::string here = join_path(at, p);
    if (!(w > w0) || !(dep > d0))
      throw SceneError(here, "the points must rise in mass_fraction and in depression (" + format_number(w) +
                                 ", " + format_number(dep) + " K after " + format_number(w0) + ", " +
                                 format_number(d0) + " K)");
    // Between points liquidus.h interpolates the slope d / w linearly in w; the curve it draws must rise.
    if (p > 0) {
      const double r0 = d0 / w0, r1 = dep / w;
      for (int k = 1; k <= 64; ++k) {
        const double x = w0 + (w - w0) * k / 64.0, xp = w0 + (w - w0) * (k - 1) / 64.0;
        const double y = x * (r0 + (r1 - r0) * (x - w0) / (w - w0)),
                     yp = xp * (r0 + (r1 - r0) * (xp - w0) / (w - w0));
        if (!(y > yp))
          throw SceneError(here,
                           "between this point and the one before, the interpolated liquidus falls; add a "
                           "point between them");
      }
    }
    sub.liquidus_points.push_back({w, dep});
    w0 = w;
    d0 = dep;
  }
}

// The index in s.substances of the substance called `name`, which a scene names at `path`; a SceneError
// there, listing what the scene declares, if it declares none of that name.
std::size_t substance_index(const Scene& s, const std::string& name, const std::string& path) {
  for (std::size_t k = 0; k < s.substances.size(); ++k)
    if (s.substances[k].name == name) return k;
  std::string known;
  for (const Substance& d : s.substances) known += (known.empty() ? "" : ", ") + d.name;
  throw SceneError(path, "the scene's `substances` declare no substance '" + name + "' (" +
                             (known.empty() ? "it declares none" : "it declares " + known) + ")");
}

// The concentration of each of the scene's substances [kg/m^3] that a fluid block or an emitter (`entry`, at
// `path`) of fluid `material` gives in its `substances`; 0 for those it does not name. A concentration past
// what the fluid dissolves (the substance's solubility) is refused: a scene starts or pours solutions.
std::vector<double> concentrations_from_json(const Json& entry, const std::string& path, const Scene& s,
                                             int material) {
  std::vector<double> out(s.substances.size(), 0.0);
  if (!entry.contains("substances")) return out;
  for (const auto& [name, value] : entry["substances"].items()) {
    const std::string at = path + ".substances." + name;
    const std::size_t k = substance_index(s, name, at);
    out[k] = value["concentration"].get<double>();
    const double most = most_dissolved(s, material, k);
    if (out[k] > most * (1 + 1e-12))
      throw SceneError(at + ".concentration",
                       format_number(out[k]) + " kg/m^3 is more than '" +
                           s.materials[static_cast<std::size_t>(material)].name + "' dissolves of '" + name +
                           "' (its solubility " + format_number(s.substances[k].solubility) +
                           " kg per kg of solution: " + format_number(most) + " kg/m^3)");
  }
  // Whatever their solubility, what a fluid holds is part of its mass.
  double sum = 0;
  for (double c : out) sum += c;
  const Material& fluid = s.materials[static_cast<std::size_t>(material)];
  if (!(sum < fluid.density))
    throw SceneError(path + ".substances",
                     format_number(sum) + " kg/m^3 of substances in all is not less than '" + fluid.name +
                         "''s own density, " + format_number(fluid.density) +
                         " kg/m^3: they would be more than the fluid that holds them");
  return out;
}

// `materials` is the document's block, for the names; `s` has the domain, the materials and the ambient
// temperature (a block without one starts at it).
FluidBlock fluid_block_from_json(Json& f, const std::string& path, const Scene& s, const Json& materials,
                                 const std::string& folder) {
  FluidBlock block;
  block.material = material_index(materials, f["material"], path + ".material", "fluid", "a fluid block");
  block.shape = shape_of(f, path, folder);
  block.box = box_of(block.shape);
  block.velocity = vec(f["velocity"]);
  block.temperature = temperature_or(f, s.heat.ambient_temperature);
  check_inside(s.domain, block.box, block.shape.axis_aligned_box() ? path + ".box" : path);
  block.substances = concentrations_from_json(f, path, s, block.material);
  check_start(s, block.material, block.temperature, path + (f.contains("temperature") ? ".temperature" : ""),
              block.substances);
  return block;
}

AirFill air_fill_from_json(const Json& a, const Scene& s, const Json& materials) {
  AirFill air;
  air.material = material_index(materials, a["material"], "air.material", "air", "the air fill");
  air.region = a.contains("region") ? box(a["region"]) : s.domain;
  if (a.contains("region")) {
    check_box(air.region, "air.region", "empty box");
    check_inside(s.domain, air.region, "air.region");
  }
  air.temperature = temperature_or(a, s.heat.ambient_temperature);
  air.buoyancy = choice_of<Buoyancy>(a["buoyancy"]);
  air.theta = a["theta"].get<double>();
  air.reference_temperature =
      a.contains("reference_temperature") ? a["reference_temperature"].get<double>() : air.temperature;
  air.expansion =
      a.contains("expansion") ? a["expansion"].get<double>() : 1.0 / (air.reference_temperature + 273.15);
  air.face_time = a["face_exchange_time"].get<double>();
  air.artificial_buoyancy = a["artificial_buoyancy"].get<double>();
  air.max_temperature = a["max_temperature"].get<double>();
  air.face_depth = a["face_exchange_depth"].get<double>();
  if (air.face_depth == 0) air.face_depth = s.solver.support_ratio * s.spacing;
  // Eq 7's denominator 1 + theta T: the kernel holds it at 0.1 or more (dfsph.cl); a scene whose air
  // starts or is referred to below that has a theta too large for its temperatures.
  if (air.buoyancy == Buoyancy::IdealGas)
    for (const double t : {air.temperature, air.reference_temperature})
      if (1.0 + air.theta * t < 0.1)
        throw SceneError("air.theta", "1 + theta T = " + format_number(1.0 + air.theta * t) + " at " +
                                          format_number(t) + " °C; eq 7 needs it above 0.1");
  return air;
}

IceBlock ice_block_from_json(Json& f, const std::string& path, const Scene& s, const Json& materials,
                             const std::string& folder) {
  IceBlock block;
  block.material = material_index(materials, f["material"], path + ".material", "ice", "an ice block");
  block.shape = shape_of(f, path, folder);
  block.box = box_of(block.shape);
  block.motion = f["motion"] == "free" ? IceBlock::Motion::Free : IceBlock::Motion::Fixed;
  const double melt = s.materials[static_cast<std::size_t>(block.material)].melting_point;
  block.temperature = temperature_or(f, std::min(s.heat.ambient_temperature, melt));
  check_inside(s.domain, block.box, block.shape.axis_aligned_box() ? path + ".box" : path);
  check_start(s, block.material, block.temperature, path + ".temperature");
  return block;
}

// A solid as its file says it; a held one's material variant is the loader's business.
Solid solid_from_json(Json& j, const std::string& path, const Scene& s, const Json& materials,
                      const std::string& folder) {
  Solid solid;
  solid.material = material_index(materials, j["material"], path + ".material", "solid", "a solid");
  if (j["shape"] != "plane") {
    solid.shape = shape_of(j, path, folder);
    solid.box = box_of(solid.shape);
  } else {
    check_shared_shape_fields(j, path);
    solid.plane = true;
    solid.point = vec(j["point"]);
    solid.normal = unit_direction(vec(j["normal"]), path + ".normal");
  }
  solid.temperature = temperature_or(j, s.heat.ambient_temperature);
  solid.deposits.assign(s.substances.size(), 0.0);
  for (const auto& [name, value] : j["deposits"].items()) {
    const std::string at = path + ".deposits." + name;
    const std::size_t k = substance_index(s, name, at);
    if (!s.substances[k].coating())
      throw SceneError(at, "only a coating sticks to a solid: substance '" + name + "' is of kind " +
                               thaw::name(s.substances[k].kind));
    solid.deposits[k] = value["deposit"].get<double>();
  }
  return solid;
}

SceneCamera camera_from_json(const Json& j) {
  SceneCamera c;
  c.azimuth = j["azimuth"].get<double>();
  c.elevation = j["elevation"].get<double>();
  c.distance = j["distance"].get<double>();
  c.fov = j["fov"].get<double>();
  if (j.contains("target")) c.target = vec(j["target"]);
  return c;
}

Scene convert_and_check(Json doc, const std::string& folder) {
  Scene s;
  s.name = doc["name"].get<std::string>();
  s.description = doc["description"].get<std::string>();
  s.gravity = vec(doc["gravity"]);
  s.spacing = doc["spacing"].get<double>();
  s.solver = solver_settings_from_json(doc["solver"]);
  // The lattice sum sum_j dx^3 W is 1.034 for Wendland C2 at H = 2 dx and 1.003 at 3 dx (cubic spline:
  // 0.99997 at 2 dx; tests/sim/sph_kernel_test.cpp): below 3 dx a resting lattice starts compressed.
  if (s.solver.kernel == KernelFunction::WendlandC2 && s.solver.support_ratio < 3.0)
    throw SceneError(
        "solver.support_ratio",
        format_number(s.solver.support_ratio) +
            " is too small for the wendland_c2 kernel: use >= 3 (at 2 a resting lattice starts 3.4 % "
            "compressed), or the cubic_spline kernel");

  const Json& domain = doc["domain"];
  s.domain = box(domain);
  check_box(s.domain, "domain", "empty domain");
  const double smallest = (s.domain.max - s.domain.min).minCoeff();
  if (s.spacing >= smallest) {
    throw SceneError("spacing", format_number(s.spacing) +
                                    " m is not smaller than the smallest extent of the domain (" +
                                    format_number(smallest) + " m)");
  }

  const Json& materials = doc["materials"];
  for (const auto& [name, m] : materials.items()) s.materials.push_back(material_from_json(name, m));
  // Ice and the fluid it melts into share the latent heat and melting point (sim/kernels/thermal_law.h).
  {
    int index = 0;
    for (const auto& [name, m] : materials.items()) {
      if (m["kind"] == "ice") {
        const std::string path = "materials." + name + ".melts_into";
        const int fluid = material_index(materials, m["melts_into"], path, "fluid", "ice's melts_into");
        Material& liquid = s.materials[static_cast<std::size_t>(fluid)];
        if (liquid.partner >= 0)
          throw SceneError(path, "'" + liquid.name + "' already freezes into '" +
                                     s.materials[static_cast<std::size_t>(liquid.partner)].name +
                                     "'; each fluid may have one ice");
        Material& ice = s.materials[static_cast<std::size_t>(index)];
        ice.partner = fluid;
        liquid.partner = index;
        ice.latent_heat = liquid.latent_heat = m["latent_heat"].get<double>();
        ice.melting_point = liquid.melting_point = m["melting_point"].get<double>();
      }
      ++index;
    }
  }
  s.heat = heat_settings_from_json(doc);
  s.tension = tension_settings_from_json(doc["tension"]);
  for (const auto& [name, d] : doc["substances"].items()) {
    if (s.substances.size() == std::size_t(kMaxSubstances))
      throw SceneError("substances",
                       "a scene carries at most " + std::to_string(kMaxSubstances) +
                           " substances (their stage walks the neighbours once for all of them)");
    Substance sub;
    sub.name = name;
    sub.diffusivity = d["diffusivity"].get<double>();
    sub.molar_mass = d["molar_mass"].get<double>();
    sub.dissociation = d["dissociation"].get<double>();
    liquidus_from_json(sub, d, "substances." + name);
    sub.enters_ice = d["enters_ice"].get<bool>();
    sub.kind = choice_of<SubstanceKind>(d["kind"]);
    sub.colour = substance_colour(d["colour"].get<std::string>(), s.substances.size(),
                                  "substances." + name + ".colour");
    if (sub.surface_active()) {
      sub.surface_diffusivity = d["surface_diffusivity"].get<double>();
      sub.adsorption_rate = d["adsorption_rate"].get<double>();
      sub.desorption_rate = d["desorption_rate"].get<double>();
      sub.surface_capacity = d["surface_capacity"].get<double>();
      sub.tension_law = choice_of<TensionLaw>(d["tension_law"]);
      sub.tension_scale = d["tension_scale"].get<double>();
      if (sub.lowers_tension() && sub.surface_capacity <= 0 && s.tension.enabled())
        throw SceneError("substances." + name + ".tension_law",
                         std::string("the ") + thaw::name(sub.tension_law) +
                             " law is written in Gamma / Gamma_max: it needs a surface_capacity above 0 (or "
                             "tension_law none)");
    }
    if (sub.coating()) {
      sub.coating_rate = d["coating_rate"].get<double>();
      sub.coating_capacity = d["coating_capacity"].get<double>();
      sub.cleansing_rate = d["cleansing_rate"].get<double>();
    }
    s.substances.push_back(sub);
  }
  // A coating's cleanser: another of the scene's substances.
  for (Substance& sub : s.substances) {
    if (!sub.coating()) continue;
    const std::string by = doc["substances"][sub.name]["cleansed_by"].get<std::string>();
    const std::string path = "substances." + sub.name + ".cleansed_by";
    if (by.empty()) {
      if (sub.cleansing_rate > 0)
        throw SceneError("substances." + sub.name + ".cleansing_rate",
                         "cleansing needs a cleanser: name the substance in cleansed_by");
      continue;
    }
    const std::size_t k = substance_index(s, by, path);
    if (&s.substances[k] == &sub) throw SceneError(path, "a coating cannot cleanse itself");
    sub.cleanser = static_cast<int>(k);
  }
  s.camera = camera_from_json(doc["camera"]);

  s.walls = domain["walls"].get<std::vector<std::string>>();
  s.wall_layers = domain["wall_layers"].get<int>();
  for (const std::string& side : domain["open"].get<std::vector<std::string>>()) {
    if (std::find(s.walls.begin(), s.walls.end(), side) != s.walls.end())
      throw SceneError("domain.open", "side " + side + " has a wall; water cannot leave through it");
    s.open_faces |= 1u << (2 * (side[1] - 'x') + (side[0] == '+' ? 1 : 0));
  }
  // Walls lie on the lattice that starts at the domain's lower corner. Along an axis with an upper wall,
  // an extent that is not a whole number of spacings leaves that wall standing off its face: still
  // water ran into the gap and was clamped there (a 5 cm tank at 4 mm: 484,096 clamps in 0.6 s; at
  // 4.8 cm, none).
  for (int a = 0; a < 3; ++a) {
    bool walled = false;
    for (const std::string& w : s.walls) walled = walled || (w[0] == '+' && w[1] == "xyz"[a]);
    if (!walled) continue;
    const double extent = s.domain.max[a] - s.domain.min[a];
    const double n = extent / s.spacing;
    if (std::abs(n - std::round(n)) > 1e-6 * std::max(1.0, n)) {
      const double below = s.domain.min[a] + std::max(1.0, std::floor(n)) * s.spacing;
      const double above = s.domain.min[a] + std::ceil(n) * s.spacing;
      throw SceneError("domain.max",
                       std::string("the extent along ") + "xyz"[a] + ", " + format_number(extent) +
                           " m, is " + format_number(n) + " spacings of " + format_number(s.spacing) +
                           " m; with a wall on its upper side it must be a whole number: set its " +
                           "xyz"[a] + " to " + format_number(below) + " or " + format_number(above) +
                           ", or choose a spacing that divides the extent");
    }
  }
  if (domain.contains("wall_material")) {
    s.wall_material = material_index(materials, domain["wall_material"], "domain.wall_material", "solid",
                                     "the domain walls");
  } else if (!s.walls.empty()) {
    throw SceneError("domain.wall_material", "missing: required because domain.walls is not empty");
  }
  if (s.heat.wall_coefficient > 0) {
    if (s.wall_material >= 0 && s.materials[static_cast<std::size_t>(s.wall_material)].adiabatic)
      throw SceneError("domain.wall_heat.coefficient",
                       "the wall material '" + s.materials[static_cast<std::size_t>(s.wall_material)].name +
                           "' is adiabatic: no heat crosses it");
    if (s.walls.empty())
      throw SceneError("domain.wall_heat.coefficient", "needs walls: domain.walls is empty");
    Material wall = s.materials[static_cast<std::size_t>(s.wall_material)];
    wall.name += " (tank wall)";
    wall.wall_heat = true;
    s.materials.push_back(wall);
    s.wall_material = static_cast<int>(s.materials.size()) - 1;
  }

  for (std::size_t i = 0; i < doc["fluids"].size(); ++i)
    s.fluids.push_back(fluid_block_from_json(doc["fluids"][i], join_path("fluids", i), s, materials, folder));
  for (std::size_t i = 0; i < doc["ice"].size(); ++i)
    s.ice.push_back(ice_block_from_json(doc["ice"][i], join_path("ice", i), s, materials, folder));
  if (doc.contains("air")) s.air = air_fill_from_json(doc["air"], s, materials);
  if (s.fluids.empty() && s.ice.empty() && doc["emitters"].empty() && !s.has_air())
    throw SceneError(
        "fluids", "the scene has neither fluid nor ice nor air nor an emitter: add a block to fluids or ice");

  for (std::size_t i = 0; i < doc["solids"].size(); ++i) {
    Json& j = doc["solids"][i];
    Solid solid = solid_from_json(j, join_path("solids", i), s, materials, folder);
    if (j["hold_temperature"].get<bool>() && s.materials[static_cast<std::size_t>(solid.material)].adiabatic)
      throw SceneError(join_path("solids", i) + ".hold_temperature",
                       "material '" + s.materials[static_cast<std::size_t>(solid.material)].name +
                           "' is adiabatic: it passes no heat, so holding its temperature does nothing");
    if (j["hold_temperature"].get<bool>()) {
      Material held = s.materials[static_cast<std::size_t>(solid.material)];
      held.name += " (held at " + format_number(solid.temperature) + " °C)";
      held.held = true;
      held.held_temperature = solid.temperature;
      s.materials.push_back(held);
      solid.material = static_cast<int>(s.materials.size()) - 1;
    }
    s.solids.push_back(solid);
  }
  if (s.materials.size() > 255)
    throw SceneError("solids", "too many materials (held solids count as their own): at most 255");

  for (std::size_t i = 0; i < doc["lamps"].size(); ++i)
    s.lamps.push_back(lamp_from_json(doc["lamps"][i], join_path("lamps", i)));
  // A lamp's photons are traced once a flow step and absorbed by the heat pass that follows: sub-steps
  // would absorb them again.
  if (s.heat.max_substeps > 1 && !s.lamps.empty())
    throw SceneError("heat.max_substeps", "lamps trace their photons once a step: with lamps it must be 1");
  for (std::size_t i = 0; i < doc["dryers"].size(); ++i) {
    s.dryers.push_back(dryer_from_json(doc["dryers"][i], join_path("dryers", i)));
    check_dryer(s.dryers.back(), s, join_path("dryers", i));
  }
  // The intake's flags number a dryer in a byte (sim/kernels/grid.cl): 2k + 2 <= 255.
  if (s.air_dryer_count() > std::size_t(kMaxAirDryers))
    throw SceneError("dryers", "more than " + std::to_string(kMaxAirDryers) + " air dryers");
  for (std::size_t i = 0; i < doc["emitters"].size(); ++i) {
    Json e = doc["emitters"][i];
    if (!e.contains("temperature")) e["temperature"] = s.heat.ambient_temperature;
    const std::string path = join_path("emitters", i);
    s.emitters.push_back(emitter_from_json(e, path, s.materials));
    s.emitters.back().substances = concentrations_from_json(e, path, s, s.emitters.back().material);
    check_emitter(s.emitters.back(), s, path);
  }

  check_multiphase(s);

  for (int a = 0; a < 3; ++a) {
    if (!s.solver.periodic[static_cast<std::size_t>(a)]) continue;
    const std::string axis(1, kAxis[static_cast<std::size_t>(a)]);
    if (s.solver.flow && a == 0)
      throw SceneError(
          "solver.periodic",
          "x can be periodic only with solver.flow = false: flowing particles wrap along y and z");
    if (s.solver.flow)
      for (std::size_t b = 0; b < s.ice.size(); ++b)
        if (s.ice[b].motion == IceBlock::Motion::Free)
          throw SceneError(join_path("ice", b) + ".motion", "free ice cannot move through a periodic axis (" +
                                                                axis +
                                                                "): make it fixed, or the axis not periodic");
    if (s.open_faces & (3u << (2 * a)))
      throw SceneError("domain.open", "an open side on the periodic axis " + axis);
    for (const std::string& w : s.walls)
      if (w[1] == kAxis[static_cast<std::size_t>(a)])
        throw SceneError("domain.walls", "wall " + w + " on the periodic axis " + axis);
    const double length = s.domain.max[a] - s.domain.min[a];
    const double support = s.solver.support_ratio * s.spacing;
    if (length < 3.0 * support * (1.0 - 1e-9))
      throw SceneError("solver.periodic", "the domain is " + format_number(length) + " m long along " + axis +
                                              ", less than 3 kernel supports (" +
                                              format_number(3.0 * support) + " m)");
    // brackbill1992 fits the surface over the cells within tension::kFitRadius spacings: around an axis of
    // fewer cells than that walk spans it would visit a row twice (grid_common.h's rows wrap).
    if (s.tension.model == TensionModel::Brackbill1992) {
      const int reach = static_cast<int>(std::ceil(tension::kFitRadius * s.spacing / support - 1e-9));
      const double needed = (2.0 * reach + 1.0) * support;
      if (length < needed * (1.0 - 1e-9))
        throw SceneError("tension.model",
                         "brackbill1992 fits the surface over " + std::to_string(2 * reach + 1) +
                             " kernel supports: the periodic axis " + axis + " must be at least " +
                             format_number(needed) + " m long; it is " + format_number(length) + " m");
    }
  }

  if (s.solver.no_slip != NoSlip::None)
    for (std::size_t b = 0; b < s.ice.size(); ++b)
      if (s.ice[b].motion == IceBlock::Motion::Free)
        throw SceneError("solver.no_slip", "no-slip walls are not built for free ice yet (" +
                                               join_path("ice", b) +
                                               " is free): the body would not take the viscous reaction");

  const double n = estimated_particles(s, wall_layer_count(s));
  if (n > kMaxParticles) {
    throw SceneError("spacing", "about " + format_count(n) + " particles at " + format_number(s.spacing) +
                                    " m, more than the limit of " + format_count(kMaxParticles) +
                                    "; increase the spacing or shrink the scene");
  }
  // Refused before anything is allocated: 18.2 million particles took 6 GB and 24 s for two steps, and a
  // scene past the machine's memory would be killed by the kernel, or swap it to a halt.
  const double needed = estimated_memory_bytes(n), limit = memory_limit_bytes();
  if (needed > limit) {
    const auto gb = [](double bytes) {
      std::ostringstream o;
      o.precision(2);
      o << std::fixed << bytes / 1e9 << " GB";
      return o.str();
    };
    const bool from_env = std::getenv("THAW_MEMORY_LIMIT") != nullptr;
    throw SceneError("spacing", "about " + format_count(n) + " particles at " + format_number(s.spacing) +
                                    " m need about " + gb(needed) + " of memory, more than the " + gb(limit) +
                                    (from_env ? " THAW_MEMORY_LIMIT allows" : " this machine has available") +
                                    "; increase the spacing, shrink the scene, or set THAW_MEMORY_LIMIT "
                                    "(e.g. THAW_MEMORY_LIMIT=32G, or off) to override");
  }
  if (s.solver.min_dt >= s.solver.max_dt) {
    throw SceneError("solver.min_dt", format_number(s.solver.min_dt) + " s must be below solver.max_dt (" +
                                          format_number(s.solver.max_dt) + " s)");
  }
  s.source = std::move(doc);
  return s;
}

// Line and column (1-based) of a 0-based byte offset, as editors count them.
std::string location(const std::string& text, std::size_t offset) {
  offset = std::min(offset, text.size());
  const std::size_t line =
      1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + offset, '\n'));
  const std::size_t last_newline = offset == 0 ? std::string::npos : text.rfind('\n', offset - 1);
  const std::size_t column = last_newline == std::string::npos ? offset + 1 : offset - last_newline;
  return std::to_string(line) + ":" + std::to_string(column);
}

// nlohmann's message without its "[json.exception...] parse error at line 1, column 2: " prefix.
std::string parse_reason(const std::string& what) {
  std::size_t start = what.find("column ");
  start = what.find(": ", start == std::string::npos ? 0 : start);
  return start == std::string::npos ? what : what.substr(start + 2);
}

}  // namespace

namespace {
Json v(const Eigen::Vector3d& x) { return Json::array({x.x(), x.y(), x.z()}); }
}  // namespace

Json to_json(const Dryer& d) {
  return {{"model", name(d.model)},
          {"on", d.on},
          {"position", v(d.position)},
          {"direction", v(d.direction)},
          {"half_angle", d.half_angle},
          {"reach", d.reach},
          {"temperature", d.temperature},
          {"speed", d.speed},
          {"nozzle_diameter", d.nozzle_diameter}};
}

Json to_json(const Lamp& l) {
  return {{"on", l.on},
          {"centre", v(l.centre)},
          {"normal", v(l.normal)},
          {"width", l.width},
          {"height", l.height},
          {"temperature", l.temperature},
          {"emissivity", l.emissivity},
          {"photons", l.photons}};
}

Dryer dryer_from_json(const Json& j, const std::string& path) {
  Dryer d;
  d.model = choice_of<DryerModel>(j["model"]);
  d.on = j["on"].get<bool>();
  d.position = vec(j["position"]);
  d.direction = unit_direction(vec(j["direction"]), path + ".direction");
  d.half_angle = j["half_angle"].get<double>();
  d.reach = j["reach"].get<double>();
  d.temperature = j["temperature"].get<double>();
  d.speed = j["speed"].get<double>();
  d.nozzle_diameter = j["nozzle_diameter"].get<double>();
  return d;
}

Lamp lamp_from_json(const Json& j, const std::string& path) {
  Lamp l;
  l.on = j["on"].get<bool>();
  l.centre = vec(j["centre"]);
  l.normal = unit_direction(vec(j["normal"]), path + ".normal");
  l.width = j["width"].get<double>();
  l.height = j["height"].get<double>();
  l.temperature = j["temperature"].get<double>();
  l.emissivity = j["emissivity"].get<double>();
  l.photons = j["photons"].get<int>();
  return l;
}

double Emitter::area() const { return M_PI * radius * radius; }
std::size_t Scene::air_dryer_count() const {
  return static_cast<std::size_t>(
      std::count_if(dryers.begin(), dryers.end(), [](const Dryer& d) { return d.model == DryerModel::Air; }));
}

double Dryer::area() const { return 0.25 * M_PI * nozzle_diameter * nozzle_diameter; }

Json to_json(const Emitter& e, const std::vector<Material>& materials) {
  return {{"open", e.open},
          {"material", materials.at(static_cast<std::size_t>(e.material)).name},
          {"position", v(e.position)},
          {"direction", v(e.direction)},
          {"radius", e.radius},
          {"speed", e.speed},
          {"temperature", e.temperature},
          {"start", e.start},
          {"stop", e.stop}};
}

Emitter emitter_from_json(const Json& j, const std::string& path, const std::vector<Material>& materials) {
  Emitter e;
  e.open = j["open"].get<bool>();
  const std::string name = j["material"].get<std::string>();
  const auto it =
      std::find_if(materials.begin(), materials.end(), [&](const Material& m) { return m.name == name; });
  if (it == materials.end() || it->kind != MaterialKind::Fluid) {
    std::string fluids;
    for (const Material& m : materials)
      if (m.kind == MaterialKind::Fluid) fluids += (fluids.empty() ? "" : ", ") + m.name;
    throw SceneError(path + ".material", (it == materials.end() ? "unknown material '" : "material '") +
                                             name + (it == materials.end() ? "'" : "' is not a fluid") +
                                             "; an emitter pours a fluid (fluid materials: " +
                                             (fluids.empty() ? "none" : fluids) + ")");
  }
  e.material = static_cast<int>(it - materials.begin());
  e.position = vec(j["position"]);
  e.direction = unit_direction(vec(j["direction"]), path + ".direction");
  e.radius = j["radius"].get<double>();
  if (j.contains("speed") && j.contains("rate"))
    throw SceneError(path + ".rate", "give the exit speed or the volume flow rate, not both (speed " +
                                         format_number(j["speed"].get<double>()) + " m/s, rate " +
                                         format_number(j["rate"].get<double>()) + " L/s)");
  e.speed = j.contains("rate")    ? j["rate"].get<double>() * 1e-3 / e.area()
            : j.contains("speed") ? j["speed"].get<double>()
                                  : 0.5;
  if (!(e.speed <= 50))
    throw SceneError(path + ".rate", format_number(j["rate"].get<double>()) +
                                         " L/s through a nozzle of radius " + format_number(e.radius) +
                                         " m is an exit speed of " + format_number(e.speed) +
                                         " m/s, above the limit of 50 m/s");
  e.temperature = j.contains("temperature") ? j["temperature"].get<double>() : 20.0;
  if (it->partner >= 0 && e.temperature < it->melting_point)
    throw SceneError(path + ".temperature", format_number(e.temperature) +
                                                " °C is below the freezing point of '" + it->name + "' (" +
                                                format_number(it->melting_point) +
                                                " °C); supercooled fluid is not modelled");
  e.start = j["start"].get<double>();
  e.stop = j["stop"].get<double>();
  if (e.stop > 0 && e.stop <= e.start)
    throw SceneError(path + ".stop", format_number(e.stop) + " s is not after start (" +
                                         format_number(e.start) + " s); 0 pours for ever");
  return e;
}

namespace {
// A nozzle's position inside the domain; SceneError at PATH.position otherwise.
void check_nozzle_inside(const Eigen::Vector3d& x, const Scene& scene, const std::string& path) {
  const Box& d = scene.domain;
  if ((x.array() < d.min.array()).any() || (x.array() > d.max.array()).any())
    throw SceneError(path + ".position", "[" + format_number(x.x()) + ", " + format_number(x.y()) + ", " +
                                             format_number(x.z()) + "] lies outside the domain");
}
}  // namespace

void check_emitter(const Emitter& e, const Scene& scene, const std::string& path) {
  if (e.radius < scene.spacing)
    throw SceneError(path + ".radius", format_number(e.radius) + " m is less than the particle spacing (" +
                                           format_number(scene.spacing) +
                                           " m): a nozzle must be at least one particle wide");
  check_nozzle_inside(e.position, scene, path);
  // The disc's reach along each axis: its radius times the sine of the angle between the axis and the
  // direction. A disc past a side lays its particles outside the domain, where the walls clamp them, and a
  // disc wider than the domain lays more a step than the domain holds.
  const Box& d = scene.domain;
  for (int a = 0; a < 3; ++a) {
    const double reach = e.radius * std::sqrt(std::max(0.0, 1.0 - e.direction[a] * e.direction[a]));
    const double room = std::min(e.position[a] - d.min[a], d.max[a] - e.position[a]);
    if (reach > room * (1.0 + 1e-9) + 1e-12)
      throw SceneError(path + ".radius",
                       format_number(e.radius) + " m: the nozzle's disc reaches " + format_number(reach) +
                           " m along " + std::string(1, char('x' + a)) +
                           " from its centre, and the domain's side is " + format_number(room) +
                           " m away; the disc must lie inside the domain");
  }
  // Its centre and two rings of eight points across the disc, none inside a solid or ice.
  const Eigen::Vector3d u = e.direction.unitOrthogonal(), v = e.direction.cross(u);
  std::vector<Eigen::Vector3d> points{e.position};
  for (const double r : {0.5 * e.radius, e.radius - 0.5 * scene.spacing})
    for (int k = 0; k < 8; ++k) {
      const double phi = k * M_PI / 4;
      points.push_back(e.position + r * (std::cos(phi) * u + std::sin(phi) * v));
    }
  const auto refuse = [&](const std::string& what, std::size_t index) {
    throw SceneError(path + ".position", "the nozzle's disc lies inside " + join_path(what, index) +
                                             ": an emitter must pour into open space");
  };
  for (std::size_t b = 0; b < scene.ice.size(); ++b)
    for (const std::uint8_t in : scene.ice[b].shape.contains(points))
      if (in) refuse("ice", b);
  for (std::size_t b = 0; b < scene.solids.size(); ++b) {
    const Solid& s = scene.solids[b];
    for (std::size_t k = 0; k < points.size(); ++k) {
      const bool in = s.plane ? (points[k] - s.point).dot(s.normal) < 0.0 : s.shape.contains(points[k]);
      if (in) refuse("solids", b);
    }
  }
}

void check_dryer(const Dryer& d, const Scene& scene, const std::string& path) {
  if (d.model == DryerModel::Cone) {
    if (scene.has_air())
      throw SceneError(path + ".model",
                       "the cone dryer heats ice and water where no air particles are; with `air` it would "
                       "heat them through the air (counted twice): set \"model\": \"air\" to blow the air");
    return;
  }
  if (!scene.has_air())
    throw SceneError(
        path + ".model",
        "an air dryer blows the scene's air particles, and this scene has none: add `air`, or use "
        "\"model\": \"cone\"");
  if (d.nozzle_diameter < 2.0 * scene.spacing * (1.0 - 1e-9))
    throw SceneError(path + ".nozzle_diameter", format_number(d.nozzle_diameter) +
                                                    " m is less than two particle spacings (" +
                                                    format_number(2.0 * scene.spacing) +
                                                    " m): an air dryer's nozzle must be at least "
                                                    "two particles wide");
  check_nozzle_inside(d.position, scene, path);
}

Eigen::Vector3d unit_direction(const Eigen::Vector3d& v, const std::string& path) {
  const double squared = v.squaredNorm();
  if (!std::isfinite(squared) || !(squared > 0))
    throw SceneError(path, "must be a non-zero vector of moderate size, got [" + format_number(v.x()) + ", " +
                               format_number(v.y()) + ", " + format_number(v.z()) + "]");
  return v / std::sqrt(squared);
}

double estimated_memory_bytes(double particles) { return 300e6 + 360.0 * particles; }

double particle_limit() {
  return std::min(kMaxParticles, std::max(0.0, (memory_limit_bytes() - estimated_memory_bytes(0)) / 360.0));
}

double memory_limit_bytes() {
  if (const char* env = std::getenv("THAW_MEMORY_LIMIT")) {
    const std::string text = env;
    if (text == "off") return std::numeric_limits<double>::infinity();
    std::size_t used = 0;
    double value = 0;
    try {
      value = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    const std::string unit = text.substr(used);
    const double scale = unit.empty()  ? 1
                         : unit == "K" ? 1e3
                         : unit == "M" ? 1e6
                         : unit == "G" ? 1e9
                         : unit == "T" ? 1e12
                                       : 0;
    if (used == 0 || scale == 0 || !(value > 0) || !std::isfinite(value))
      throw Error("THAW_MEMORY_LIMIT: expected a size such as 16G, 800M or 123456 (bytes), or off; got '" +
                  text + "'");
    return value * scale;
  }
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kb = 0;
  std::string unit;
  while (meminfo >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024.0;
  return std::numeric_limits<double>::infinity();
}

int wall_layer_count(const Scene& s) {
  if (s.wall_layers > 0) return s.wall_layers;
  // Over a support of 3 spacings, 3 layers let water under load creep into the wall (its deepest layer is
  // just out of reach of water resting on it, and the wall particles it does reach are short of
  // neighbours below) until the walls' short-range push (forces.cl) came; the fourth still fills the
  // kernel's support next to the wall. Over 2, 2 held as well as 3. Measured in docs/VALIDATION-RESULTS.md.
  const double r = s.solver.support_ratio;
  return r > 2.0 + 1e-9 ? static_cast<int>(std::floor(r + 1e-9)) + 1 : static_cast<int>(std::ceil(r - 1e-9));
}

SolverSettings solver_settings_from_json(const Json& j) {
  SolverSettings s;
  s.kernel = choice_of<KernelFunction>(j["kernel"]);
  s.support_ratio = j["support_ratio"].get<double>();
  s.pressure = choice_of<PressureSolver>(j["pressure"]);
  s.density_tolerance = j["density_tolerance"].get<double>();
  s.divergence_tolerance = j["divergence_tolerance"].get<double>();
  s.max_pressure_iterations = j["max_pressure_iterations"].get<int>();
  s.pressure_relaxation = j["pressure_relaxation"].get<double>();
  s.divergence_warm_start = j["divergence_warm_start"].get<bool>();
  s.boundary_pressure = choice_of<DfsphBoundary>(j["boundary_pressure"]);
  s.multiphase = choice_of<Multiphase>(j["multiphase"]);
  s.eos = choice_of<Eos>(j["eos"]);
  s.gamma = j["gamma"].get<double>();
  s.speed_of_sound = j["speed_of_sound"].get<double>();
  s.sound_speed_factor = j["sound_speed_factor"].get<double>();
  s.reference_speed = j["reference_speed"].get<double>();
  s.artificial_viscosity = j["artificial_viscosity"].get<double>();
  s.boundary_viscosity = j["boundary_viscosity"].get<double>();
  s.no_slip = choice_of<NoSlip>(j["no_slip"]);
  s.boundary_volume = choice_of<BoundaryVolume>(j["boundary_volume"]);
  s.cfl = j["cfl"].get<double>();
  s.viscous_number = j["viscous_number"].get<double>();
  s.force_number = j["force_number"].get<double>();
  s.max_dt = j["max_dt"].get<double>();
  s.min_dt = j["min_dt"].get<double>();
  s.max_speed = j["max_speed"].get<double>();
  s.output_interval = j["output_interval"].get<double>();
  s.flow = j["flow"].get<bool>();
  for (const auto& axis : j["periodic"])
    s.periodic[static_cast<std::size_t>(axis.get<std::string>()[0] - 'x')] = true;
  s.diffusion_number = j["diffusion_number"].get<double>();
  return s;
}

void apply_override(Json& doc, const std::string& assignment) {
  apply_override(doc, assignment, scene_schema());
}

void apply_override(Json& doc, const std::string& assignment, const Field& schema) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw Error("--set '" + assignment + "': expected PATH=VALUE, e.g. solver.cfl=0.3");
  }
  const std::string path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  Json value;
  try {
    value = parse_json(text);
  } catch (const JsonShapeError& e) {
    throw SceneError(path, "value: " + std::string(e.what()));
  } catch (const Json::parse_error&) {
    value = text;  // solver.kernel=wendland_c2 needs no quotes
  } catch (const Json::out_of_range&) {
    throw SceneError(path, "number " + text + " is out of range");
  }
  set_at_path(doc, path, std::move(value), &schema);
}

void check_multiphase(const Scene& s) {
  if (!s.solver.flow || !s.multiphase()) return;
  if (s.solver.pressure != PressureSolver::Dfsph && !s.several_rest_densities())
    throw SceneError("air.buoyancy",
                     "'ideal_gas' gives every air particle its own rest density, which needs "
                     "solver.pressure 'dfsph' (its multiphase form, Hu & Adams 2006); with 'wcsph' use "
                     "'boussinesq'");
  if (s.solver.pressure != PressureSolver::Dfsph)
    throw SceneError("solver.pressure",
                     "fluids of several rest densities (air beside water, or beside the water the ice melts "
                     "into) need 'dfsph', whose multiphase form (Hu & Adams 2006) holds at the real density "
                     "ratio; 'wcsph' has one rest density");
  // Two incompressible fluids sealed in a box must fill it exactly: what the water's tolerance leaves over
  // goes to the air, which the solve cannot relieve, and the run blows up (docs/VALIDATION-RESULTS.md,
  // air-water). Air in a real closed box would give way; ours is not compressible yet.
  if (s.has_air() && s.several_rest_densities() && s.walls.size() >= 6)
    throw SceneError(
        "domain.walls",
        "air beside water needs an open side of the domain (leave one of the six walls out, e.g. "
        "\"+z\", the room above): sealed in, the two incompressible fluids cannot make room "
        "for each other");
}

double ideal_gas_rest_density(double material_density, const AirFill& air, double temperature) {
  // rho0(T) = rho0(0 °C) / (1 + theta T) (eq 7), with rho0(0 °C) = rho (1 + theta T0); the denominator
  // held at 0.1 as in dfsph.cl.
  return material_density * (1.0 + air.theta * air.reference_temperature) /
         std::max(1.0 + air.theta * temperature, 0.1);
}

double rest_density_at(const Scene& scene, int material, double temperature) {
  const double rho = scene.materials.at(static_cast<std::size_t>(material)).density;
  // Without heat every air particle keeps the rest density of the fill's temperature (the flow table's
  // row, material_flow_table): a dryer's warmer air too, so that it starts on the lattice as well. With
  // heat enabled the heat stage is built wherever a new particle's temperature differs (plan_heat counts
  // the dryers' and the room's air), so its temperature is the one the flow table reads.
  if (scene.has_air() && material == scene.air.material && scene.air.buoyancy == Buoyancy::IdealGas)
    return ideal_gas_rest_density(rho, scene.air, scene.heat.enabled ? temperature : scene.air.temperature);
  return rho;
}

std::vector<double> Scene::fluid_rest_densities() const {
  std::vector<double> rest;
  auto add = [&](int m) {
    if (m >= 0) rest.push_back(materials[static_cast<std::size_t>(m)].density);
  };
  for (const auto& f : fluids) add(f.material);
  for (const auto& e : emitters) add(e.material);
  for (const auto& c : ice) add(materials[static_cast<std::size_t>(c.material)].partner);
  if (has_air()) add(air.material);
  return rest;
}

bool Scene::several_rest_densities() const {
  const auto rest = fluid_rest_densities();
  return std::any_of(rest.begin(), rest.end(), [&](double d) { return d != rest.front(); });
}

bool Scene::multiphase() const {
  return several_rest_densities() || (has_air() && air.buoyancy == Buoyancy::IdealGas);
}

double Scene::rest_density_split() const {
  const auto rest = fluid_rest_densities();
  if (rest.empty()) return 0;
  const auto [lo, hi] = std::minmax_element(rest.begin(), rest.end());
  if (*hi == *lo) return 0;  // one fluid (ideal-gas air alone): the walls' pressure as for water
  // Only a gas-like contrast makes a light fluid (its walls mirror its own pressure, dfsph.cl): two
  // liquids (water and a syrup 10 % denser) both take the walls' extrapolated pressure.
  return *hi >= 5.0 * *lo ? std::sqrt(*lo * *hi) : 0.5 * *lo;
}

Scene scene_from_json(Json doc, const std::vector<std::string>& overrides, const std::string& folder) {
  for (const std::string& o : overrides) apply_override(doc, o);
  validate(doc, scene_schema());
  return convert_and_check(std::move(doc), folder);
}

std::string resolve_scene_path(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path configs = fs::path(THAW_SOURCE_DIR) / "configs";
  std::vector<fs::path> candidates = {name};
  if (fs::path(name).extension() != ".json") candidates.emplace_back(name + ".json");
  if (!fs::path(name).is_absolute()) {
    candidates.push_back(configs / name);
    if (fs::path(name).extension() != ".json") candidates.push_back(configs / (name + ".json"));
  }
  std::string looked;
  for (const fs::path& p : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) return p.string();
    looked += (looked.empty() ? "" : ", ") + p.string();
  }
  throw Error("scene '" + name + "' not found; looked for " + looked);
}

Json read_json_file(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file + ": cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  try {
    return parse_json(text, true);
  } catch (const JsonShapeError& e) {
    throw Error(file + ": " + e.what());
  } catch (const Json::parse_error& e) {
    const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
    throw Error(file + ":" + location(text, offset) + ": invalid JSON: " + parse_reason(e.what()));
  } catch (const Json::out_of_range& e) {
    // Overflow ("1e400") carries no position; the literal itself, quoted in the message, locates it.
    const std::string what = e.what();
    const std::size_t open = what.find('\'');
    const std::size_t close = what.rfind('\'');
    const std::string literal = open < close ? what.substr(open + 1, close - open - 1) : std::string();
    const std::size_t at = literal.empty() ? std::string::npos : text.find(literal);
    const std::string where = at == std::string::npos ? "" : ":" + location(text, at);
    throw Error(file + where + ": invalid JSON: number " + literal + " is out of range of a double");
  }
}

Scene load_scene(const std::string& file, const std::vector<std::string>& overrides) {
  const std::string path = resolve_scene_path(file);
  Json doc = read_json_file(path);
  if (doc.is_object() && !doc.contains("name")) doc["name"] = std::filesystem::path(path).stem().string();
  return scene_from_json(std::move(doc), overrides, std::filesystem::path(path).parent_path().string());
}

double Substance::eutectic_depression() const {
  if (!lowers_melting_point()) return 0.0;
  return liquidus == LiquidusLaw::Blagden ? kMaxMeltingPointDrop : liquidus_points.back()[1];
}

std::vector<thermal::Liquidus> liquidus_table(const Scene& s) {
  std::vector<thermal::Liquidus> out(kMaxSubstances);
  for (std::size_t k = 0; k < out.size(); ++k) {
    thermal::Liquidus& l = out[k];
    l = thermal::Liquidus{};
    l.solubility = 1e30f;
    if (k >= s.substances.size()) continue;
    const Substance& sub = s.substances[k];
    if (sub.solubility > 0) l.solubility = static_cast<float>(sub.solubility);
    if (!sub.lowers_melting_point()) continue;
    l.cap = static_cast<float>(sub.eutectic_depression());
    if (sub.liquidus == LiquidusLaw::Blagden) {
      l.moles = static_cast<float>(sub.dissociation / sub.molar_mass);
      continue;
    }
    l.points = static_cast<int>(sub.liquidus_points.size());
    for (std::size_t p = 0; p < sub.liquidus_points.size(); ++p) {
      l.w[p] = static_cast<float>(sub.liquidus_points[p][0]);
      l.d[p] = static_cast<float>(sub.liquidus_points[p][1]);
    }
  }
  return out;
}

double melting_point_drop(const Scene& s, int material, const std::vector<double>& concentrations) {
  const Material& m = s.materials[static_cast<std::size_t>(material)];
  if (m.kind != MaterialKind::Fluid) return 0.0;
  // Per kg of solution, wholly liquid: kg of each substance.
  const std::vector<thermal::Liquidus> table = liquidus_table(s);
  double q[kMaxSubstances] = {};
  for (std::size_t k = 0; k < concentrations.size() && k < s.substances.size(); ++k)
    q[k] = concentrations[k] / m.density;
  return thermal::liquidus_drop(table.data(), kMaxSubstances, q, 1.0, m.cryoscopic_constant);
}

double most_dissolved(const Scene& s, int material, std::size_t k) {
  const double w = s.substances.at(k).solubility;
  return w > 0 ? w * s.materials[static_cast<std::size_t>(material)].density
               : std::numeric_limits<double>::infinity();
}

}  // namespace thaw
