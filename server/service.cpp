#include "server/service.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "sim/scene.h"

namespace thaw {
namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Scene names a client may load: the files of configs/.
Json scene_names() {
  Json names = Json::array();
  std::error_code ec;
  std::vector<std::string> found;
  for (const auto& e :
       std::filesystem::directory_iterator(std::filesystem::path(THAW_SOURCE_DIR) / "configs", ec))
    if (e.path().extension() == ".json") found.push_back(e.path().stem().string());
  std::sort(found.begin(), found.end());
  for (const auto& n : found) names.push_back(n);
  return names;
}

Json vec(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json view_json(const RenderOptions& o) {
  // The reference is kept as a float: written to 6 digits, 0.1 reads back as 0.1 and the page's menu finds
  // it.
  char reference[32];
  std::snprintf(reference, sizeof reference, "%.6g", double(o.field.tint_reference));
  return {{"view", o.view}, {"colour_by", o.colour_by}, {"tint_reference", std::stod(reference)}};
}

// The camera as drawn now: distance 0 frames the domain, target null looks at its centre.
Json camera_json(const RenderOptions& o) {
  return {{"azimuth", o.azimuth},
          {"elevation", o.elevation},
          {"distance", o.distance},
          {"target", o.has_target ? vec(o.target) : Json(nullptr)},
          {"fov", o.fov}};
}

Json dryers_json(const Scene& s) {
  Json out = Json::array();
  for (const Dryer& d : s.dryers) out.push_back(to_json(d));
  return out;
}

Json lamps_json(const Scene& s) {
  Json out = Json::array();
  for (const Lamp& l : s.lamps) out.push_back(to_json(l));
  return out;
}

// Each tap as the scene file would say it, with its volume flow in L/s beside the exit speed.
Json emitters_json(const Scene& s) {
  Json out = Json::array();
  for (const Emitter& e : s.emitters) {
    Json j = to_json(e, s.materials);
    j["rate"] = e.volume_flow() * 1e3;
    out.push_back(std::move(j));
  }
  return out;
}

// "#rrggbb" of an sRGB colour in [0, 1].
std::string hex_colour(const std::array<float, 3>& c) {
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", int(std::lround(std::clamp(c[0], 0.0f, 1.0f) * 255.0f)),
                int(std::lround(std::clamp(c[1], 0.0f, 1.0f) * 255.0f)),
                int(std::lround(std::clamp(c[2], 0.0f, 1.0f) * 255.0f)));
  return text;
}

// The scene's substances, each with its kind and colour, in the order the scene declares them: what
// substance.drop names.
Json substance_names(const Scene& s) {
  Json out = Json::array();
  for (const Substance& sub : s.substances)
    out.push_back({{"name", sub.name},
                   {"kind", name(sub.kind)},
                   {"lowers_melting_point", sub.lowers_melting_point()},
                   {"colour", hex_colour(sub.colour)}});
  return out;
}

}  // namespace

Service::Service(Session& session, RenderWorker& renderer, ServiceOptions options)
    : session_(session), renderer_(renderer), options_(std::move(options)) {
  if (const auto stats = session_.latest_stats()) generation_ = stats->value("generation", std::uint64_t(0));
  subscription_ = session_.subscribe([this] { on_published(); });
  // Nobody connected: no frames to draw, so the simulation gets the whole machine.
  renderer_.set_watched(false);
}

Service::~Service() { session_.unsubscribe(subscription_); }

void Service::attach(WsServer& server) { server_ = &server; }

Json Service::scene_state() const {
  const auto scene = session_.scene();
  const auto stats = session_.latest_stats();
  const RenderOptions o = renderer_.options();
  return {{"scene", scene->name},
          {"description", scene->description},
          {"dryers", dryers_json(*scene)},
          {"lamps", lamps_json(*scene)},
          {"emitters", emitters_json(*scene)},
          {"substances", substance_names(*scene)},
          {"view", view_json(o)},
          {"quality", quality_json()},
          {"camera", camera_json(o)},
          {"speed", stats ? stats->value("speed", 0.0) : 0.0},
          {"heat_time_scale", scene->heat.time_scale},
          {"tension", name(scene->tension.model)},
          {"paused", stats ? stats->value("paused", false) : false},
          // Why the run stopped, if it did (a blow-up, a device failure), as the stats carry it.
          {"error", stats && stats->contains("error") ? (*stats)["error"] : Json(nullptr)}};
}

Json Service::quality_json() const {
  const RenderOptions now = renderer_.options();
  return {{"width", now.width},
          {"height", now.height},
          {"jpeg_quality", renderer_.jpeg_quality()},
          {"fps", renderer_.fps_cap()},
          {"fps_limit", renderer_.fps_limit()},
          {"surface", now.quality},
          {"scale", now.scale}};
}

Json Service::welcome(bool controller) const {
  Json w = {{"type", "welcome"},
            {"protocol", protocol::kVersion},
            {"scenes", scene_names()},
            {"role", controller ? "controller" : "viewer"},
            {"views", {"surface", "particles", "slice"}},
            {"limits",
             {{"max_message_bytes", protocol::kMaxMessageBytes},
              {"commands_per_second", options_.command_rate},
              {"command_burst", options_.command_burst},
              {"unacknowledged_frames", 2}}}};
  w.update(scene_state());
  return w;
}

void Service::reply(std::uint64_t client, const Json& event) {
  if (server_) server_->send_text(client, event.dump());
}

void Service::on_open(std::uint64_t client, const std::string&) {
  std::lock_guard lock(mutex_);
  // Without a token, a server that only loopback clients can reach gives everyone control.
  clients_.emplace(client, Client{options_.token.empty() && options_.loopback,
                                  protocol::RateLimiter(options_.command_rate, options_.command_burst)});
  renderer_.set_watched(true);
}

void Service::on_close(std::uint64_t client) {
  std::lock_guard lock(mutex_);
  clients_.erase(client);
  renderer_.set_watched(!clients_.empty());
}

void Service::on_oversize(std::uint64_t client, std::size_t bytes) {
  reply(client, protocol::error(protocol::ErrorCode::TooLarge,
                                "message of " + std::to_string(bytes) + " bytes; the limit is " +
                                    std::to_string(protocol::kMaxMessageBytes)));
}

void Service::on_binary(std::uint64_t client, std::size_t bytes) {
  reply(client, protocol::error(protocol::ErrorCode::BadJson, "message: a binary message of " +
                                                                  std::to_string(bytes) +
                                                                  " bytes; commands are JSON text messages"));
}

void Service::on_text(std::uint64_t client, std::string_view message) {
  using namespace protocol;
  bool controller = false;
  const auto parsed = parse(message);  // bounded: the loop refuses messages over kMaxMessageBytes
  // Frame acknowledgements come with every frame and cost nothing: they are not counted as commands.
  if (const auto* r = std::get_if<Request>(&parsed)) {
    if (const auto* ack = std::get_if<FrameAck>(&r->command)) {
      if (server_) server_->ack_frame(client, ack->frame);
      return;
    }
  }
  {
    std::lock_guard lock(mutex_);
    const auto it = clients_.find(client);
    if (it == clients_.end()) return;
    if (!it->second.limiter.allow(now_s())) {
      std::optional<Json> id;
      std::string type;
      if (const auto* r = std::get_if<Request>(&parsed)) {
        id = r->id;
        type = type_name(r->command);
      } else {
        id = std::get<ParseError>(parsed).id;
        type = std::get<ParseError>(parsed).type;
      }
      reply(client,
            error(ErrorCode::RateLimited,
                  "more than " + std::to_string(int(options_.command_rate)) + " commands a second; slow down",
                  id, type));
      return;
    }
    controller = it->second.controller;
  }
  if (const auto* e = std::get_if<ParseError>(&parsed)) {
    reply(client, error(e->code, e->message, e->id, e->type));
    return;
  }
  const Request& r = std::get<Request>(parsed);
  const std::string type = type_name(r.command);
  if (const auto* hello = std::get_if<Hello>(&r.command)) {
    if (hello->token && !options_.token.empty() && *hello->token == options_.token) {
      std::lock_guard lock(mutex_);
      const auto it = clients_.find(client);
      if (it != clients_.end()) it->second.controller = controller = true;
    } else if (hello->token && !options_.token.empty()) {
      reply(client, error(ErrorCode::Forbidden, "hello: wrong token; connected as a viewer", r.id, type));
    }
    reply(client, welcome(controller));
    return;
  }
  if (needs_controller(r.command) && !controller) {
    reply(client, error(ErrorCode::Forbidden,
                        type + ": needs the controller role (hello with the server's token)", r.id, type));
    return;
  }
  const auto id = r.id;
  auto done = [this, client, id, type](std::optional<ErrorCode> code, std::string msg, Json result) {
    // A command has changed what the picture shows: draw it now rather than at the next fps slot.
    if (!code) renderer_.hurry();
    if (code) {
      reply(client, error(*code, msg, id, type));
    } else {
      Json a = ack(id, type);
      if (result.is_object())
        for (const auto& [k, v] : result.items()) a[k] = v;
      reply(client, a);
    }
  };
  std::visit(
      [&](const auto& c) {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, FrameAck>) {
          // answered above, before the rate limit
        } else if constexpr (std::is_same_v<T, CameraSet>) {
          renderer_.set_camera(c.azimuth, c.elevation, c.distance, c.target, c.fov);
          done({}, "", Json::object());
        } else if constexpr (std::is_same_v<T, CameraOrbit>) {
          renderer_.orbit(c.d_azimuth, c.d_elevation, c.zoom);
          done({}, "", Json::object());
        } else if constexpr (std::is_same_v<T, CameraReset>) {
          renderer_.reset_camera(session_.scene()->camera);
          done({}, "", {{"camera", camera_json(renderer_.options())}});
        } else if constexpr (std::is_same_v<T, ViewSet>) {
          const std::string prefix = kSubstanceColouring;
          if (c.colour_by && c.colour_by->rfind(prefix, 0) == 0) {
            const std::string wanted = c.colour_by->substr(prefix.size());
            const auto scene = session_.scene();
            const bool known = std::any_of(scene->substances.begin(), scene->substances.end(),
                                           [&](const Substance& x) { return x.name == wanted; });
            if (!known) {
              done(ErrorCode::BadField,
                   type + ": colour_by: the scene declares no substance '" + wanted + "'", Json::object());
              return;
            }
          }
          renderer_.set_view(c.view, c.colour_by, c.tint_reference);
          done({}, "", Json::object());
        } else if constexpr (std::is_same_v<T, QualitySet>) {
          renderer_.set_quality(c.width, c.height, c.jpeg_quality, c.fps, c.surface, c.scale);
          done({}, "", quality_json());
        } else if constexpr (std::is_same_v<T, DryerAim> || std::is_same_v<T, SubstanceDrop>) {
          // The surface point under the pixel of the last frame, then the simulation's part.
          const auto hit = renderer_.pick(c.x, c.y);
          if (!hit)
            done(ErrorCode::NotFound,
                 type + ": no surface under pixel (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ")",
                 Json::object());
          else if constexpr (std::is_same_v<T, DryerAim>)
            session_.aim_dryer(c.dryer, hit->hit, done);
          else
            session_.drop_substance(c.substance, c.amount, hit->hit, done);
        } else {
          session_.submit(r.command, done);
        }
      },
      r.command);
}

void Service::on_published() {
  // A scene loaded, reset or replaced by a saved state: the camera goes back to the scene's own, and
  // every client gets everything it shows again (the `scene` event), ahead of the stats.
  if (const auto stats = session_.latest_stats(); stats && server_) {
    const std::uint64_t generation = stats->value("generation", std::uint64_t(0));
    bool changed = false;
    {
      std::lock_guard lock(mutex_);
      changed = generation != generation_;
      generation_ = generation;
    }
    if (changed) {
      renderer_.reset_camera(session_.scene()->camera);
      Json event = {{"type", "scene"}};
      event.update(scene_state());
      server_->broadcast_text(event.dump());
    }
  }
  // Stats at most stats_rate a second: a browser needs no more, and they share the socket with frames. But a
  // run that paused or failed says so at once: the publish that carries it is the last one a paused run
  // makes, and when it came within the rate's interval of the one before, no client ever heard of it.
  const auto stats = session_.latest_stats();
  {
    std::lock_guard lock(mutex_);
    const double t = now_s();
    const bool paused = stats && stats->value("paused", false);
    const std::string error = stats && stats->contains("error") ? (*stats)["error"].get<std::string>() : "";
    const bool news = paused != sent_paused_ || error != sent_error_;
    if (!news && last_stats_ >= 0 && t - last_stats_ < 1.0 / options_.stats_rate) return;
    if (!stats || !server_) return;
    last_stats_ = t;
    sent_paused_ = paused;
    sent_error_ = error;
  }
  Json s = *stats;
  if (const auto f = renderer_.latest_frame()) {
    s["frame"] = f->frame;
    s["render_ms"] = f->render_ms;
    s["encode_ms"] = f->encode_ms;
    // What the frame on screen is: its march's scale, and whether it was drawn while the camera moved.
    s["frame_scale"] = f->scale;
    s["frame_moving"] = f->moving;
    s["fps"] = renderer_.fps();
  }
  const auto scene = session_.scene();
  s["dryers"] = dryers_json(*scene);
  s["emitters"] = emitters_json(*scene);
  s["lamps"] = lamps_json(*scene);
  const RenderOptions o = renderer_.options();
  s["view"] = view_json(o);
  s["quality"] = {{"surface", o.quality}, {"width", o.width}, {"height", o.height}, {"scale", o.scale}};
  server_->broadcast_text(s.dump());
}

void Service::frame_ready() {
  const auto f = renderer_.latest_frame();
  if (!f || !server_) return;
  {
    std::lock_guard lock(mutex_);
    if (f->frame <= last_frame_sent_) return;
    last_frame_sent_ = f->frame;
  }
  auto bytes = std::make_shared<std::string>(protocol::frame_header(
      f->frame, f->sim_time, static_cast<std::uint16_t>(f->width), static_cast<std::uint16_t>(f->height),
      static_cast<std::uint32_t>(f->jpeg.size())));
  bytes->append(f->jpeg);
  server_->publish_frame(std::move(bytes), f->frame);
}

}  // namespace thaw
