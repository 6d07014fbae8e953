#pragma once
// `thaw serve`'s glue: the three parts and their hand-offs (docs/ARCHITECTURE.md, Server). The network loop
// (WsServer) hands each client's text to this service on the loop's thread; the service checks it
// (protocol::parse, the client's role, its rate), answers presentation commands from the render worker,
// and queues simulation commands on the Session, whose answers come back from the session's thread and
// are queued for the loop to send. Stats are broadcast as the session publishes them; frames as the
// render worker encodes them, every client taking the newest one its acknowledgements allow.
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "server/protocol.h"
#include "server/render_worker.h"
#include "server/session.h"
#include "server/ws_server.h"

namespace thaw {

struct ServiceOptions {
  std::string token;         // empty: no token; then only a loopback server gives clients control
  bool loopback = true;      // the server listens on 127.0.0.1 only
  double command_rate = 50;  // commands a second per client, on average
  double command_burst = 100;
  double stats_rate = 10;  // stats events a second at most
};

class Service : public WsHandler {
 public:
  Service(Session& session, RenderWorker& renderer, ServiceOptions options);
  ~Service() override;
  // The loop to send through; set once, before the loop runs.
  void attach(WsServer& server);

  void on_open(std::uint64_t client, const std::string& peer_address) override;
  void on_text(std::uint64_t client, std::string_view message) override;
  void on_oversize(std::uint64_t client, std::size_t bytes) override;
  void on_binary(std::uint64_t client, std::size_t bytes) override;
  void on_close(std::uint64_t client) override;

  // The welcome event a client gets in answer to hello (also for tests and `thaw ctl`): the protocol, the
  // scenes, the client's role and limits, and the scene state.
  Json welcome(bool controller) const;
  // Everything a page shows of the running scene: its name and description, dryers, lamps, emitters, the
  // view, quality and camera, the simulation speed, the heat time scale and whether it is paused. Sent in
  // welcome and, as the `scene` event, to every client when the scene is loaded, reset or replaced.
  Json scene_state() const;

  // The render worker's frame callback: sends the newest encoded frame to the loop (any thread).
  void frame_ready();

 private:
  struct Client {
    bool controller = false;
    protocol::RateLimiter limiter;
  };
  void reply(std::uint64_t client, const Json& event);
  void on_published();
  Json quality_json() const;  // the frame settings in force (quality.set's answer)

  Session& session_;
  RenderWorker& renderer_;
  ServiceOptions options_;
  WsServer* server_ = nullptr;
  std::mutex mutex_;  // clients_ and the stats throttle
  std::map<std::uint64_t, Client> clients_;
  double last_stats_ = -1;
  // What the last stats sent said of the run: paused, and why it stopped ("": it did not fail).
  bool sent_paused_ = false;
  std::string sent_error_;
  std::uint64_t generation_ = 0;  // of the last scene event sent (Session's stats "generation")
  std::uint64_t last_frame_sent_ = 0;
  int subscription_ = 0;
};

}  // namespace thaw
