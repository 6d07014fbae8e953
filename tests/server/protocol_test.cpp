// The thaw.v1 protocol without sockets: every command from a valid message, every way a message is
// refused (with its code and the field named), the events' JSON, the binary frame header, the rate
// limiter, and a fuzz loop showing that parse() takes any bytes without throwing.
#include "server/protocol.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "sim/scene.h"

namespace thaw::protocol {
namespace {

// The command a valid message parses into; fails the test (and returns a default) otherwise.
template <class T>
T parsed(const std::string& text, std::optional<Json>* id = nullptr) {
  auto result = parse(text);
  if (const auto* e = std::get_if<ParseError>(&result)) {
    ADD_FAILURE() << text << "\n  refused: " << e->message;
    return T{};
  }
  const Request& request = std::get<Request>(result);
  if (id != nullptr) *id = request.id;
  if (!std::holds_alternative<T>(request.command)) {
    ADD_FAILURE() << text << "\n  parsed as " << type_name(request.command);
    return T{};
  }
  return std::get<T>(request.command);
}

// The refusal of a bad message; fails the test when it parses.
ParseError refused(const std::string& text) {
  auto result = parse(text);
  if (std::holds_alternative<Request>(result)) {
    ADD_FAILURE() << text << "\n  was accepted";
    return {ErrorCode::Failed, "", {}, ""};
  }
  return std::get<ParseError>(result);
}

// A refusal with its code, whose message starts with `prefix` (the type, or "message" before the type
// is known) and names `field`.
void expect_refused(const std::string& text, ErrorCode code, const std::string& prefix,
                    const std::string& field) {
  SCOPED_TRACE(text);
  const ParseError e = refused(text);
  EXPECT_EQ(error_code_name(e.code), std::string(error_code_name(code))) << e.message;
  EXPECT_EQ(e.message.rfind(prefix + ": ", 0), 0u) << e.message;
  EXPECT_NE(e.message.find(field), std::string::npos) << "does not name '" << field << "': " << e.message;
}

// One valid message per command: the round trip, the needs_controller table and the fuzz seeds.
const std::vector<std::string>& valid_messages() {
  static const std::vector<std::string> messages = {
      R"({"type":"hello","version":1,"id":"h1"})",
      R"({"type":"dryer.set","dryer":0,"on":true,"position":[0.5,0.1,0.3],"direction":[-1,0,-1],)"
      R"("temperature":80,"speed":12.5,"half_angle":20,"reach":0.4,"id":7})",
      R"({"type":"dryer.aim","dryer":1,"x":320,"y":240})",
      R"({"type":"lamp.set","lamp":0,"on":false,"centre":[0,0,1],"normal":[0,0,-1],"temperature":600,)"
      R"("emissivity":0.8})",
      R"({"type":"sim.pause"})",
      R"({"type":"sim.resume"})",
      R"({"type":"sim.step","n":10})",
      R"({"type":"sim.reset"})",
      R"({"type":"sim.speed","factor":2})",
      R"({"type":"scene.load","name":"ice_cube-2"})",
      R"({"type":"param.set","path":"solver.cfl","value":0.3})",
      R"({"type":"camera.set","azimuth":30,"elevation":20,"distance":1.5,"fov":45,"target":[0.2,0.1,0]})",
      R"({"type":"camera.orbit","d_azimuth":5,"d_elevation":-2,"zoom":1.1})",
      R"({"type":"view.set","view":"particles","colour_by":"temperature"})",
      R"({"type":"quality.set","width":640,"height":480,"jpeg_quality":80,"fps":15,"surface":"fast"})",
      R"({"type":"state.save","name":"before_melt"})",
      R"({"type":"state.load","name":"before_melt"})",
      R"({"type":"frame.ack","frame":42})",
      R"({"type":"emitter.set","emitter":0,"open":true,"position":[0.04,0.04,0.09],"direction":[0,1,-2],)"
      R"("radius":0.006,"speed":0.8,"temperature":40,"start":0.5,"stop":3})",
      R"({"type":"camera.reset"})",
      R"({"type":"substance.drop","substance":"salt","amount":0.0001,"x":320,"y":240})",
  };
  return messages;
}

// ---- every command from a valid message -------------------------------------------------------------

TEST(ProtocolParse, EveryCommandRoundTripsItsType) {
  ASSERT_EQ(valid_messages().size(), std::variant_size_v<Command>);
  for (std::size_t i = 0; i < valid_messages().size(); ++i) {
    const std::string& text = valid_messages()[i];
    auto result = parse(text);
    ASSERT_TRUE(std::holds_alternative<Request>(result))
        << text << ": " << std::get<ParseError>(result).message;
    const Command& c = std::get<Request>(result).command;
    EXPECT_EQ(c.index(), i) << text;
    EXPECT_EQ(Json::parse(text)["type"], type_name(c));
  }
}

TEST(ProtocolParse, Hello) {
  std::optional<Json> id;
  Hello h = parsed<Hello>(R"({"type":"hello","version":1,"token":"s3cret","id":"a-1"})", &id);
  EXPECT_EQ(h.version, kVersion);
  EXPECT_EQ(h.token, "s3cret");
  EXPECT_EQ(id, Json("a-1"));
  h = parsed<Hello>(R"({"type":"hello","version":1})", &id);
  EXPECT_FALSE(h.token);
  EXPECT_FALSE(id);
}

TEST(ProtocolParse, IdIsAStringOrAnInteger) {
  std::optional<Json> id;
  parsed<SimPause>(R"({"type":"sim.pause","id":12})", &id);
  EXPECT_EQ(id, Json(12));
  parsed<SimPause>(R"({"id":"x","type":"sim.pause"})", &id);
  EXPECT_EQ(id, Json("x"));
  parsed<SimPause>(R"({"type":"sim.pause","id":-3})", &id);
  EXPECT_EQ(id, Json(-3));
}

TEST(ProtocolParse, DryerSet) {
  std::optional<Json> id;
  const DryerSet d = parsed<DryerSet>(valid_messages()[1], &id);
  EXPECT_EQ(d.dryer, 0);
  EXPECT_EQ(d.on, true);
  ASSERT_TRUE(d.position && d.direction);
  EXPECT_EQ(*d.position, Eigen::Vector3d(0.5, 0.1, 0.3));
  EXPECT_EQ(*d.direction, Eigen::Vector3d(-1, 0, -1));
  EXPECT_EQ(d.temperature, 80.0);
  EXPECT_EQ(d.speed, 12.5);
  EXPECT_EQ(d.half_angle, 20.0);
  EXPECT_EQ(d.reach, 0.4);
  EXPECT_EQ(id, Json(7));

  // Fields left out keep their current value: nothing is filled in.
  const DryerSet only = parsed<DryerSet>(R"({"type":"dryer.set","dryer":63,"speed":0})");
  EXPECT_EQ(only.dryer, 63);
  EXPECT_EQ(only.speed, 0.0);
  EXPECT_FALSE(only.on || only.position || only.direction || only.temperature || only.half_angle ||
               only.reach);

  // Limits at their edges: temperature (-100, 500], half_angle (0, 60], reach (0, 10], speed [0, 100].
  const DryerSet edge = parsed<DryerSet>(
      R"({"type":"dryer.set","dryer":2,"temperature":500,"half_angle":60,"reach":10,"speed":100})");
  EXPECT_EQ(edge.temperature, 500.0);
  EXPECT_EQ(edge.speed, 100.0);
  // A whole-number float is an index.
  EXPECT_EQ(parsed<DryerSet>(R"({"type":"dryer.set","dryer":3.0})").dryer, 3);
}

TEST(ProtocolParse, DryerAim) {
  const DryerAim a = parsed<DryerAim>(valid_messages()[2]);
  EXPECT_EQ(a.dryer, 1);
  EXPECT_EQ(a.x, 320.0);
  EXPECT_EQ(a.y, 240.0);
  EXPECT_EQ(parsed<DryerAim>(R"({"type":"dryer.aim","dryer":0,"x":0.5,"y":0})").x, 0.5);
}

TEST(ProtocolParse, SubstanceDrop) {
  const SubstanceDrop d = parsed<SubstanceDrop>(valid_messages().back());
  EXPECT_EQ(d.substance, "salt");
  EXPECT_EQ(d.amount, 0.0001);
  EXPECT_EQ(d.x, 320.0);
  EXPECT_EQ(d.y, 240.0);
  EXPECT_TRUE(needs_controller(Command{d}));
}

TEST(ProtocolParse, LampSet) {
  const LampSet l = parsed<LampSet>(valid_messages()[3]);
  EXPECT_EQ(l.lamp, 0);
  EXPECT_EQ(l.on, false);
  EXPECT_EQ(*l.centre, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(*l.normal, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(l.temperature, 600.0);
  EXPECT_EQ(l.emissivity, 0.8);
  const LampSet few = parsed<LampSet>(R"({"type":"lamp.set","lamp":5,"emissivity":1})");
  EXPECT_EQ(few.lamp, 5);
  EXPECT_FALSE(few.on || few.centre || few.normal || few.temperature);
}

TEST(ProtocolParse, EmitterSet) {
  const EmitterSet e = parsed<EmitterSet>(valid_messages()[18]);
  EXPECT_EQ(e.emitter, 0);
  EXPECT_EQ(e.open, true);
  EXPECT_EQ(*e.position, Eigen::Vector3d(0.04, 0.04, 0.09));
  EXPECT_EQ(*e.direction, Eigen::Vector3d(0, 1, -2));
  EXPECT_EQ(e.radius, 0.006);
  EXPECT_EQ(e.speed, 0.8);
  EXPECT_FALSE(e.rate);
  EXPECT_EQ(e.temperature, 40.0);
  EXPECT_EQ(e.start, 0.5);
  EXPECT_EQ(e.stop, 3.0);
  // The tap alone, or a flow in litres per second: nothing else is filled in.
  const EmitterSet tap = parsed<EmitterSet>(R"({"type":"emitter.set","emitter":2,"open":false})");
  EXPECT_EQ(tap.emitter, 2);
  EXPECT_EQ(tap.open, false);
  EXPECT_FALSE(tap.position || tap.direction || tap.radius || tap.speed || tap.rate || tap.temperature ||
               tap.start || tap.stop);
  EXPECT_EQ(parsed<EmitterSet>(R"({"type":"emitter.set","emitter":0,"rate":0.05})").rate, 0.05);
}

TEST(ProtocolParse, SimulationControl) {
  parsed<SimPause>(R"({"type":"sim.pause"})");
  parsed<SimResume>(R"({"type":"sim.resume"})");
  parsed<SimReset>(R"({"type":"sim.reset"})");
  EXPECT_EQ(parsed<SimStep>(R"({"type":"sim.step","n":10})").n, 10);
  EXPECT_EQ(parsed<SimStep>(R"({"type":"sim.step"})").n, 1);
  EXPECT_EQ(parsed<SimStep>(R"({"type":"sim.step","n":10000})").n, 10000);
  EXPECT_EQ(parsed<SimSpeed>(R"({"type":"sim.speed","factor":0.25})").factor, 0.25);
  EXPECT_EQ(parsed<SimSpeed>(R"({"type":"sim.speed","factor":0})").factor, 0.0) << "as fast as possible";
  EXPECT_EQ(parsed<SimSpeed>(R"({"type":"sim.speed","factor":1000})").factor, 1000.0);
}

TEST(ProtocolParse, SceneAndStateNames) {
  EXPECT_EQ(parsed<SceneLoad>(valid_messages()[9]).name, "ice_cube-2");
  EXPECT_EQ(parsed<StateSave>(valid_messages()[15]).name, "before_melt");
  EXPECT_EQ(parsed<StateLoad>(valid_messages()[16]).name, "before_melt");
  const std::string longest(64, 'a');
  EXPECT_EQ(parsed<StateSave>(R"({"type":"state.save","name":")" + longest + "\"}").name, longest);
}

TEST(ProtocolParse, ParamSet) {
  ParamSet p = parsed<ParamSet>(valid_messages()[10]);
  EXPECT_EQ(p.path, "solver.cfl");
  EXPECT_EQ(p.value, Json(0.3));
  p = parsed<ParamSet>(R"({"type":"param.set","path":"dryers[0].speed","value":40})");
  EXPECT_EQ(p.path, "dryers[0].speed");
  EXPECT_EQ(p.value, Json(40));
  p = parsed<ParamSet>(R"({"type":"param.set","path":"gravity","value":[0,0,-1.62]})");
  EXPECT_EQ(p.value, Json::parse("[0,0,-1.62]"));
  p = parsed<ParamSet>(R"({"type":"param.set","path":"dryers[2].on","value":false})");
  EXPECT_EQ(p.value, Json(false));
  p = parsed<ParamSet>(R"({"type":"param.set","path":"lamps[0].normal","value":[0,1,0]})");
  EXPECT_EQ(p.path, "lamps[0].normal");
}

TEST(ProtocolParse, ParamSetAcceptsEverySettablePath) {
  // Each pattern made concrete ("dryers[].speed" -> "dryers[0].speed", "<name>" -> "water") passes the
  // path check; its value may still be refused, but never as an unknown path.
  for (std::string path : settable_paths(scene_schema())) {
    SCOPED_TRACE(path);
    for (std::size_t at; (at = path.find("[]")) != std::string::npos;) path.replace(at, 2, "[0]");
    for (std::size_t at; (at = path.find('<')) != std::string::npos;)
      path.replace(at, path.find('>') - at + 1, "water");
    auto result = parse(Json{{"type", "param.set"}, {"path", path}, {"value", "x"}}.dump());
    if (const auto* e = std::get_if<ParseError>(&result)) {
      EXPECT_EQ(e->message.find("param.set: path:"), std::string::npos) << e->message;
    }
  }
}

TEST(ProtocolParse, Camera) {
  const CameraSet c = parsed<CameraSet>(valid_messages()[11]);
  EXPECT_EQ(c.azimuth, 30.0);
  EXPECT_EQ(c.elevation, 20.0);
  EXPECT_EQ(c.distance, 1.5);
  EXPECT_EQ(c.fov, 45.0);
  EXPECT_EQ(*c.target, Eigen::Vector3d(0.2, 0.1, 0));
  const CameraSet none = parsed<CameraSet>(R"({"type":"camera.set"})");
  EXPECT_FALSE(none.azimuth || none.elevation || none.distance || none.fov || none.target);

  const CameraOrbit o = parsed<CameraOrbit>(valid_messages()[12]);
  EXPECT_EQ(o.d_azimuth, 5.0);
  EXPECT_EQ(o.d_elevation, -2.0);
  EXPECT_EQ(o.zoom, 1.1);
  const CameraOrbit zoom_only = parsed<CameraOrbit>(R"({"type":"camera.orbit","zoom":0.5})");
  EXPECT_EQ(zoom_only.d_azimuth, 0.0);
  EXPECT_EQ(zoom_only.d_elevation, 0.0);
  EXPECT_EQ(zoom_only.zoom, 0.5);
  EXPECT_EQ(parsed<CameraOrbit>(R"({"type":"camera.orbit","d_azimuth":3})").zoom, 1.0);
}

TEST(ProtocolParse, ViewAndQuality) {
  const ViewSet v = parsed<ViewSet>(valid_messages()[13]);
  EXPECT_EQ(v.view, "particles");
  EXPECT_EQ(v.colour_by, "temperature");
  const ViewSet slice = parsed<ViewSet>(R"({"type":"view.set","view":"slice"})");
  EXPECT_EQ(slice.view, "slice");
  EXPECT_FALSE(slice.colour_by);
  EXPECT_EQ(parsed<ViewSet>(R"({"type":"view.set","view":"slice","colour_by":"substance:salt"})").colour_by,
            "substance:salt");
  EXPECT_FALSE(slice.tint_reference);
  EXPECT_EQ(parsed<ViewSet>(
                R"({"type":"view.set","view":"surface","colour_by":"substance:dye","tint_reference":20})")
                .tint_reference,
            20.0);

  const QualitySet q = parsed<QualitySet>(valid_messages()[14]);
  EXPECT_EQ(q.width, 640);
  EXPECT_EQ(q.height, 480);
  EXPECT_EQ(q.jpeg_quality, 80);
  EXPECT_EQ(q.fps, 15.0);
  EXPECT_EQ(q.surface, "fast");
  const QualitySet fps_only = parsed<QualitySet>(R"({"type":"quality.set","fps":60})");
  EXPECT_FALSE(fps_only.width || fps_only.height || fps_only.jpeg_quality || fps_only.surface ||
               fps_only.scale);
  EXPECT_EQ(parsed<QualitySet>(R"({"type":"quality.set","scale":0.5})").scale, 0.5);
}

TEST(ProtocolParse, FrameAck) {
  EXPECT_EQ(parsed<FrameAck>(valid_messages()[17]).frame, 42u);
  EXPECT_EQ(parsed<FrameAck>(R"({"type":"frame.ack","frame":0})").frame, 0u);
  EXPECT_EQ(parsed<FrameAck>(R"({"type":"frame.ack","frame":18446744073709551615})").frame,
            18446744073709551615ull);
}

// ---- the envelope: size, JSON, type, id --------------------------------------------------------------

TEST(ProtocolRefuse, Oversize) {
  const std::string base = R"({"type":"sim.pause"})";
  std::string at_limit = base + std::string(kMaxMessageBytes - base.size(), ' ');
  ASSERT_EQ(at_limit.size(), kMaxMessageBytes);
  parsed<SimPause>(at_limit);
  expect_refused(at_limit + " ", ErrorCode::TooLarge, "message", std::to_string(kMaxMessageBytes));
  // The size is judged before the JSON: a huge non-JSON message is too large, not bad JSON.
  expect_refused(std::string(1 << 20, '{'), ErrorCode::TooLarge, "message", "bytes");
}

TEST(ProtocolRefuse, NotJsonOrNotAnObject) {
  for (const std::string text : {"", "{", "nul", "{\"type\":\"sim.pause\",}", "{'type':'sim.pause'}",
                                 "{\"type\":\"sim.pause\"} trailing", "\xff\xfe", "{\"type\":\"\xc3\"}"}) {
    expect_refused(text, ErrorCode::BadJson, "message", "JSON");
  }
  for (const std::string text : {"[]", R"([{"type":"sim.pause"}])", "\"sim.pause\"", "42", "null", "true"}) {
    expect_refused(text, ErrorCode::BadJson, "message", "object");
  }
  // JSON has no NaN or Inf; a number too large for a double is refused as unreadable.
  expect_refused(R"({"type":"sim.speed","factor":1e400})", ErrorCode::BadJson, "message", "JSON");
  expect_refused(R"({"type":"sim.speed","factor":NaN})", ErrorCode::BadJson, "message", "JSON");
  expect_refused(R"({"type":"sim.speed","factor":Infinity})", ErrorCode::BadJson, "message", "JSON");
  // Deep nesting is refused at the first bracket too deep, before anything deeper is built.
  expect_refused(R"({"type":"param.set","path":"solver.cfl","value":)" + std::string(100, '[') +
                     std::string(100, ']') + "}",
                 ErrorCode::BadJson, "message", "nested");
  expect_refused(std::string(8000, '[') + std::string(8000, ']'), ErrorCode::BadJson, "message", "nested");
  // A pace so slow it overflowed the session's clock arithmetic.
  expect_refused(R"({"type":"sim.speed","factor":1e-300})", ErrorCode::BadField, "sim.speed", "factor");
  // A key given twice is refused, naming it, rather than one of the two values picked silently.
  expect_refused(R"({"type":"dryer.set","dryer":0,"speed":5,"speed":90})", ErrorCode::BadJson, "message",
                 "speed: key appears twice");
}

TEST(ProtocolRefuse, Type) {
  expect_refused(R"({"id":1})", ErrorCode::UnknownType, "message", "type");
  expect_refused(R"({"type":3})", ErrorCode::UnknownType, "message", "type");
  expect_refused(R"({"type":null})", ErrorCode::UnknownType, "message", "type");
  expect_refused(R"({"type":"dryer.fly"})", ErrorCode::UnknownType, "message", "dryer.fly");
  // The message lists what the server knows, and the id still comes back.
  const ParseError e = refused(R"({"type":"Hello","id":"q"})");
  EXPECT_EQ(e.code, ErrorCode::UnknownType);
  for (const char* known : {"hello", "dryer.set", "param.set", "frame.ack"}) {
    EXPECT_NE(e.message.find(known), std::string::npos) << e.message;
  }
  EXPECT_EQ(e.id, Json("q"));
  EXPECT_EQ(e.type, "");
}

TEST(ProtocolRefuse, Id) {
  for (const std::string& id : std::vector<std::string>{"1.5", "true", "null", "[1]", "{\"a\":1}",
                                                        "\"" + std::string(300, 'x') + "\""}) {
    const std::string text = R"({"type":"sim.pause","id":)" + id + "}";
    expect_refused(text, ErrorCode::BadField, "sim.pause", "id");
    const ParseError e = refused(text);
    EXPECT_FALSE(e.id);
    EXPECT_EQ(e.type, "sim.pause");
  }
  expect_refused(R"({"type":"nope","id":false})", ErrorCode::BadField, "message", "id");
}

TEST(ProtocolRefuse, ErrorsCarryIdAndType) {
  const ParseError e = refused(R"({"type":"dryer.set","dryer":0,"speed":250,"id":"d7"})");
  EXPECT_EQ(e.code, ErrorCode::BadField);
  EXPECT_EQ(e.id, Json("d7"));
  EXPECT_EQ(e.type, "dryer.set");
  EXPECT_NE(e.message.find("250"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("100"), std::string::npos) << e.message;  // the limit is said
}

// ---- each command's fields ---------------------------------------------------------------------------

struct BadCase {
  std::string text, type, field;
};

void expect_bad_fields(const std::vector<BadCase>& cases) {
  for (const BadCase& c : cases) {
    expect_refused(c.text, ErrorCode::BadField, c.type, c.field);
    EXPECT_EQ(refused(c.text).type, c.type);
  }
}

TEST(ProtocolRefuse, UnknownFieldsAreNamed) {
  expect_bad_fields({
      {R"({"type":"dryer.set","dryer":0,"sped":3})", "dryer.set", "sped"},
      {R"({"type":"sim.pause","now":true})", "sim.pause", "now"},
      {R"({"type":"sim.reset","hard":1})", "sim.reset", "hard"},
      {R"({"type":"sim.resume","x":1})", "sim.resume", "x"},
      {R"({"type":"hello","version":1,"name":"me"})", "hello", "name"},
      {R"({"type":"frame.ack","frame":1,"ts":5})", "frame.ack", "ts"},
  });
  EXPECT_NE(refused(R"({"type":"dryer.set","dryer":0,"sped":3})").message.find("did you mean 'speed'"),
            std::string::npos);
}

TEST(ProtocolRefuse, Hello) {
  expect_bad_fields({
      {R"({"type":"hello"})", "hello", "version"},
      {R"({"type":"hello","version":"1"})", "hello", "version"},
      {R"({"type":"hello","version":1.5})", "hello", "version"},
      {R"({"type":"hello","version":1,"token":7})", "hello", "token"},
      {R"({"type":"hello","version":1,"token":")" + std::string(300, 't') + "\"}", "hello", "token"},
  });
  // A version the server does not speak: the message says which it does.
  const ParseError e = refused(R"({"type":"hello","version":2})");
  EXPECT_EQ(e.code, ErrorCode::BadField);
  EXPECT_EQ(e.message.rfind("hello: version: ", 0), 0u) << e.message;
  EXPECT_NE(e.message.find("speaks version " + std::to_string(kVersion)), std::string::npos) << e.message;
}

TEST(ProtocolRefuse, DryerSet) {
  const std::string d = R"({"type":"dryer.set","dryer":0,)";
  expect_bad_fields({
      {R"({"type":"dryer.set","speed":3})", "dryer.set", "dryer"},
      {R"({"type":"dryer.set","dryer":"0"})", "dryer.set", "dryer"},
      {R"({"type":"dryer.set","dryer":0.5})", "dryer.set", "dryer"},
      {R"({"type":"dryer.set","dryer":-1})", "dryer.set", "dryer"},
      {R"({"type":"dryer.set","dryer":64})", "dryer.set", "dryer"},
      {d + R"("on":1})", "dryer.set", "on"},
      {d + R"("on":"true"})", "dryer.set", "on"},
      {d + R"("position":[0,0]})", "dryer.set", "position"},
      {d + R"("position":[0,0,0,0]})", "dryer.set", "position"},
      {d + R"("position":[0,"1",0]})", "dryer.set", "position[1]"},
      {d + R"("position":{"x":0,"y":0,"z":0}})", "dryer.set", "position"},
      {d + R"("direction":[0,0,0]})", "dryer.set", "direction"},
      {d + R"("direction":[1e308,1e308,1e308]})", "dryer.set", "direction"},
      {d + R"("direction":[0,null,-1]})", "dryer.set", "direction[1]"},
      {d + R"("temperature":"hot"})", "dryer.set", "temperature"},
      {d + R"("temperature":-100})", "dryer.set", "temperature"},
      {d + R"("temperature":501})", "dryer.set", "temperature"},
      {d + R"("speed":-0.1})", "dryer.set", "speed"},
      {d + R"("speed":250})", "dryer.set", "speed"},
      {d + R"("half_angle":0})", "dryer.set", "half_angle"},
      {d + R"("half_angle":61})", "dryer.set", "half_angle"},
      {d + R"("reach":0})", "dryer.set", "reach"},
      {d + R"("reach":11})", "dryer.set", "reach"},
      {d + R"("speed":null})", "dryer.set", "speed"},
  });
}

TEST(ProtocolRefuse, DryerAim) {
  expect_bad_fields({
      {R"({"type":"dryer.aim","x":1,"y":1})", "dryer.aim", "dryer"},
      {R"({"type":"dryer.aim","dryer":0,"y":1})", "dryer.aim", "x"},
      {R"({"type":"dryer.aim","dryer":0,"x":1})", "dryer.aim", "y"},
      {R"({"type":"dryer.aim","dryer":0,"x":"1","y":1})", "dryer.aim", "x"},
      {R"({"type":"dryer.aim","dryer":0,"x":-1,"y":1})", "dryer.aim", "x"},
      {R"({"type":"dryer.aim","dryer":0,"x":1,"y":5000})", "dryer.aim", "y"},
      {R"({"type":"dryer.aim","dryer":99,"x":1,"y":1})", "dryer.aim", "dryer"},
  });
}

TEST(ProtocolRefuse, SubstanceDrop) {
  expect_bad_fields({
      {R"({"type":"substance.drop","amount":0.001,"x":1,"y":1})", "substance.drop", "substance"},
      {R"({"type":"substance.drop","substance":"salt","x":1,"y":1})", "substance.drop", "amount"},
      {R"({"type":"substance.drop","substance":"salt","amount":0,"x":1,"y":1})", "substance.drop", "amount"},
      {R"({"type":"substance.drop","substance":"salt","amount":-1,"x":1,"y":1})", "substance.drop", "amount"},
      {R"({"type":"substance.drop","substance":"salt","amount":1,"x":1,"y":1})", "substance.drop", "amount"},
      {R"({"type":"substance.drop","substance":7,"amount":0.001,"x":1,"y":1})", "substance.drop",
       "substance"},
      {R"({"type":"substance.drop","substance":"salt","amount":0.001,"y":1})", "substance.drop", "x"},
      {R"({"type":"substance.drop","substance":"salt","amount":0.001,"x":1,"y":5000})", "substance.drop",
       "y"},
  });
}

TEST(ProtocolRefuse, LampSet) {
  const std::string l = R"({"type":"lamp.set","lamp":0,)";
  expect_bad_fields({
      {R"({"type":"lamp.set","on":true})", "lamp.set", "lamp"},
      {R"({"type":"lamp.set","lamp":64})", "lamp.set", "lamp"},
      {l + R"("on":0})", "lamp.set", "on"},
      {l + R"("centre":[1,2]})", "lamp.set", "centre"},
      {l + R"("normal":[0,0,0]})", "lamp.set", "normal"},
      {l + R"("temperature":-273.15})", "lamp.set", "temperature"},
      {l + R"("temperature":3001})", "lamp.set", "temperature"},
      {l + R"("emissivity":0})", "lamp.set", "emissivity"},
      {l + R"("emissivity":1.01})", "lamp.set", "emissivity"},
      {l + R"("emissivity":[0.5]})", "lamp.set", "emissivity"},
  });
}

TEST(ProtocolRefuse, EmitterSet) {
  const std::string e = R"({"type":"emitter.set","emitter":0,)";
  expect_bad_fields({
      {R"({"type":"emitter.set","open":true})", "emitter.set", "emitter"},
      {R"({"type":"emitter.set","emitter":64})", "emitter.set", "emitter"},
      {e + R"("open":1})", "emitter.set", "open"},
      {e + R"("direction":[0,0,0]})", "emitter.set", "direction"},
      {e + R"("radius":0})", "emitter.set", "radius"},
      {e + R"("speed":0})", "emitter.set", "speed"},
      {e + R"("speed":51})", "emitter.set", "speed"},
      {e + R"("rate":-1})", "emitter.set", "rate"},
      {e + R"("speed":1,"rate":0.1})", "emitter.set", "rate"},
      {e + R"("temperature":-300})", "emitter.set", "temperature"},
      {e + R"("stop":-1})", "emitter.set", "stop"},
      {e + R"("material":"water"})", "emitter.set", "material"},
  });
}

TEST(ProtocolRefuse, SimulationControl) {
  expect_bad_fields({
      {R"({"type":"sim.step","n":0})", "sim.step", "n"},
      {R"({"type":"sim.step","n":10001})", "sim.step", "n"},
      {R"({"type":"sim.step","n":2.5})", "sim.step", "n"},
      {R"({"type":"sim.step","n":"5"})", "sim.step", "n"},
      {R"({"type":"sim.speed"})", "sim.speed", "factor"},
      {R"({"type":"sim.speed","factor":0.0005})", "sim.speed", "factor"},
      {R"({"type":"sim.speed","factor":-1})", "sim.speed", "factor"},
      {R"({"type":"sim.speed","factor":1001})", "sim.speed", "factor"},
      {R"({"type":"sim.speed","factor":"fast"})", "sim.speed", "factor"},
  });
}

TEST(ProtocolRefuse, NamesAreNeverPaths) {
  for (const std::string type : {"scene.load", "state.save", "state.load"}) {
    const std::string head = R"({"type":")" + type + R"(","name":)";
    expect_bad_fields({
        {R"({"type":")" + type + "\"}", type, "name"},
        {head + "3}", type, "name"},
        {head + R"("../x"})", type, "name"},
        {head + R"("a/b"})", type, "name"},
        {head + R"("a\\b"})", type, "name"},
        {head + R"("x.json"})", type, "name"},
        {head + R"(""})", type, "name"},
        {head + R"("/etc/passwd"})", type, "name"},
        {head + R"("a b"})", type, "name"},
        {head + R"("caf\u00e9"})", type, "name"},
        {head + R"("x\u0000y"})", type, "name"},
        {head + "\"" + std::string(65, 'a') + "\"}", type, "name"},
    });
  }
}

TEST(ProtocolRefuse, ParamSet) {
  expect_bad_fields({
      {R"({"type":"param.set","value":1})", "param.set", "path"},
      {R"({"type":"param.set","path":"solver.cfl"})", "param.set", "value"},
      {R"({"type":"param.set","path":"solver.cfl","value":null})", "param.set", "value"},
      {R"({"type":"param.set","path":5,"value":1})", "param.set", "path"},
      // Declared by the scene, but not settable while running.
      {R"({"type":"param.set","path":"spacing","value":0.01})", "param.set", "spacing"},
      {R"({"type":"param.set","path":"dryers[0].nozzle_diameter","value":0.05})", "param.set",
       "dryers[0].nozzle_diameter"},
      // Not paths of settable fields at all.
      {R"({"type":"param.set","path":"solver","value":{}})", "param.set", "path"},
      {R"({"type":"param.set","path":"dryers[0]","value":{}})", "param.set", "path"},
      {R"({"type":"param.set","path":"dryers[x].speed","value":1})", "param.set", "path"},
      {R"({"type":"param.set","path":"dryers.0.speed","value":1})", "param.set", "path"},
      {R"({"type":"param.set","path":"dryers[].speed","value":1})", "param.set", "path"},
      {R"({"type":"param.set","path":"solver.cfl.x","value":1})", "param.set", "path"},
      {R"({"type":"param.set","path":"../solver.cfl","value":1})", "param.set", "path"},
      {R"({"type":"param.set","path":"","value":1})", "param.set", "path"},
      // Settable, but the value breaks the field's declaration: the path is named.
      {R"({"type":"param.set","path":"dryers[0].speed","value":250})", "param.set", "dryers[0].speed"},
      {R"({"type":"param.set","path":"dryers[0].speed","value":"fast"})", "param.set", "dryers[0].speed"},
      {R"({"type":"param.set","path":"dryers[1].on","value":1})", "param.set", "dryers[1].on"},
      {R"({"type":"param.set","path":"gravity","value":[0,0]})", "param.set", "gravity"},
      {R"({"type":"param.set","path":"dryers[0].direction","value":[0,0,0]})", "param.set",
       "dryers[0].direction must be a non-zero"},
      {R"({"type":"param.set","path":"solver.cfl","value":0})", "param.set", "solver.cfl"},
  });
  // The refusal of a non-settable path lists what may be set.
  const ParseError e = refused(R"({"type":"param.set","path":"spacing","value":0.01})");
  EXPECT_NE(e.message.find("solver.cfl"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("dryers[].speed"), std::string::npos) << e.message;
}

TEST(ProtocolRefuse, Camera) {
  expect_bad_fields({
      {R"({"type":"camera.set","elevation":90})", "camera.set", "elevation"},
      {R"({"type":"camera.set","elevation":-90})", "camera.set", "elevation"},
      {R"({"type":"camera.set","distance":0})", "camera.set", "distance"},
      {R"({"type":"camera.set","fov":4.9})", "camera.set", "fov"},
      {R"({"type":"camera.set","fov":121})", "camera.set", "fov"},
      {R"({"type":"camera.set","azimuth":"north"})", "camera.set", "azimuth"},
      {R"({"type":"camera.set","target":[0,0]})", "camera.set", "target"},
      {R"({"type":"camera.orbit","zoom":0.01})", "camera.orbit", "zoom"},
      {R"({"type":"camera.orbit","zoom":101})", "camera.orbit", "zoom"},
      {R"({"type":"camera.orbit","d_azimuth":[1]})", "camera.orbit", "d_azimuth"},
      {R"({"type":"camera.orbit","d_elevation":true})", "camera.orbit", "d_elevation"},
  });
}

TEST(ProtocolRefuse, ViewAndQuality) {
  expect_bad_fields({
      {R"({"type":"view.set"})", "view.set", "view"},
      {R"({"type":"view.set","view":"wireframe"})", "view.set", "view"},
      {R"({"type":"view.set","view":1})", "view.set", "view"},
      {R"({"type":"view.set","view":"surface","colour_by":"velocity"})", "view.set", "colour_by"},
      {R"({"type":"view.set","view":"surface","colour_by":"substance:"})", "view.set", "colour_by"},
      {R"({"type":"view.set","view":"surface","colour_by":3})", "view.set", "colour_by"},
      {R"({"type":"view.set","view":"surface","tint_reference":-1})", "view.set", "tint_reference"},
      {R"({"type":"view.set","view":"surface","tint_reference":"2"})", "view.set", "tint_reference"},
      // A float holds 1e-300 as 0, "auto": it was acked and reported back as 0 (issue 44).
      {R"({"type":"view.set","view":"surface","tint_reference":1e-300})", "view.set", "tint_reference"},
      {R"({"type":"quality.set","width":15})", "quality.set", "width"},
      {R"({"type":"quality.set","width":1921})", "quality.set", "width"},
      {R"({"type":"quality.set","width":640.5})", "quality.set", "width"},
      {R"({"type":"quality.set","height":1081})", "quality.set", "height"},
      {R"({"type":"quality.set","jpeg_quality":9})", "quality.set", "jpeg_quality"},
      {R"({"type":"quality.set","jpeg_quality":96})", "quality.set", "jpeg_quality"},
      {R"({"type":"quality.set","fps":0.5})", "quality.set", "fps"},
      {R"({"type":"quality.set","fps":61})", "quality.set", "fps"},
      {R"({"type":"quality.set","surface":"best"})", "quality.set", "surface"},
      {R"({"type":"quality.set","scale":0.2})", "quality.set", "scale"},
      {R"({"type":"quality.set","scale":1.5})", "quality.set", "scale"},
      {R"({"type":"quality.set","scale":"half"})", "quality.set", "scale"},
  });
}

TEST(ProtocolRefuse, FrameAck) {
  expect_bad_fields({
      {R"({"type":"frame.ack"})", "frame.ack", "frame"},
      {R"({"type":"frame.ack","frame":-1})", "frame.ack", "frame"},
      {R"({"type":"frame.ack","frame":1.5})", "frame.ack", "frame"},
      {R"({"type":"frame.ack","frame":"1"})", "frame.ack", "frame"},
  });
}

// ---- roles, names, events ----------------------------------------------------------------------------

TEST(ProtocolRoles, NeedsControllerForWhatEveryoneSees) {
  // quality.set sets the cost of the frame every client shares: controller only.
  const std::vector<std::string> viewer = {"hello",        "camera.set", "camera.orbit",
                                           "camera.reset", "view.set",   "frame.ack"};
  for (const std::string& text : valid_messages()) {
    const Command c = std::get<Request>(parse(text)).command;
    const bool presentation = std::find(viewer.begin(), viewer.end(), type_name(c)) != viewer.end();
    EXPECT_EQ(needs_controller(c), !presentation) << type_name(c);
  }
  EXPECT_TRUE(needs_controller(DryerSet{}));
  EXPECT_TRUE(needs_controller(EmitterSet{}));
  EXPECT_TRUE(needs_controller(ParamSet{}));
  EXPECT_TRUE(needs_controller(StateLoad{}));
  EXPECT_FALSE(needs_controller(FrameAck{}));
  EXPECT_FALSE(needs_controller(Hello{}));
  EXPECT_TRUE(needs_controller(QualitySet{}));
}

TEST(ProtocolEvents, ErrorCodeNames) {
  EXPECT_STREQ(error_code_name(ErrorCode::BadJson), "bad_json");
  EXPECT_STREQ(error_code_name(ErrorCode::TooLarge), "too_large");
  EXPECT_STREQ(error_code_name(ErrorCode::UnknownType), "unknown_type");
  EXPECT_STREQ(error_code_name(ErrorCode::BadField), "bad_field");
  EXPECT_STREQ(error_code_name(ErrorCode::Forbidden), "forbidden");
  EXPECT_STREQ(error_code_name(ErrorCode::RateLimited), "rate_limited");
  EXPECT_STREQ(error_code_name(ErrorCode::NotFound), "not_found");
  EXPECT_STREQ(error_code_name(ErrorCode::Failed), "failed");
}

TEST(ProtocolEvents, AckAndErrorShape) {
  EXPECT_EQ(ack(Json("a1"), "dryer.set").dump(), R"({"type":"ack","id":"a1","of":"dryer.set"})");
  EXPECT_EQ(ack(Json(3), "sim.step").dump(), R"({"type":"ack","id":3,"of":"sim.step"})");
  EXPECT_EQ(ack(std::nullopt, "sim.pause").dump(), R"({"type":"ack","of":"sim.pause"})");
  EXPECT_EQ(error(ErrorCode::Forbidden, "dryer.set: needs the controller role", Json(9), "dryer.set").dump(),
            R"({"type":"error","code":"forbidden","message":"dryer.set: needs the controller role","id":9,)"
            R"("of":"dryer.set"})");
  EXPECT_EQ(error(ErrorCode::BadJson, "message: not JSON").dump(),
            R"({"type":"error","code":"bad_json","message":"message: not JSON"})");

  // A refusal becomes its event as is.
  const ParseError e = refused(R"({"type":"sim.step","n":0,"id":"s"})");
  const Json j = error(e.code, e.message, e.id, e.type);
  EXPECT_EQ(j["code"], "bad_field");
  EXPECT_EQ(j["id"], "s");
  EXPECT_EQ(j["of"], "sim.step");

  // Messages quote client text; whatever it held, the event serialises.
  EXPECT_NO_THROW(error(ErrorCode::Failed, "bad \xff\xc3 bytes").dump());
  std::string long_accents;
  for (int i = 0; i < 40; ++i) long_accents += "\xc3\xa9";
  const ParseError quoted =
      refused(R"({"type":"param.set","path":"solver.cfl","value":")" + long_accents + "\"}");
  EXPECT_NO_THROW(error(quoted.code, quoted.message, quoted.id, quoted.type).dump()) << quoted.message;
}

TEST(ProtocolEvents, FrameHeaderLayout) {
  const std::string h = frame_header(0x0102030405060708ull, 12.5, 640, 480, 25000);
  ASSERT_EQ(h.size(), kFrameHeaderBytes);
  const auto byte = [&](std::size_t i) {
    return static_cast<std::uint64_t>(static_cast<unsigned char>(h[i]));
  };
  const auto little = [&](std::size_t at, std::size_t n) {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i) v |= byte(at + i) << (8 * i);
    return v;
  };
  EXPECT_EQ(h.substr(0, 4), "THF1");
  EXPECT_EQ(little(4, 8), 0x0102030405060708ull);
  EXPECT_EQ(byte(4), 0x08u);  // little-endian: the low byte first
  const std::uint64_t bits = little(12, 8);
  double time = 0;
  std::memcpy(&time, &bits, sizeof time);
  EXPECT_EQ(time, 12.5);
  EXPECT_EQ(little(20, 2), 640u);
  EXPECT_EQ(little(22, 2), 480u);
  EXPECT_EQ(little(24, 4), 25000u);

  const std::string extreme = frame_header(~0ull, -1.0, 65535, 65535, 0xFFFFFFFFu);
  ASSERT_EQ(extreme.size(), kFrameHeaderBytes);
  EXPECT_EQ(extreme.substr(4, 8), std::string(8, '\xff'));
  EXPECT_EQ(extreme.substr(20), std::string(8, '\xff'));
}

TEST(ProtocolRateLimiter, BurstThenRefill) {
  RateLimiter bucket(2.0, 5.0);                                       // 2 a second, bursts of 5
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(bucket.allow(100.0)) << i;  // starts full
  EXPECT_FALSE(bucket.allow(100.0));
  EXPECT_FALSE(bucket.allow(100.25));  // half a token back
  EXPECT_TRUE(bucket.allow(100.5));    // the half from before and another half make one
  EXPECT_FALSE(bucket.allow(100.5));
  // A long pause refills to the burst, not beyond.
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(bucket.allow(1000.0)) << i;
  EXPECT_FALSE(bucket.allow(1000.0));
  // A clock that steps back refills nothing, then or later.
  EXPECT_FALSE(bucket.allow(900.0));
  EXPECT_FALSE(bucket.allow(1000.0));
  // A steady 2 a second is always allowed.
  for (int i = 1; i <= 20; ++i) EXPECT_TRUE(bucket.allow(1000.0 + 0.5 * i)) << i;
}

// ---- fuzz --------------------------------------------------------------------------------------------

// Whatever the bytes, parse() returns, the result is one of the two, a refusal says why in a message that
// serialises, and nothing reaches the catch-all (code Failed would be a bug in the checks).
void expect_handled(const std::string& text) {
  std::variant<Request, ParseError> result;
  ASSERT_NO_THROW(result = parse(text)) << text;
  ASSERT_FALSE(result.valueless_by_exception());
  if (const auto* e = std::get_if<ParseError>(&result)) {
    EXPECT_NE(e->code, ErrorCode::Failed) << text << ": " << e->message;
    EXPECT_FALSE(e->message.empty());
    EXPECT_NO_THROW(error(e->code, e->message, e->id, e->type).dump()) << e->message;
  } else {
    const Request& r = std::get<Request>(result);
    EXPECT_NO_THROW(ack(r.id, type_name(r.command)).dump());
  }
}

TEST(ProtocolFuzz, RandomBytes) {
  std::mt19937 rng(20240611);
  const std::string json_chars = "{}[]\",:0123456789.eE+-truefalsnl \\u";
  for (int i = 0; i < 5000; ++i) {
    std::string text(std::uniform_int_distribution<std::size_t>(0, 200)(rng), '\0');
    const bool json_like = i % 2 == 0;
    for (char& c : text) {
      c = json_like ? json_chars[std::uniform_int_distribution<std::size_t>(0, json_chars.size() - 1)(rng)]
                    : static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    }
    expect_handled(text);
    if (HasFatalFailure() || HasNonfatalFailure()) return;
  }
}

TEST(ProtocolFuzz, MutatedValidMessages) {
  std::mt19937 rng(7);
  const auto pick = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
  using namespace std::string_literals;
  const std::string alphabet = "{}[]\",:-.0123456789eE \\/\x00\xff\xc3"s;  // NUL and stray UTF-8 too
  for (int i = 0; i < 5000; ++i) {
    std::string text = valid_messages()[pick(valid_messages().size())];
    const std::size_t edits = 1 + pick(4);
    for (std::size_t k = 0; k < edits && !text.empty(); ++k) {
      const std::size_t at = pick(text.size());
      switch (pick(5)) {
        case 0:
          text[at] = alphabet[pick(alphabet.size())];
          break;
        case 1:
          text.insert(at, 1, alphabet[pick(alphabet.size())]);
          break;
        case 2:
          text.erase(at, 1 + pick(4));
          break;
        case 3:
          text.resize(at);
          break;
        default:
          text.insert(at, text.substr(pick(text.size())));
          break;
      }
    }
    expect_handled(text);
    if (HasFatalFailure() || HasNonfatalFailure()) return;
  }
}

// Well-formed JSON with every field's value swapped for one of the wrong kind: the checks, not the
// parser, must catch these.
TEST(ProtocolFuzz, WrongValuesInValidMessages) {
  std::mt19937 rng(99);
  const std::vector<Json> values = {nullptr,
                                    true,
                                    -1,
                                    0,
                                    1,
                                    1e308,
                                    -1e308,
                                    2.5,
                                    -0.0,
                                    1e-320,
                                    "",
                                    "x",
                                    "../x",
                                    "a/b",
                                    "\u00e9",
                                    Json::array(),
                                    Json::object(),
                                    {1, 2},
                                    {0, 0, 0},
                                    {1, 2, 3},
                                    {"a", 1, 2},
                                    {1, 2, 3, 4},
                                    18446744073709551615ull,
                                    -9223372036854775807ll - 1,
                                    2147483648.0,
                                    4294967296ll,
                                    Json{{"a", 1}}};
  for (int i = 0; i < 3000; ++i) {
    Json message = Json::parse(valid_messages()[i % valid_messages().size()]);
    std::vector<std::string> keys;
    for (const auto& [key, _] : message.items()) keys.push_back(key);
    keys.push_back("extra");
    const std::string key = keys[std::uniform_int_distribution<std::size_t>(0, keys.size() - 1)(rng)];
    message[key] = values[std::uniform_int_distribution<std::size_t>(0, values.size() - 1)(rng)];
    expect_handled(message.dump());
    if (HasFatalFailure() || HasNonfatalFailure()) return;
  }
}

}  // namespace
}  // namespace thaw::protocol
