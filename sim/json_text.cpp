#include "sim/json_text.h"

#include <unordered_set>
#include <vector>

namespace thaw {

Json parse_json(std::string_view text, bool comments) {
  // Where the parser is: one frame per open array or object, so an error can name the path.
  struct Frame {
    bool array = false;
    long index = -1;  // arrays: the element being read
    std::string key;  // objects: the key being read
    std::unordered_set<std::string> keys;
  };
  std::vector<Frame> frames;
  const auto path = [&frames] {
    std::string p;
    for (const Frame& f : frames) {
      if (f.array)
        p += "[" + std::to_string(f.index) + "]";
      else if (!f.key.empty())
        p += (p.empty() ? "" : ".") + f.key;
    }
    // A path 64 levels deep is kept readable: its start and its end.
    return p.size() > 120 ? p.substr(0, 60) + "..." + p.substr(p.size() - 40) : p;
  };
  // An element of the array on top of the stack begins.
  const auto next_element = [&frames] {
    if (!frames.empty() && frames.back().array) ++frames.back().index;
  };
  using Event = Json::parse_event_t;
  const Json::parser_callback_t check = [&](int depth, Event event, Json& parsed) {
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        next_element();
        if (depth >= kMaxJsonDepth)
          throw JsonShapeError(path(), "nested deeper than " + std::to_string(kMaxJsonDepth) +
                                           " levels of arrays and objects");
        frames.push_back({event == Event::array_start, -1, {}, {}});
        break;
      case Event::key: {
        Frame& f = frames.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second)
          throw JsonShapeError(path(),
                               "key appears twice in one object; only one of the two could be used, "
                               "so neither is (remove one)");
        break;
      }
      case Event::value:
        next_element();
        break;
      case Event::object_end:
      case Event::array_end:
        frames.pop_back();
        break;
    }
    return true;
  };
  return Json::parse(text.begin(), text.end(), check, true, comments);
}

}  // namespace thaw
