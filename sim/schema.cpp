#include "sim/schema.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "sim/error.h"

namespace thaw {

Field& Field::in(std::string si_unit) {
  unit = std::move(si_unit);
  return *this;
}
Field& Field::def(Json value) {
  default_value = std::move(value);
  return *this;
}
Field& Field::optional() {
  absent_ok = true;
  return *this;
}
Field& Field::above(double v) {
  min = Bound{v, false};
  return *this;
}
Field& Field::at_least(double v) {
  min = Bound{v, true};
  return *this;
}
Field& Field::below(double v) {
  max = Bound{v, false};
  return *this;
}
Field& Field::at_most(double v) {
  max = Bound{v, true};
  return *this;
}
Field& Field::non_empty() {
  nonempty = true;
  return *this;
}
Field& Field::client_settable() {
  settable = true;
  return *this;
}
Field& Field::live_in_place() {
  settable = true;
  in_place = true;
  return *this;
}
Field& Field::when(std::string sibling, std::string value) {
  when_key = std::move(sibling);
  when_value = std::move(value);
  return *this;
}

bool Field::required() const {
  if (default_value || absent_ok || !when_key.empty()) return false;
  if (kind == FieldKind::Object) {
    return std::any_of(fields.begin(), fields.end(), [](const Field& f) { return f.required(); });
  }
  return true;
}

namespace {

Field make(std::string key, FieldKind kind, std::string doc) {
  Field f;
  f.key = std::move(key);
  f.kind = kind;
  f.doc = std::move(doc);
  return f;
}

}  // namespace

Field number(std::string key, std::string doc) {
  return make(std::move(key), FieldKind::Number, std::move(doc));
}
Field integer(std::string key, std::string doc) {
  return make(std::move(key), FieldKind::Integer, std::move(doc));
}
Field text(std::string key, std::string doc) {
  return make(std::move(key), FieldKind::String, std::move(doc));
}
Field flag(std::string key, std::string doc) { return make(std::move(key), FieldKind::Bool, std::move(doc)); }
Field vec3(std::string key, std::string doc) { return make(std::move(key), FieldKind::Vec3, std::move(doc)); }
Field choice(std::string key, std::vector<std::string> choices, std::string doc) {
  Field f = make(std::move(key), FieldKind::Choice, std::move(doc));
  f.choices = std::move(choices);
  return f;
}
Field subset(std::string key, std::vector<std::string> choices, std::string doc) {
  Field f = make(std::move(key), FieldKind::Subset, std::move(doc));
  f.choices = std::move(choices);
  return f;
}
Field object(std::string key, std::vector<Field> fields, std::string doc) {
  Field f = make(std::move(key), FieldKind::Object, std::move(doc));
  f.fields = std::move(fields);
  return f;
}
Field map_of(std::string key, std::string element, std::vector<Field> fields, std::string doc) {
  Field f = make(std::move(key), FieldKind::Map, std::move(doc));
  f.fields = {object(std::move(element), std::move(fields))};
  return f;
}
Field array_of(std::string key, std::vector<Field> fields, std::string doc) {
  Field f = make(std::move(key), FieldKind::Array, std::move(doc));
  f.fields = {object("[]", std::move(fields))};
  return f;
}

// ---- paths ------------------------------------------------------------------------------------------

namespace {

bool is_name(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

bool is_index(std::string_view s) {
  return !s.empty() && s.size() < 10 &&
         std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

struct PathToken {
  std::string text;
  bool bracketed = false;  // written "[2]": must index an array
};

// "a.b[2].c" and "a.b.2.c" both become {a, b, 2, c}; an unbracketed "2" indexes an array or names a key,
// whichever the container is.
std::vector<PathToken> split_path(std::string_view path) {
  std::vector<PathToken> tokens;
  std::string current;
  bool after_bracket = false;
  auto bad = [&](const std::string& why) { return SceneError(std::string(path), "bad path: " + why); };
  for (std::size_t i = 0; i < path.size(); ++i) {
    const char c = path[i];
    if (c == '.') {
      if (current.empty() && !after_bracket) throw bad("empty key before '.'");
      if (!current.empty()) tokens.push_back({current});
      current.clear();
      after_bracket = false;
    } else if (c == '[') {
      if (!current.empty())
        tokens.push_back({current});
      else if (tokens.empty())
        throw bad("'[' needs a key before it");
      current.clear();
      const std::size_t close = path.find(']', i);
      if (close == std::string_view::npos) throw bad("missing ']'");
      const std::string_view index = path.substr(i + 1, close - i - 1);
      if (!is_index(index)) throw bad("'[" + std::string(index) + "]' is not an array index");
      tokens.push_back({std::string(index), true});
      i = close;
      after_bracket = true;
    } else {
      if (after_bracket) throw bad("expected '.' or '[' after ']'");
      current += c;
    }
  }
  if (!current.empty())
    tokens.push_back({current});
  else if (!after_bracket)
    throw bad(path.empty() ? "empty path" : "path ends with '.'");
  return tokens;
}

// The declaration one step below `field`, or nullptr.
const Field* child_field(const Field* field, const PathToken& token) {
  if (field == nullptr) return nullptr;
  if (field->kind == FieldKind::Map && !token.bracketed) return &field->fields.front();
  if (field->kind == FieldKind::Array && is_index(token.text)) return &field->fields.front();
  if (field->kind != FieldKind::Object || token.bracketed) return nullptr;
  auto it = std::find_if(field->fields.begin(), field->fields.end(),
                         [&](const Field& f) { return f.key == token.text; });
  return it == field->fields.end() ? nullptr : &*it;
}

}  // namespace

std::string join_path(const std::string& path, std::string_view key) {
  if (path.empty()) return std::string(key);
  return path + "." + std::string(key);
}

std::string join_path(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

void set_at_path(Json& doc, std::string_view path, Json value, const Field* schema) {
  const std::vector<PathToken> tokens = split_path(path);
  Json* node = &doc;
  const Field* field = schema;
  std::string where;
  for (const PathToken& token : tokens) {
    if (node->is_null()) {
      // A section left out of the document: start from its declared default so that one element of
      // it ("gravity[2]") can be changed.
      if (field != nullptr && field->default_value) {
        *node = *field->default_value;
      } else {
        const bool array = field != nullptr ? field->kind == FieldKind::Array : token.bracketed;
        *node = array ? Json::array() : Json::object();
      }
    }
    field = child_field(field, token);
    if (node->is_object()) {
      if (token.bracketed) throw SceneError(where, "is an object, not an array; write ." + token.text);
      where = join_path(where, token.text);
      node = &(*node)[token.text];
    } else if (node->is_array()) {
      if (!is_index(token.text)) {
        throw SceneError(where, "is an array; '" + token.text + "' is not an index");
      }
      const std::size_t index = std::stoul(token.text);
      where = join_path(where, index);
      if (index >= node->size()) {
        throw IndexPastEndError(where, "index " + token.text + " is past the end (the array has " +
                                           std::to_string(node->size()) + " element" +
                                           (node->size() == 1 ? "" : "s") + ")");
      }
      node = &(*node)[index];
    } else {
      throw SceneError(where,
                       "is a " + std::string(node->type_name()) + ", so it has no '" + token.text + "'");
    }
  }
  *node = std::move(value);
}

const Field* find_field(const Field& root, std::string_view path) {
  const Field* field = &root;
  for (const PathToken& token : split_path(path)) field = child_field(field, token);
  return field;
}

std::vector<std::string> settable_paths(const Field& root) {
  std::vector<std::string> out;
  auto walk = [&](auto& self, const Field& f, const std::string& path) -> void {
    if (f.settable) out.push_back(path);
    for (const Field& child : f.fields) {
      if (f.kind == FieldKind::Array)
        self(self, child, path + "[]");
      else
        self(self, child, join_path(path, child.key));
    }
  };
  walk(walk, root, root.key);
  return out;
}

// ---- validation --------------------------------------------------------------------------------------

namespace {

std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string short_dump(const Json& v) {
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

std::string type_of(const Json& v) {
  if (v.is_number()) return "number " + short_dump(v);
  if (v.is_string() || v.is_boolean()) return std::string(v.type_name()) + " " + short_dump(v);
  if (v.is_array())
    return "array of " + std::to_string(v.size()) + (v.size() == 1 ? " element" : " elements");
  return v.type_name();
}

std::string kind_name(const Field& f) {
  switch (f.kind) {
    case FieldKind::Number:
      return "number";
    case FieldKind::Integer:
      return "integer";
    case FieldKind::String:
      return "string";
    case FieldKind::Bool:
      return "bool";
    case FieldKind::Vec3:
      return "array of 3 numbers [x, y, z]";
    case FieldKind::Choice:
      return "string";
    case FieldKind::Subset:
      return "array of strings";
    case FieldKind::Object:
      return "object";
    case FieldKind::Map:
      return "object (name -> object)";
    case FieldKind::Array:
      return "array of objects";
  }
  return "value";
}

[[noreturn]] void wrong_type(const Field& f, const Json& v, const std::string& path) {
  throw SceneError(path, "expected " + kind_name(f) + ", got " + type_of(v));
}

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// The one candidate within a typo's reach (one or two edits, fewer for short words), if any.
std::string closest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = word.size() < 5 ? 1 : 2;
  bool tie = false;
  for (const std::string& candidate : candidates) {
    const std::size_t d = edit_distance(lower(word), lower(candidate));
    if (d < best_distance || (d == best_distance && best.empty())) {
      best = candidate;
      best_distance = d;
      tie = false;
    } else if (d == best_distance) {
      tie = true;
    }
  }
  return tie ? std::string() : best;
}

// A typo, or an abbreviation of exactly one candidate ("wendland" for "wendland_c2").
std::string suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  std::string guess = closest(word, candidates);
  if (guess.empty() && word.size() >= 3) {
    for (const std::string& candidate : candidates) {
      if (lower(candidate).starts_with(lower(word))) {
        if (!guess.empty()) return "";
        guess = candidate;
      }
    }
  }
  return guess.empty() ? std::string() : " (did you mean '" + guess + "'?)";
}

std::string quoted_list(const std::vector<std::string>& items) {
  std::vector<std::string> quoted;
  for (const std::string& item : items) quoted.push_back("'" + item + "'");
  return join(quoted, ", ");
}

void check_range(const Field& f, double v, const std::string& path, const std::string& shown) {
  const bool low = f.min && (f.min->inclusive ? v < f.min->value : v <= f.min->value);
  const bool high = f.max && (f.max->inclusive ? v > f.max->value : v >= f.max->value);
  if (!low && !high) return;
  const std::string unit = f.unit.empty() ? "" : " " + f.unit;
  const std::string range = range_text(f);
  const bool interval = range.front() == '[' || range.front() == '(';
  throw SceneError(path,
                   shown + unit + " is out of range: must be " + (interval ? "in " : "") + range + unit);
}

void validate_number(Json& v, const Field& f, const std::string& path) {
  if (!v.is_number()) wrong_type(f, v, path);
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw SceneError(path, "expected a finite number, got " + format_number(x));
  if (f.kind == FieldKind::Integer) {
    if (!v.is_number_integer()) {
      if (x != std::floor(x) || std::abs(x) > 1e15) {
        throw SceneError(path, "expected integer, got number " + short_dump(v));
      }
      v = static_cast<std::int64_t>(x);
    }
  }
  check_range(f, x, path, short_dump(v));
}

void validate_choice(const Json& v, const Field& f, const std::string& path) {
  if (!v.is_string()) wrong_type(f, v, path);
  const std::string s = v.get<std::string>();
  if (std::find(f.choices.begin(), f.choices.end(), s) != f.choices.end()) return;
  throw SceneError(path, "'" + s + "' is not one of " + quoted_list(f.choices) + suggestion(s, f.choices));
}

void validate_elements(Json& v, const Field& f, const std::string& path) {
  if (f.nonempty && v.empty()) throw SceneError(path, "must not be empty");
  const Field& element = f.fields.front();
  if (f.kind == FieldKind::Array && f.max && double(v.size()) > f.max->value)
    throw SceneError(path, "holds " + std::to_string(v.size()) + " entries, more than the " +
                               format_number(f.max->value) + " a scene may have");
  if (f.kind == FieldKind::Array) {
    for (std::size_t i = 0; i < v.size(); ++i) validate(v[i], element, join_path(path, i));
    return;
  }
  for (auto& [name, value] : v.items()) {
    if (!is_name(name)) {
      throw SceneError(join_path(path, name),
                       "'" + name + "' is not a valid name: use letters, digits, '_' and '-'");
    }
    validate(value, element, join_path(path, name));
  }
}

void validate_object(Json& v, const std::vector<Field>& fields, const std::string& path) {
  if (!v.is_object()) throw SceneError(path, "expected object, got " + type_of(v));
  std::vector<std::string> allowed;
  for (const Field& f : fields) allowed.push_back(f.key);
  // Unknown keys first: a misspelt required key is reported as the typo, not as missing.
  for (const auto& [key, _] : v.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      throw SceneError(join_path(path, key),
                       "unknown key" + suggestion(key, allowed) + "; allowed keys: " + join(allowed, ", "));
    }
  }
  Json out = Json::object();
  for (const Field& f : fields) {
    const std::string child = join_path(path, f.key);
    const bool present = v.contains(f.key);
    if (!f.when_key.empty()) {
      const bool wanted = out.contains(f.when_key) && out.at(f.when_key) == f.when_value;
      if (present && !wanted) {
        throw SceneError(child, "only allowed when " + f.when_key + " is '" + f.when_value + "'");
      }
      if (!present && wanted && !f.default_value && !f.absent_ok) {
        throw SceneError(child, "missing: required when " + f.when_key + " is '" + f.when_value + "'");
      }
      if (!present && !wanted) continue;  // its default belongs to the other variant
    }
    if (present) {
      out[f.key] = std::move(v[f.key]);
    } else if (f.default_value) {
      out[f.key] = *f.default_value;
    } else if (f.kind == FieldKind::Object && !f.required() && f.when_key.empty() && !f.absent_ok) {
      out[f.key] = Json::object();
    } else if (f.required()) {
      throw SceneError(child, "missing required key");
    } else {
      continue;
    }
    validate(out[f.key], f, child);
  }
  v = std::move(out);
}

}  // namespace

void validate(Json& v, const Field& f, const std::string& path) {
  switch (f.kind) {
    case FieldKind::Number:
    case FieldKind::Integer:
      validate_number(v, f, path);
      return;
    case FieldKind::String:
      if (!v.is_string()) wrong_type(f, v, path);
      return;
    case FieldKind::Bool:
      if (!v.is_boolean()) wrong_type(f, v, path);
      return;
    case FieldKind::Vec3:
      if (!v.is_array() || v.size() != 3) wrong_type(f, v, path);
      for (std::size_t i = 0; i < 3; ++i) {
        if (!v[i].is_number()) throw SceneError(join_path(path, i), "expected number, got " + type_of(v[i]));
        const double x = v[i].get<double>();
        if (!std::isfinite(x)) {
          throw SceneError(join_path(path, i), "expected a finite number, got " + format_number(x));
        }
      }
      return;
    case FieldKind::Choice:
      validate_choice(v, f, path);
      return;
    case FieldKind::Subset:
      if (!v.is_array()) wrong_type(f, v, path);
      if (f.nonempty && v.empty()) throw SceneError(path, "must not be empty");
      for (std::size_t i = 0; i < v.size(); ++i) {
        validate_choice(v[i], f, join_path(path, i));
        for (std::size_t j = 0; j < i; ++j) {
          if (v[j] == v[i])
            throw SceneError(join_path(path, i), "'" + v[i].get<std::string>() + "' is listed twice");
        }
      }
      return;
    case FieldKind::Object:
      validate_object(v, f.fields, path);
      return;
    case FieldKind::Map:
      if (!v.is_object()) wrong_type(f, v, path);
      validate_elements(v, f, path);
      return;
    case FieldKind::Array:
      if (!v.is_array()) wrong_type(f, v, path);
      validate_elements(v, f, path);
      return;
  }
}

// ---- Markdown ----------------------------------------------------------------------------------------

std::string range_text(const Field& f) {
  if (f.min && f.max) {
    return (f.min->inclusive ? "[" : "(") + format_number(f.min->value) + ", " + format_number(f.max->value) +
           (f.max->inclusive ? "]" : ")");
  }
  if (f.min) return (f.min->inclusive ? ">= " : "> ") + format_number(f.min->value);
  if (f.max) return (f.max->inclusive ? "<= " : "< ") + format_number(f.max->value);
  return "";
}

namespace {

std::string cell(std::string s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

std::string code_list(const std::vector<std::string>& items) {
  std::vector<std::string> coded;
  for (const std::string& item : items) coded.push_back("`" + item + "`");
  return join(coded, ", ");
}

// Defaults read like the JSON a user would write: [0, 0, -9.81] rather than [0.0,0.0,-9.81].
std::string json_text(const Json& v) {
  if (v.is_number_float()) return format_number(v.get<double>());
  if (v.is_array()) {
    std::vector<std::string> items;
    for (const Json& item : v) items.push_back(json_text(item));
    return "[" + join(items, ", ") + "]";
  }
  return v.dump();
}

// GitHub's anchor for a heading that is only code: lower case, punctuation other than '-' and '_' gone.
std::string anchor(const std::string& heading) {
  std::string out;
  for (char c : heading) {
    if (is_name(std::string_view(&c, 1)))
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

std::string type_text(const Field& f, const std::string& section) {
  const std::string link = "see [`" + section + "`](#" + anchor(section) + ")";
  switch (f.kind) {
    case FieldKind::Vec3:
      return "[x, y, z]";
    case FieldKind::Choice:
      return "one of " + code_list(f.choices);
    case FieldKind::Subset:
      return "list of " + code_list(f.choices);
    case FieldKind::Object:
      return "object, " + link;
    case FieldKind::Map:
      return "map `" + f.fields.front().key + "` → object, " + link;
    case FieldKind::Array:
      return "array of objects, " + link;
    default:
      return kind_name(f);
  }
}

std::string default_text(const Field& f) {
  if (!f.when_key.empty()) {
    const std::string when = "when `" + f.when_key + "` is `" + f.when_value + "`";
    return f.default_value ? "`" + json_text(*f.default_value) + "` " + when : "required " + when;
  }
  if (f.default_value) return "`" + json_text(*f.default_value) + "`";
  if (f.absent_ok) return "optional";
  if (f.kind == FieldKind::Object && !f.required()) return "`{}`";
  return "required";
}

void render(const std::vector<Field>& fields, const std::string& title, const std::string& path, int level,
            std::string& out) {
  struct Nested {
    const Field* body;
    std::string path;
    std::string doc;
  };
  std::vector<Nested> nested;
  out += std::string(static_cast<std::size_t>(level), '#') + " " + title + "\n\n";
  out += "| key | type | unit | default | range | live | meaning |\n";
  out += "|---|---|---|---|---|---|---|\n";
  for (const Field& f : fields) {
    std::string child = join_path(path, f.key);
    const Field* body = &f;
    if (f.kind == FieldKind::Map) {
      child = join_path(child, f.fields.front().key);
      body = &f.fields.front();
    } else if (f.kind == FieldKind::Array) {
      child += "[]";
      body = &f.fields.front();
    }
    const std::string range = f.nonempty ? "non-empty" : range_text(f);
    out += "| `" + f.key + "` | " + cell(type_text(f, child)) + " | " + cell(f.unit) + " | " +
           cell(default_text(f)) + " | " + cell(range) + " | " +
           (f.in_place   ? "in place"
            : f.settable ? "rebuild"
                         : "") +
           " | " + cell(f.doc) + " |\n";
    if (!body->fields.empty()) nested.push_back({body, child, f.doc});
  }
  out += "\n";
  for (const Nested& n : nested) {
    std::string heading = "`" + n.path + "`";
    if (!n.doc.empty()) heading += "\n\n" + n.doc;
    render(n.body->fields, heading, n.path, level + 1 < 6 ? level + 1 : 6, out);
  }
}

}  // namespace

std::string schema_markdown(const Field& root, const std::string& title, int level) {
  std::string out;
  render(root.fields, title, root.key, level, out);
  return out;
}

}  // namespace thaw
