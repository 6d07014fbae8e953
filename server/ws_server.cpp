#include "server/ws_server.h"

#include <libwebsockets.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <vector>

#include "sim/error.h"

namespace thaw {

namespace {

struct Client {
  lws* wsi = nullptr;
  std::deque<std::string> texts;    // JSON events waiting to go out, oldest first
  std::set<std::uint64_t> unacked;  // frames sent and not yet acknowledged
  std::uint64_t last_frame_sent = 0;
  bool sent_any_frame = false;
  std::string rx;  // a message arriving in fragments
  bool rx_oversize = false;
  std::size_t rx_total = 0;
};

}  // namespace

struct WsServer::Impl {
  ServerOptions options;
  WsHandler& handler;
  lws_context* context = nullptr;
  lws_http_mount mount{};
  std::vector<lws_protocols> protocols;
  int bound_port = 0;
  std::atomic<bool> stopping{false};

  mutable std::mutex mutex;  // guards everything below (the loop and other threads share it)
  std::map<std::uint64_t, Client> clients;
  std::map<lws*, std::uint64_t> ids;
  std::uint64_t next_id = 1;
  std::shared_ptr<const std::string> frame;  // the newest frame, whole message bytes
  std::uint64_t frame_number = 0;

  Impl(const ServerOptions& o, WsHandler& h) : options(o), handler(h) {}

  // Asks for a writeable callback on every client with something to send (loop thread only).
  void request_writes() {
    std::lock_guard lock(mutex);
    for (auto& [id, c] : clients)
      if (!c.texts.empty() || wants_frame(c)) lws_callback_on_writable(c.wsi);
  }

  bool wants_frame(const Client& c) const {
    return frame && (!c.sent_any_frame || frame_number > c.last_frame_sent) &&
           int(c.unacked.size()) < options.frame_window;
  }

  int on_event(lws* wsi, lws_callback_reasons reason, void* in, std::size_t len);
};

namespace {

int callback(lws* wsi, lws_callback_reasons reason, void* user, void* in, std::size_t len) {
  (void)user;
  auto* impl = static_cast<WsServer::Impl*>(lws_context_user(lws_get_context(wsi)));
  if (!impl) return 0;
  return impl->on_event(wsi, reason, in, len);
}

// The HTTP protocol: static files, and the handshakes that named no subprotocol of ours. lws binds an
// upgrade without a Sec-WebSocket-Protocol header to its first protocol, this one; accepted, such a
// socket got a 101 and then no callback ever answered it (100 held for 30 s were never closed). Refused
// here, lws closes the connection before answering, as it does for a subprotocol it does not know.
int http_callback(lws* wsi, lws_callback_reasons reason, void* user, void* in, std::size_t len) {
  if (reason == LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION) return -1;
  return lws_callback_http_dummy(wsi, reason, user, in, len);
}

// One lws_write of `bytes` with the LWS_PRE headroom lws needs in front of it.
int write_message(lws* wsi, const std::string& bytes, lws_write_protocol kind) {
  std::vector<unsigned char> buffer(LWS_PRE + bytes.size());
  std::memcpy(buffer.data() + LWS_PRE, bytes.data(), bytes.size());
  const int n = lws_write(wsi, buffer.data() + LWS_PRE, bytes.size(), kind);
  return n < int(bytes.size()) ? -1 : 0;
}

}  // namespace

int WsServer::Impl::on_event(lws* wsi, lws_callback_reasons reason, void* in, std::size_t len) {
  switch (reason) {
    case LWS_CALLBACK_ESTABLISHED: {
      char peer[128] = "";
      lws_get_peer_simple(wsi, peer, sizeof peer);
      std::uint64_t id = 0;
      {
        std::lock_guard lock(mutex);
        id = next_id++;
        clients[id].wsi = wsi;
        ids[wsi] = id;
      }
      handler.on_open(id, peer);
      lws_callback_on_writable(wsi);
      return 0;
    }
    case LWS_CALLBACK_CLOSED: {
      std::uint64_t id = 0;
      {
        std::lock_guard lock(mutex);
        const auto it = ids.find(wsi);
        if (it == ids.end()) return 0;
        id = it->second;
        ids.erase(it);
        clients.erase(id);
      }
      handler.on_close(id);
      return 0;
    }
    case LWS_CALLBACK_RECEIVE: {
      std::uint64_t id = 0;
      std::string message;
      bool whole = false, oversize = false;
      std::size_t total = 0;
      {
        std::lock_guard lock(mutex);
        const auto it = ids.find(wsi);
        if (it == ids.end()) return 0;
        id = it->second;
        Client& c = clients[id];
        c.rx_total += len;
        if (c.rx_total > options.max_message_bytes) {
          // Keep reading to the end of the message, but nothing of it is kept.
          c.rx_oversize = true;
          c.rx.clear();
        } else if (!lws_frame_is_binary(wsi)) {
          c.rx.append(static_cast<const char*>(in), len);
        }
        if (lws_is_final_fragment(wsi) && lws_remaining_packet_payload(wsi) == 0) {
          whole = true;
          oversize = c.rx_oversize;
          total = c.rx_total;
          message.swap(c.rx);
          c.rx_oversize = false;
          c.rx_total = 0;
        }
      }
      if (whole) {
        if (oversize)
          handler.on_oversize(id, total);
        else if (lws_frame_is_binary(wsi))
          handler.on_binary(id, total);
        else
          handler.on_text(id, message);
      }
      return 0;
    }
    case LWS_CALLBACK_SERVER_WRITEABLE: {
      std::string text;
      std::shared_ptr<const std::string> bytes;
      {
        std::lock_guard lock(mutex);
        const auto it = ids.find(wsi);
        if (it == ids.end()) return 0;
        Client& c = clients[it->second];
        if (!c.texts.empty()) {
          text = std::move(c.texts.front());
          c.texts.pop_front();
        } else if (wants_frame(c)) {
          bytes = frame;
          c.last_frame_sent = frame_number;
          c.sent_any_frame = true;
          c.unacked.insert(frame_number);
        }
      }
      if (!text.empty() && write_message(wsi, text, LWS_WRITE_TEXT) < 0) return -1;
      if (bytes && write_message(wsi, *bytes, LWS_WRITE_BINARY) < 0) return -1;
      // One write per callback: ask again while there is more.
      {
        std::lock_guard lock(mutex);
        const auto it = ids.find(wsi);
        if (it != ids.end()) {
          const Client& c = clients[it->second];
          if (!c.texts.empty() || wants_frame(c)) lws_callback_on_writable(wsi);
        }
      }
      return 0;
    }
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
      request_writes();
      return 0;
    default:
      return 0;
  }
}

WsServer::WsServer(const ServerOptions& options, WsHandler& handler)
    : impl_(std::make_unique<Impl>(options, handler)) {
  Impl& m = *impl_;
  lws_set_log_level(LLL_ERR, nullptr);
  m.protocols.push_back({"http", http_callback, 0, 0, 0, nullptr, 0});
  m.protocols.push_back({"thaw.v1", callback, 0, 4096, 0, nullptr, 0});
  m.protocols.push_back({nullptr, nullptr, 0, 0, 0, nullptr, 0});
  m.mount.mountpoint = "/";
  m.mount.mountpoint_len = 1;
  m.mount.origin = m.options.web_root.c_str();
  m.mount.def = "index.html";
  m.mount.origin_protocol = LWSMPRO_FILE;

  lws_context_creation_info info{};
  info.port = options.port;
  info.iface = options.host.c_str();
  info.protocols = m.protocols.data();
  info.mounts = options.web_root.empty() ? nullptr : &m.mount;
  info.user = &m;
  info.options = LWS_SERVER_OPTION_DISABLE_IPV6;
  m.context = lws_create_context(&info);
  if (!m.context)
    throw Error("cannot serve on " + options.host + ":" + std::to_string(options.port) +
                " (address in use, or not an address of this machine?)");
  lws_vhost* vhost = lws_get_vhost_by_name(m.context, "default");
  m.bound_port = vhost ? lws_get_vhost_listen_port(vhost) : options.port;
}

WsServer::~WsServer() {
  if (impl_->context) lws_context_destroy(impl_->context);
}

void WsServer::run() {
  while (!impl_->stopping.load()) {
    if (lws_service(impl_->context, 0) < 0) break;
  }
}

void WsServer::request_stop() {
  impl_->stopping = true;
  wake();
}

void WsServer::send_text(std::uint64_t client, std::string text) {
  {
    std::lock_guard lock(impl_->mutex);
    const auto it = impl_->clients.find(client);
    if (it == impl_->clients.end()) return;
    auto& q = it->second.texts;
    if (q.size() >= impl_->options.max_queued_texts) q.pop_front();
    q.push_back(std::move(text));
  }
  wake();
}

void WsServer::broadcast_text(std::string text) {
  {
    std::lock_guard lock(impl_->mutex);
    for (auto& [id, c] : impl_->clients) {
      if (c.texts.size() >= impl_->options.max_queued_texts) c.texts.pop_front();
      c.texts.push_back(text);
    }
  }
  wake();
}

void WsServer::publish_frame(std::shared_ptr<const std::string> bytes, std::uint64_t frame) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->frame = std::move(bytes);
    impl_->frame_number = frame;
  }
  wake();
}

void WsServer::ack_frame(std::uint64_t client, std::uint64_t frame) {
  {
    std::lock_guard lock(impl_->mutex);
    const auto it = impl_->clients.find(client);
    if (it == impl_->clients.end()) return;
    auto& s = it->second.unacked;
    s.erase(s.begin(), s.upper_bound(frame));
  }
  wake();
}

void WsServer::wake() {
  if (impl_->context) lws_cancel_service(impl_->context);
}

int WsServer::port() const { return impl_->bound_port; }

std::size_t WsServer::clients() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->clients.size();
}

}  // namespace thaw
