#pragma once
// The thaw.v1 WebSocket protocol (docs/PROTOCOL.md): client messages parsed and checked into commands,
// and the server's JSON events. Nothing here touches sockets or the simulation: the network loop hands
// text in, gets a command or an error out; the session applies commands between steps.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>

#include "sim/schema.h"

namespace thaw::protocol {

inline constexpr const char* kSubprotocol = "thaw.v1";
inline constexpr int kVersion = 1;
inline constexpr std::size_t kMaxMessageBytes = 16 * 1024;  // larger text messages are refused

// Why a message was refused; the `code` of an `error` event.
enum class ErrorCode {
  BadJson,      // not JSON, or not a JSON object
  TooLarge,     // over kMaxMessageBytes
  UnknownType,  // `type` missing, not a string, or not a command
  BadField,     // a field missing, of the wrong type, not finite, or out of range
  Forbidden,    // needs the controller role
  RateLimited,  // too many commands: the client's bucket is empty
  NotFound,     // a dryer, lamp, emitter, scene or saved state that does not exist
  Failed,       // valid, but the server could not carry it out (e.g. a state file failed to load)
};
const char* error_code_name(ErrorCode c);

// ---- commands (client -> server) ----------------------------------------------------------------
// Optional fields are those a client may leave out: the server keeps the current value.

struct Hello {
  int version = kVersion;
  std::optional<std::string> token;
};
struct DryerSet {
  int dryer = 0;
  std::optional<bool> on;
  std::optional<Eigen::Vector3d> position, direction;           // [m], any length but not zero
  std::optional<double> temperature, speed, half_angle, reach;  // °C, m/s, deg, m
};
struct DryerAim {  // aim at the surface under a pixel of the client's current image
  int dryer = 0;
  double x = 0, y = 0;  // pixels from the top left
};
struct SubstanceDrop {    // a dose of a substance where the surface under a pixel of the client's image is
  std::string substance;  // a name the scene's `substances` declares
  double amount = 0;      // [kg]
  double x = 0, y = 0;    // pixels from the top left
};
struct LampSet {
  int lamp = 0;
  std::optional<bool> on;
  std::optional<Eigen::Vector3d> centre, normal;
  std::optional<double> temperature, emissivity;
};
struct EmitterSet {  // a tap: open or close it, change its flow, place, aim, times or temperature
  int emitter = 0;
  std::optional<bool> open;
  std::optional<Eigen::Vector3d> position, direction;                   // [m], any length but not zero
  std::optional<double> radius, speed, rate, temperature, start, stop;  // m, m/s, L/s, °C, s, s
};
struct SimPause {};
struct SimResume {};
struct SimStep {
  int n = 1;  // 1 .. 10000
};
struct SimReset {};
struct SimSpeed {
  double factor = 1;  // simulated seconds per wall second relative to real time; (0, 1000]
};
struct SceneLoad {
  std::string name;  // a scene in configs/, by name only (no paths)
};
struct ParamSet {
  std::string path;  // a client-settable scene field (the schema's `live` column)
  Json value;
};
struct CameraSet {
  std::optional<double> azimuth, elevation, distance, fov;
  std::optional<Eigen::Vector3d> target;
};
struct CameraOrbit {                                // relative change, e.g. from a mouse drag or wheel
  double d_azimuth = 0, d_elevation = 0, zoom = 1;  // deg, deg, distance factor
};
struct CameraReset {};  // back to the scene's own camera
struct ViewSet {
  std::string view = "surface";          // surface | particles | slice
  std::optional<std::string> colour_by;  // phase | temperature | speed | substance:NAME
  std::optional<double> tint_reference;  // the surface view's full-colour concentration [g/L]; 0: automatic
};
struct QualitySet {
  std::optional<int> width, height;    // 16 .. 1920, 16 .. 1080
  std::optional<int> jpeg_quality;     // 10 .. 95
  std::optional<double> fps;           // frame cap, 1 .. 60
  std::optional<std::string> surface;  // full | fast
  std::optional<double> scale;         // surface: the fraction of width and height the march draws
};
struct StateSave {
  std::string name;  // [A-Za-z0-9_-]{1,64}: a file in the server's state folder, never a path
};
struct StateLoad {
  std::string name;
};
struct FrameAck {
  std::uint64_t frame = 0;
};

using Command = std::variant<Hello, DryerSet, DryerAim, LampSet, SimPause, SimResume, SimStep, SimReset,
                             SimSpeed, SceneLoad, ParamSet, CameraSet, CameraOrbit, ViewSet, QualitySet,
                             StateSave, StateLoad, FrameAck, EmitterSet, CameraReset, SubstanceDrop>;

// The `type` string of each command, e.g. "dryer.set".
const char* type_name(const Command& c);

// Whether a command changes what every client sees (needs the controller role).
bool needs_controller(const Command& c);

struct Request {
  Command command;
  std::optional<Json> id;  // echoed in the ack or error; a string or a number
};

struct ParseError {
  ErrorCode code;
  std::string message;     // names the field, e.g. "dryer.set: speed: 250 m/s is above the limit 100"
  std::optional<Json> id;  // when the message had a readable id
  std::string type;        // the message's type when readable
};

// Parses and checks one text message. Never throws.
std::variant<Request, ParseError> parse(std::string_view text);

// ---- events (server -> client) ------------------------------------------------------------------

Json ack(const std::optional<Json>& id, const std::string& type);
Json error(ErrorCode code, const std::string& message, const std::optional<Json>& id = {},
           const std::string& type = "");

// Binary frames: a 28-byte little-endian header, then the JPEG bytes:
//   "THF1" (4 bytes) | frame number u64 | simulated time f64 [s] | width u16 | height u16 | JPEG bytes u32
inline constexpr std::size_t kFrameHeaderBytes = 28;
std::string frame_header(std::uint64_t frame, double sim_time, std::uint16_t width, std::uint16_t height,
                         std::uint32_t jpeg_bytes);

// A token bucket per client: `rate` commands a second on average, bursts of `burst`.
class RateLimiter {
 public:
  RateLimiter(double rate, double burst) : rate_(rate), burst_(burst), tokens_(burst) {}
  // Takes one token at time `now` [s, monotonic]; false when the bucket is empty.
  bool allow(double now);

 private:
  double rate_, burst_, tokens_;
  double last_ = -1;
};

}  // namespace thaw::protocol
