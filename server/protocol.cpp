// The thaw.v1 protocol (docs/PROTOCOL.md). Each command's fields are declared once, with the schema
// builders that check scene files (sim/schema.h), so a client gets the same kind of error a scene author
// does: the field named, unknown keys with a suggestion, wrong types, non-finite numbers and ranges. The
// dryer and lamp fields are the scene schema's own declarations, so what a client may set live is what a
// scene file may hold. Whatever arrives, parse() answers with a Request or a ParseError and never throws:
// the network loop calls it on bytes from anyone.
#include "server/protocol.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "render/density_field.h"
#include "render/particle_view.h"
#include "sim/error.h"
#include "sim/json_text.h"
#include "sim/scene.h"

namespace thaw::protocol {
namespace {

constexpr int kMaxIndex = kMaxAddressable - 1;  // dryers, lamps and emitters a client may address
constexpr std::size_t kMaxIdChars = 256;        // echoed in every reply, so kept short
constexpr std::size_t kMaxNameChars = 64;       // scene and state names
constexpr std::size_t kMaxPathChars = 256;
constexpr std::size_t kMaxTokenChars = 256;

// A field that passed the schema but fails a rule the schema cannot say (a zero vector, a path-like
// name, an unspoken version). Thrown inside parse() only.
struct FieldError {
  std::string field, message;
};

// Replaces bytes that are not UTF-8 with '?': nlohmann::json refuses to serialise such strings, and error
// messages quote client text (possibly cut short mid-character).
std::string utf8_safe(std::string s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    bool ok = n != 0 && i + n <= s.size();
    for (std::size_t k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(s[i + k]) >> 6) == 0x2;
    if (ok && n > 1) {
      // Overlong forms, surrogates and code points past U+10FFFF are invalid too.
      std::uint32_t cp = c & (0xFF >> (n + 1));
      for (std::size_t k = 1; k < n; ++k) cp = (cp << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3F);
      const std::uint32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
      ok = cp >= least[n] && cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF);
    }
    if (ok) {
      i += n;
    } else {
      s[i] = '?';
      ++i;
    }
  }
  return s;
}

// Client text inside a message: escaped to ASCII and cut short, so a hostile string stays readable.
std::string shown(const std::string& s) {
  std::string q = Json(s).dump(-1, ' ', true, Json::error_handler_t::replace);
  if (q.size() > 42) q = q.substr(0, 38) + "...\"";
  return q;
}

bool is_name(const std::string& s) {
  return !s.empty() && s.size() <= kMaxNameChars && std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

// Scene and state names select files on the server: a name, never a path.
std::string checked_name(const Json& v, const std::string& field) {
  const std::string s = v.at(field).get<std::string>();
  if (!is_name(s)) {
    throw FieldError{field, shown(s) + " is not a name: use 1 to " + std::to_string(kMaxNameChars) +
                                " letters, digits, '_' and '-' (no dots, no slashes)"};
  }
  return s;
}

Eigen::Vector3d vec(const Json& v) { return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()}; }

// Directions and normals are normalised by the simulation; a zero vector has no direction.
// The scene's own rule (unit_direction), so a client and a scene file are refused alike.
Eigen::Vector3d nonzero_vec(const Json& v, const std::string& field, const std::string& what = "") {
  const Eigen::Vector3d d = vec(v);
  try {
    unit_direction(d, field);
  } catch (const SceneError&) {
    throw FieldError{field, what + "must be a non-zero vector of moderate size, got " + v.dump()};
  }
  return d;
}

template <class T>
std::optional<T> opt(const Json& v, const char* key) {
  if (!v.contains(key)) return std::nullopt;
  return v.at(key).get<T>();
}

// A scene field (e.g. "dryers[0].speed") as an optional command field: no default, since a field left
// out keeps its current value.
Field live(const std::string& scene_path) {
  const Field* f = find_field(scene_schema(), scene_path);
  if (f == nullptr) throw std::logic_error("the scene schema declares no " + scene_path);
  Field copy = *f;
  copy.default_value.reset();
  copy.absent_ok = true;
  copy.settable = false;
  return copy;
}

Field index_field(const std::string& key, const std::string& what) {
  return integer(key, "Which " + what + ": its index in the scene's " + what + "s")
      .at_least(0)
      .at_most(kMaxIndex);
}

// Names only, free of the scene schema: type_name must work even if building the table failed.
constexpr const char* kTypeNames[] = {
    "hello",       "dryer.set",  "dryer.aim",  "lamp.set",  "sim.pause",   "sim.resume",   "sim.step",
    "sim.reset",   "sim.speed",  "scene.load", "param.set", "camera.set",  "camera.orbit", "view.set",
    "quality.set", "state.save", "state.load", "frame.ack", "emitter.set", "camera.reset", "substance.drop"};
static_assert(std::size(kTypeNames) == std::variant_size_v<Command>, "one name per command");

// ---- the commands, one row each -------------------------------------------------------------------------

struct Spec {
  std::string type;
  Field fields;                              // every key but `type`, `id` and `raw_key`
  std::function<Command(const Json&)> read;  // from fields already checked against `fields`
  // A key taking any JSON, left to `read` to check: param.set's value, whose declaration depends on the path.
  std::string raw_key;
};

template <class T>
Spec row(std::string type, std::vector<Field> fields, void (*read)(T&, const Json&) = nullptr,
         std::string raw_key = "") {
  return {std::move(type), object("", std::move(fields)),
          [read](const Json& v) {
            T command{};
            if (read != nullptr) read(command, v);
            return Command(std::move(command));
          },
          std::move(raw_key)};
}

template <class T>
std::size_t index_of() {
  return Command(std::in_place_type<T>).index();
}

void read_hello(Hello& c, const Json& v) {
  c.version = v.at("version").get<int>();
  if (c.version != kVersion) {
    throw FieldError{"version", std::to_string(c.version) +
                                    " is not spoken here; this server speaks version " +
                                    std::to_string(kVersion) + " (" + kSubprotocol + ")"};
  }
  c.token = opt<std::string>(v, "token");
  if (c.token && c.token->size() > kMaxTokenChars) {
    throw FieldError{"token", "longer than " + std::to_string(kMaxTokenChars) + " characters"};
  }
}

void read_dryer_set(DryerSet& c, const Json& v) {
  c.dryer = v.at("dryer").get<int>();
  c.on = opt<bool>(v, "on");
  if (v.contains("position")) c.position = vec(v["position"]);
  if (v.contains("direction")) c.direction = nonzero_vec(v["direction"], "direction");
  c.temperature = opt<double>(v, "temperature");
  c.speed = opt<double>(v, "speed");
  c.half_angle = opt<double>(v, "half_angle");
  c.reach = opt<double>(v, "reach");
}

void read_dryer_aim(DryerAim& c, const Json& v) {
  c.dryer = v.at("dryer").get<int>();
  c.x = v.at("x").get<double>();
  c.y = v.at("y").get<double>();
}

void read_substance_drop(SubstanceDrop& c, const Json& v) {
  c.substance = v.at("substance").get<std::string>();
  c.amount = v.at("amount").get<double>();
  c.x = v.at("x").get<double>();
  c.y = v.at("y").get<double>();
}

void read_lamp_set(LampSet& c, const Json& v) {
  c.lamp = v.at("lamp").get<int>();
  c.on = opt<bool>(v, "on");
  if (v.contains("centre")) c.centre = vec(v["centre"]);
  if (v.contains("normal")) c.normal = nonzero_vec(v["normal"], "normal");
  c.temperature = opt<double>(v, "temperature");
  c.emissivity = opt<double>(v, "emissivity");
}

void read_emitter_set(EmitterSet& c, const Json& v) {
  c.emitter = v.at("emitter").get<int>();
  c.open = opt<bool>(v, "open");
  if (v.contains("position")) c.position = vec(v["position"]);
  if (v.contains("direction")) c.direction = nonzero_vec(v["direction"], "direction");
  c.radius = opt<double>(v, "radius");
  c.speed = opt<double>(v, "speed");
  c.rate = opt<double>(v, "rate");
  if (c.speed && c.rate) throw FieldError{"rate", "give the exit speed or the volume flow rate, not both"};
  c.temperature = opt<double>(v, "temperature");
  c.start = opt<double>(v, "start");
  c.stop = opt<double>(v, "stop");
}

void read_sim_step(SimStep& c, const Json& v) { c.n = v.at("n").get<int>(); }
void read_sim_speed(SimSpeed& c, const Json& v) {
  c.factor = v.at("factor").get<double>();
  // Below a millisecond a second the pacing's arithmetic runs away (1e-300 was a flat-out run).
  if (c.factor > 0 && c.factor < 1e-3)
    throw FieldError{"factor", std::to_string(c.factor) +
                                   " is out of range: must be 0 (as fast as possible) "
                                   "or in [0.001, 1000]"};
}
void read_scene_load(SceneLoad& c, const Json& v) { c.name = checked_name(v, "name"); }
void read_state_save(StateSave& c, const Json& v) { c.name = checked_name(v, "name"); }
void read_state_load(StateLoad& c, const Json& v) { c.name = checked_name(v, "name"); }
void read_frame_ack(FrameAck& c, const Json& v) { c.frame = v.at("frame").get<std::uint64_t>(); }

// Whether a concrete path ("dryers[0].speed", "materials.water.viscosity") fits a pattern from
// settable_paths ("dryers[].speed", "materials.<name>.viscosity").
bool matches(std::string_view pattern, std::string_view path) {
  std::size_t p = 0, q = 0;
  const auto name_char = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  };
  while (p < pattern.size()) {
    if (pattern[p] == '<') {
      const std::size_t close = pattern.find('>', p);
      if (close == std::string_view::npos) return false;
      const std::size_t start = q;
      while (q < path.size() && name_char(path[q])) ++q;
      if (q == start || q - start > kMaxNameChars) return false;
      p = close + 1;
    } else if (pattern.substr(p, 2) == "[]") {
      if (q >= path.size() || path[q] != '[') return false;
      const std::size_t start = ++q;
      while (q < path.size() && path[q] >= '0' && path[q] <= '9') ++q;
      if (q == start || q - start > 6 || q >= path.size() || path[q] != ']') return false;
      ++q;
      p += 2;
    } else {
      if (q >= path.size() || path[q] != pattern[p]) return false;
      ++p;
      ++q;
    }
  }
  return q == path.size();
}

const std::vector<std::string>& settable() {
  static const std::vector<std::string> paths = settable_paths(scene_schema());
  return paths;
}

void read_param_set(ParamSet& c, const Json& v) {
  c.path = v.at("path").get<std::string>();
  if (c.path.size() > kMaxPathChars) {
    throw FieldError{"path", "longer than " + std::to_string(kMaxPathChars) + " characters"};
  }
  const auto& patterns = settable();
  if (std::none_of(patterns.begin(), patterns.end(),
                   [&](const std::string& p) { return matches(p, c.path); })) {
    std::string list;
    for (const std::string& p : patterns) list += (list.empty() ? "" : ", ") + p;
    throw FieldError{"path", shown(c.path) + " is not a parameter a client may set; these are: " + list};
  }
  if (!v.contains("value")) throw FieldError{"value", "missing required key"};
  c.value = v.at("value");
  if (c.value.is_null()) throw FieldError{"value", "null does not set " + c.path};
  const Field* field = find_field(scene_schema(), c.path);
  if (field == nullptr) throw FieldError{"path", shown(c.path) + " is not declared by the scene schema"};
  try {
    validate(c.value, *field, c.path);
  } catch (const SceneError& e) {
    throw FieldError{"value", e.what()};
  }
  if (field->kind == FieldKind::Vec3 && (field->key == "direction" || field->key == "normal")) {
    nonzero_vec(c.value, "value", c.path + " ");
  }
}

void read_camera_set(CameraSet& c, const Json& v) {
  c.azimuth = opt<double>(v, "azimuth");
  c.elevation = opt<double>(v, "elevation");
  c.distance = opt<double>(v, "distance");
  c.fov = opt<double>(v, "fov");
  if (v.contains("target")) c.target = vec(v["target"]);
}

void read_camera_orbit(CameraOrbit& c, const Json& v) {
  c.d_azimuth = v.at("d_azimuth").get<double>();
  c.d_elevation = v.at("d_elevation").get<double>();
  c.zoom = v.at("zoom").get<double>();
}

void read_view_set(ViewSet& c, const Json& v) {
  c.view = v.at("view").get<std::string>();
  c.colour_by = opt<std::string>(v, "colour_by");
  if (c.colour_by) {
    try {
      check_colouring(*c.colour_by, "colour_by");
    } catch (const Error& e) {
      throw SceneError("colour_by", std::string(e.what()).substr(std::strlen("colour_by: ")));
    }
  }
  c.tint_reference = opt<double>(v, "tint_reference");  // its range: the row's schema
  // Held as a float, where anything below about 1e-45 is 0, which means "auto".
  if (c.tint_reference && *c.tint_reference > 0 && *c.tint_reference < kMinTintReference)
    throw SceneError("tint_reference", format_number(*c.tint_reference) +
                                           " g/L is neither 0 (auto) nor at least " +
                                           format_number(kMinTintReference) + " g/L");
}

void read_quality_set(QualitySet& c, const Json& v) {
  c.width = opt<int>(v, "width");
  c.height = opt<int>(v, "height");
  c.jpeg_quality = opt<int>(v, "jpeg_quality");
  c.fps = opt<double>(v, "fps");
  c.surface = opt<std::string>(v, "surface");
  c.scale = opt<double>(v, "scale");
}

std::vector<Spec> build_specs() {
  std::vector<Spec> rows;
  rows.push_back(row<Hello>(
      "hello",
      {integer("version", "Protocol version the client speaks").at_least(0).at_most(1000000),
       text("token", "Grants the controller role when it matches the server's --token").optional()},
      read_hello));
  rows.push_back(
      row<DryerSet>("dryer.set",
                    {index_field("dryer", "dryer"), live("dryers[0].on"), live("dryers[0].position"),
                     live("dryers[0].direction"), live("dryers[0].temperature"), live("dryers[0].speed"),
                     live("dryers[0].half_angle"), live("dryers[0].reach")},
                    read_dryer_set));
  rows.push_back(row<DryerAim>(
      "dryer.aim",
      {index_field("dryer", "dryer"),
       number("x", "Pixels from the left of the client's current image").at_least(0).at_most(1920),
       number("y", "Pixels from the top of the client's current image").at_least(0).at_most(1080)},
      read_dryer_aim));
  rows.push_back(
      row<LampSet>("lamp.set",
                   {index_field("lamp", "lamp"), live("lamps[0].on"), live("lamps[0].centre"),
                    live("lamps[0].normal"), live("lamps[0].temperature"), live("lamps[0].emissivity")},
                   read_lamp_set));
  rows.push_back(row<SimPause>("sim.pause", {}));
  rows.push_back(row<SimResume>("sim.resume", {}));
  rows.push_back(row<SimStep>("sim.step",
                              {integer("n", "Steps to take, then pause").def(1).at_least(1).at_most(10000)},
                              read_sim_step));
  rows.push_back(row<SimReset>("sim.reset", {}));
  rows.push_back(
      row<SimSpeed>("sim.speed",
                    {number("factor",
                            "Simulated time per wall-clock time; 0.001 is a millisecond a second, 0 as fast "
                            "as possible")
                         .at_least(0)
                         .at_most(1000)},
                    read_sim_speed));
  rows.push_back(
      row<SceneLoad>("scene.load", {text("name", "A scene in configs/, without .json")}, read_scene_load));
  rows.push_back(row<ParamSet>("param.set", {text("path", "A client-settable scene field, e.g. solver.cfl")},
                               read_param_set, "value"));
  rows.push_back(row<CameraSet>(
      "camera.set",
      {number("azimuth", "Angle about the vertical axis").in("deg").optional(),
       number("elevation", "Angle above the horizontal").in("deg").above(-90).below(90).optional(),
       number("distance", "From the target").in("m").above(0).optional(),
       number("fov", "Vertical field of view").in("deg").at_least(5).at_most(120).optional(),
       vec3("target", "The point the camera looks at").in("m").optional()},
      read_camera_set));
  rows.push_back(row<CameraOrbit>(
      "camera.orbit",
      {number("d_azimuth", "Change of azimuth").in("deg").def(0.0),
       number("d_elevation", "Change of elevation").in("deg").def(0.0),
       number("zoom", "Distance factor; < 1 moves closer").def(1.0).above(0.01).at_most(100)},
      read_camera_orbit));
  rows.push_back(row<ViewSet>(
      "view.set",
      {choice("view", {"surface", "particles", "slice"}, "What is drawn"),
       text("colour_by",
            "Colouring: phase, temperature, speed, or substance:<name> for one of the "
            "scene's substances")
           .optional(),
       number("tint_reference",
              "The surface view coloured by a substance: the concentration of full colour, 0 or at least "
              "1e-6; 0: the most any water holds in the first tinted frame")
           .in("g/L")
           .at_least(0)
           .at_most(kMaxTintReference)
           .optional()},
      read_view_set));
  rows.push_back(row<QualitySet>(
      "quality.set",
      {integer("width", "Image width").in("px").at_least(16).at_most(1920).optional(),
       integer("height", "Image height").in("px").at_least(16).at_most(1080).optional(),
       integer("jpeg_quality", "JPEG quality").at_least(10).at_most(95).optional(),
       number("fps", "Frame-rate cap").in("1/s").at_least(1).at_most(60).optional(),
       choice("surface", {"full", "fast"}, "Surface reconstruction quality").optional(),
       number("scale", "Fraction of width and height the surface march draws, stretched to the image")
           .at_least(0.25)
           .at_most(1)
           .optional()},
      read_quality_set));
  rows.push_back(
      row<StateSave>("state.save", {text("name", "A file in the server's state folder")}, read_state_save));
  rows.push_back(
      row<StateLoad>("state.load", {text("name", "A file in the server's state folder")}, read_state_load));
  rows.push_back(row<FrameAck>(
      "frame.ack", {integer("frame", "Number of the frame received, from its header").at_least(0)},
      read_frame_ack));
  rows.push_back(
      row<EmitterSet>("emitter.set",
                      {index_field("emitter", "emitter"), live("emitters[0].open"),
                       live("emitters[0].position"), live("emitters[0].direction"),
                       live("emitters[0].radius"), live("emitters[0].speed"), live("emitters[0].rate"),
                       live("emitters[0].temperature"), live("emitters[0].start"), live("emitters[0].stop")},
                      read_emitter_set));
  rows.push_back(row<CameraReset>("camera.reset", {}));
  rows.push_back(row<SubstanceDrop>(
      "substance.drop",
      {text("substance", "A substance the scene declares in `substances`"),
       number(
           "amount",
           "The dose, spread over the water and ice within a kernel's reach of the picked point (up to three "
           "kernels' where they cannot hold it)")
           .in("kg")
           .above(0)
           .at_most(0.01),
       number("x", "Pixels from the left of the client's current image").at_least(0).at_most(1920),
       number("y", "Pixels from the top of the client's current image").at_least(0).at_most(1080)},
      read_substance_drop));

  // Rows in variant order, so type_name and needs_controller index them by Command::index().
  std::vector<Spec> ordered(std::variant_size_v<Command>);
  const std::size_t indices[] = {index_of<Hello>(),       index_of<DryerSet>(),    index_of<DryerAim>(),
                                 index_of<LampSet>(),     index_of<SimPause>(),    index_of<SimResume>(),
                                 index_of<SimStep>(),     index_of<SimReset>(),    index_of<SimSpeed>(),
                                 index_of<SceneLoad>(),   index_of<ParamSet>(),    index_of<CameraSet>(),
                                 index_of<CameraOrbit>(), index_of<ViewSet>(),     index_of<QualitySet>(),
                                 index_of<StateSave>(),   index_of<StateLoad>(),   index_of<FrameAck>(),
                                 index_of<EmitterSet>(),  index_of<CameraReset>(), index_of<SubstanceDrop>()};
  static_assert(std::size(indices) == std::variant_size_v<Command>, "one row per command");
  for (std::size_t i = 0; i < rows.size(); ++i) ordered[indices[i]] = std::move(rows[i]);
  for (std::size_t i = 0; i < ordered.size(); ++i) {
    if (ordered[i].type != kTypeNames[i]) throw std::logic_error("kTypeNames is not in Command order");
  }
  return ordered;
}

const std::vector<Spec>& specs() {
  static const std::vector<Spec> table = build_specs();
  return table;
}

std::string known_types() {
  std::string out;
  for (const char* t : kTypeNames) out += (out.empty() ? "" : ", ") + std::string(t);
  return out;
}

ParseError refuse(ErrorCode code, std::string message, const std::optional<Json>& id = std::nullopt,
                  std::string type = "") {
  ParseError e{code, utf8_safe(std::move(message)), std::nullopt, std::move(type)};
  if (id) e.id = *id;
  return e;
}

std::variant<Request, ParseError> parse_checked(std::string_view text) {
  if (text.size() > kMaxMessageBytes) {
    return refuse(ErrorCode::TooLarge, "message: " + std::to_string(text.size()) +
                                           " bytes is over the limit of " + std::to_string(kMaxMessageBytes) +
                                           " bytes");
  }
  Json message;
  try {
    // Bounded nesting and no repeated keys (sim/json_text.h): the message is refused before anything
    // deep is built, and a command never runs with one of two values picked silently.
    message = parse_json(text);
  } catch (const JsonShapeError& e) {
    return refuse(ErrorCode::BadJson, std::string("message: ") + e.what());
  } catch (const Json::exception& e) {
    return refuse(ErrorCode::BadJson, std::string("message: not JSON: ") + e.what());
  }
  if (!message.is_object()) {
    return refuse(ErrorCode::BadJson,
                  std::string("message: expected a JSON object, got ") + message.type_name());
  }

  // The type is read first but judged after the id, so that an error about the id can still say `of`.
  std::string type;
  if (message.contains("type") && message["type"].is_string()) type = message["type"].get<std::string>();
  const auto* name = std::find(std::begin(kTypeNames), std::end(kTypeNames), type);
  const bool known = name != std::end(kTypeNames);

  std::optional<Json> id;
  if (message.contains("id")) {
    const Json& v = message["id"];
    const bool ok =
        v.is_number_integer() || (v.is_string() && v.get_ref<const std::string&>().size() <= kMaxIdChars);
    if (!ok) {
      return refuse(ErrorCode::BadField,
                    (known ? type : std::string("message")) + ": id: expected a string of at most " +
                        std::to_string(kMaxIdChars) + " characters or an integer, got " +
                        (v.is_string() ? "a longer string" : v.dump(-1, ' ', true)).substr(0, 60),
                    id, known ? type : "");  // `id` is still empty: this one is unreadable
    }
    id = v;
  }

  if (!message.contains("type")) {
    return refuse(ErrorCode::UnknownType, "message: type: missing; known types: " + known_types(), id);
  }
  if (!message["type"].is_string()) {
    return refuse(ErrorCode::UnknownType,
                  std::string("message: type: expected a string, got ") + message["type"].type_name() +
                      "; known types: " + known_types(),
                  id);
  }
  if (!known) {
    return refuse(ErrorCode::UnknownType,
                  "message: type: unknown type " + shown(type) + "; known types: " + known_types(), id);
  }

  const Spec& spec = specs()[static_cast<std::size_t>(name - std::begin(kTypeNames))];
  Json fields = message;
  fields.erase("type");
  fields.erase("id");
  std::optional<Json> raw;
  if (!spec.raw_key.empty() && fields.contains(spec.raw_key)) {
    raw = fields[spec.raw_key];
    fields.erase(spec.raw_key);
  }
  try {
    validate(fields, spec.fields, "");
    if (raw) fields[spec.raw_key] = std::move(*raw);
    return Request{spec.read(fields), id};
  } catch (const SceneError& e) {
    return refuse(ErrorCode::BadField, type + ": " + e.what(), id, type);
  } catch (const FieldError& e) {
    return refuse(ErrorCode::BadField, type + ": " + e.field + ": " + e.message, id, type);
  }
}

}  // namespace

const char* error_code_name(ErrorCode c) {
  switch (c) {
    case ErrorCode::BadJson:
      return "bad_json";
    case ErrorCode::TooLarge:
      return "too_large";
    case ErrorCode::UnknownType:
      return "unknown_type";
    case ErrorCode::BadField:
      return "bad_field";
    case ErrorCode::Forbidden:
      return "forbidden";
    case ErrorCode::RateLimited:
      return "rate_limited";
    case ErrorCode::NotFound:
      return "not_found";
    case ErrorCode::Failed:
      return "failed";
  }
  return "failed";
}

const char* type_name(const Command& c) { return kTypeNames[c.index()]; }

bool needs_controller(const Command& c) {
  // The camera and the view are cheap to change and bounded (the camera stays where it frames the
  // scene); anything else changes the one simulation every client watches, or, for quality.set, the
  // cost of the one frame every client shares: a viewer asking for 1920x1080 at full quality and 60
  // frames a second cut everyone to under 1 frame a second and the simulation from 50 to 4-40 steps/s.
  return !(std::holds_alternative<Hello>(c) || std::holds_alternative<CameraSet>(c) ||
           std::holds_alternative<CameraOrbit>(c) || std::holds_alternative<CameraReset>(c) ||
           std::holds_alternative<ViewSet>(c) || std::holds_alternative<FrameAck>(c));
}

std::variant<Request, ParseError> parse(std::string_view text) {
  try {
    return parse_checked(text);
  } catch (const std::exception& e) {
    // A bug here must not take the server down with it; the client learns that its message was not run.
    return refuse(ErrorCode::Failed, std::string("message: internal error: ") + e.what());
  } catch (...) {
    return refuse(ErrorCode::Failed, "message: internal error");
  }
}

Json ack(const std::optional<Json>& id, const std::string& type) {
  Json j = {{"type", "ack"}};
  if (id) j["id"] = *id;
  j["of"] = utf8_safe(type);
  return j;
}

Json error(ErrorCode code, const std::string& message, const std::optional<Json>& id,
           const std::string& type) {
  Json j = {{"type", "error"}, {"code", error_code_name(code)}, {"message", utf8_safe(message)}};
  if (id) j["id"] = *id;
  if (!type.empty()) j["of"] = utf8_safe(type);
  return j;
}

std::string frame_header(std::uint64_t frame, double sim_time, std::uint16_t width, std::uint16_t height,
                         std::uint32_t jpeg_bytes) {
  std::string out;
  out.reserve(kFrameHeaderBytes);
  const auto put = [&out](std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  out += "THF1";
  put(frame, 8);
  std::uint64_t time_bits = 0;
  static_assert(sizeof(time_bits) == sizeof(sim_time));
  std::memcpy(&time_bits, &sim_time, sizeof(time_bits));
  put(time_bits, 8);
  put(width, 2);
  put(height, 2);
  put(jpeg_bytes, 4);
  return out;
}

bool RateLimiter::allow(double now) {
  if (last_ >= 0) {
    // A clock that steps back refills nothing, and the refill resumes from the latest time seen.
    tokens_ = std::min(burst_, tokens_ + rate_ * std::max(0.0, now - last_));
    now = std::max(now, last_);
  }
  last_ = now;
  if (tokens_ < 1) return false;
  tokens_ -= 1;
  return true;
}

}  // namespace thaw::protocol
