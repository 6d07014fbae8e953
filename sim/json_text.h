#pragma once
// JSON text from outside the program (scene files, the scene inside a state file, `--set` values,
// protocol messages) parsed with two limits nlohmann's parser does not set: nesting depth, because
// nlohmann copies, serialises and destroys values recursively (100,000 nested objects overflowed the
// stack while a scene was copied), and keys repeated in one object, because nlohmann keeps one of them
// silently and a scene author would not learn which setting was dropped.
#include <string>
#include <string_view>

#include "sim/error.h"
#include "sim/schema.h"

namespace thaw {

// Arrays and objects nested deeper than this are refused. A scene nests 5 levels, a command 3.
inline constexpr int kMaxJsonDepth = 64;

// Nesting too deep or a repeated key, at a JSON path such as "ice[0].shape" ("(root)" for the top).
class JsonShapeError : public SceneError {
 public:
  using SceneError::SceneError;
};

// Parses `text` (with // and /* */ comments when `comments`). A syntax error is nlohmann's
// Json::parse_error (it carries the byte offset), a number out of range its Json::out_of_range; the two
// limits above are a JsonShapeError. The parse stops at the first offending bracket or key: nothing
// deeper is ever built.
Json parse_json(std::string_view text, bool comments = false);

}  // namespace thaw
