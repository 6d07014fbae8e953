#pragma once
// A declarative schema for JSON parameter documents: each field is declared once with its key, type,
// unit, default, range and meaning, and that one declaration drives validation (with JSON paths in
// every error), the Markdown reference, and which parameters a client may change while running.
//
//   object("", {
//       number("spacing", "Particle spacing").in("m").above(0),
//       number("cfl", "Courant number").def(0.4).above(0).at_most(1).client_settable(),
//       choice("eos", {"tait", "linear"}, "Equation of state").def("tait"),
//       array_of("fluids", {text("material", "Material name"), vec3("velocity", "").def({0, 0, 0})},
//                "Fluid blocks").non_empty(),
//   });
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sim/error.h"

namespace thaw {

using Json = nlohmann::ordered_json;

enum class FieldKind {
  Number,   // any finite number
  Integer,  // a whole number (2.0 is accepted and stored as 2)
  String,   // free text
  Bool,     // true or false
  Vec3,     // [x, y, z] of finite numbers
  Choice,   // one string out of `choices`
  Subset,   // a list of distinct strings out of `choices`
  Object,   // fixed keys: `fields`
  Map,      // name -> element object; names are letters, digits, '_' and '-'
  Array,    // list of element objects
};

struct Bound {
  double value = 0.0;
  bool inclusive = true;
};

struct Field {
  std::string key;
  FieldKind kind = FieldKind::Number;
  std::string doc;                    // one line: what it means, and what 0 or a special value does
  std::string unit;                   // SI unit, empty for dimensionless
  std::optional<Json> default_value;  // filled in when absent
  bool absent_ok = false;             // may be absent without a default
  std::optional<Bound> min, max;      // numbers and integers; max: also the most entries of an array
  bool nonempty = false;              // arrays, maps and subsets must have an element
  bool settable = false;              // a connected client may change it while the simulation runs
  bool in_place = false;              // settable, and applied to the running solver without a rebuild
  std::vector<std::string> choices;   // Choice, Subset
  std::vector<Field> fields;          // Object: its fields; Map and Array: one, the element object
  std::string when_key, when_value;   // present exactly when sibling `when_key` equals `when_value`

  // Builders, chained after the functions below; each returns *this.
  Field& in(std::string si_unit);
  Field& def(Json value);
  Field& optional();
  Field& above(double v);     // > v
  Field& at_least(double v);  // >= v
  Field& below(double v);     // < v
  Field& at_most(double v);   // <= v
  Field& non_empty();
  Field& client_settable();  // a change rebuilds the solver from the particles as they are
  Field& live_in_place();    // settable, applied between two steps without a rebuild (dryers and lamps
                             // only: Session::apply(ParamSet) pushes those into the running solver)
  Field& when(std::string sibling, std::string value);

  // Required: no default, not optional, no `when` (objects: some child is required).
  bool required() const;
};

Field number(std::string key, std::string doc);
Field integer(std::string key, std::string doc);
Field text(std::string key, std::string doc);
Field flag(std::string key, std::string doc);
Field vec3(std::string key, std::string doc);
Field choice(std::string key, std::vector<std::string> choices, std::string doc);
Field subset(std::string key, std::vector<std::string> choices, std::string doc);
Field object(std::string key, std::vector<Field> fields, std::string doc = "");
// `element` names a map key in the docs and in settable_paths, e.g. "<name>".
Field map_of(std::string key, std::string element, std::vector<Field> fields, std::string doc);
Field array_of(std::string key, std::vector<Field> fields, std::string doc);

// Checks `value` against `field` and fills in defaults in place; objects come back with their keys in
// declaration order. Throws SceneError at the exact JSON path (`path` is where `value` sits).
void validate(Json& value, const Field& field, const std::string& path = "");

// "solver" + "cfl" -> "solver.cfl"; "fluids" + 2 -> "fluids[2]".
std::string join_path(const std::string& path, std::string_view key);
std::string join_path(const std::string& path, std::size_t index);

// An index past an array's end: the path is well formed, the element does not exist (the protocol's
// not_found, where other path errors are a bad field).
class IndexPastEndError : public SceneError {
 public:
  using SceneError::SceneError;
};

// Sets the value at "a.b[2].c" (or "a.b.2.c"). A key missing from the document is created: from its
// default in `schema` when it declares one (so "gravity[2]" works on a defaulted gravity), else empty,
// so that validation then reports an unknown key at its own path. Indexing past an array's end, or into
// a value that is not an object or array, is a SceneError naming the path (IndexPastEndError for the first).
void set_at_path(Json& doc, std::string_view path, Json value, const Field* schema = nullptr);

// The declaration at a path such as "solver.cfl", "materials.water.density" or "fluids[0].box"
// ("fluids[0]" is the element object); nullptr when the schema declares no such field.
const Field* find_field(const Field& root, std::string_view path);

// Paths of every client-settable field below `root`; map keys appear as the map's element name (e.g.
// "materials.<name>.viscosity"), array indices as "[]".
std::vector<std::string> settable_paths(const Field& root);

// Markdown reference: one table per object (key, type, unit, default, range, live, meaning), the
// root's titled `title`, nested objects under headings named by their path, at `level` (2 = "##").
std::string schema_markdown(const Field& root, const std::string& title, int level = 2);

// How the docs and error messages write a range: "(0, 1]", "> 0", ">= 1"; empty when unbounded.
std::string range_text(const Field& field);

}  // namespace thaw
