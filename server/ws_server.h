#pragma once
// The network loop: libwebsockets on one thread, HTTP for the static client in web/ and the thaw.v1
// WebSocket protocol on the same port. All lws details stay in ws_server.cpp. Other threads hand it
// text and frames through the thread-safe calls below, which wake the loop with lws_cancel_service;
// only the loop writes to sockets (libwebsockets' rule).
//
// Handshakes: an upgrade must ask for the thaw.v1 subprotocol; one without it (or with another) is
// refused, the connection closed before any response (lws sends no status in that phase), rather than
// accepted with a 101 and left without a handler.
//
// Flow control: every client gets the newest frame when it can take one, with at most two frames it has
// not acknowledged; older frames are dropped, never queued, so a slow client costs nothing but its own
// frame rate.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace thaw {

struct ServerOptions {
  std::string host = "127.0.0.1";
  int port = 8080;       // 0: any free port (see WsServer::port())
  std::string web_root;  // folder served over HTTP ("/" is its index.html)
  std::size_t max_message_bytes = 16 * 1024;
  std::size_t max_queued_texts = 256;  // per client; beyond it the oldest queued text is dropped
  int frame_window = 2;                // unacknowledged frames per client
};

// What the loop reports; called on the loop's thread.
class WsHandler {
 public:
  virtual ~WsHandler() = default;
  virtual void on_open(std::uint64_t client, const std::string& peer_address) = 0;
  virtual void on_text(std::uint64_t client, std::string_view message) = 0;  // one whole message
  virtual void on_oversize(std::uint64_t client, std::size_t bytes) = 0;     // a message over the limit
  virtual void on_binary(std::uint64_t client, std::size_t bytes) = 0;       // a whole binary message
  virtual void on_close(std::uint64_t client) = 0;
};

class WsServer {
 public:
  // Binds host:port; throws Error naming the address when it cannot.
  WsServer(const ServerOptions& options, WsHandler& handler);
  ~WsServer();
  WsServer(const WsServer&) = delete;
  WsServer& operator=(const WsServer&) = delete;

  // Serves until request_stop(). (lws_service may sleep up to its own timer interval; request_stop()
  // wakes it, a flag alone would not.)
  void run();
  void request_stop();  // thread-safe

  // Thread-safe.
  void send_text(std::uint64_t client, std::string text);
  void broadcast_text(std::string text);
  void publish_frame(std::shared_ptr<const std::string> bytes, std::uint64_t frame);
  void ack_frame(std::uint64_t client, std::uint64_t frame);  // frames up to `frame` are acknowledged
  void wake();
  int port() const;  // the port actually bound
  std::size_t clients() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace thaw
