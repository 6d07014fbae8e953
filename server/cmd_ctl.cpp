// `thaw ctl URL JSON...`: sends commands to a running `thaw serve` from a shell and prints the replies,
// one JSON line each (the welcome first). Exit status 0 when every command was acknowledged, 1 when one
// was refused, 2 when the server could not be reached.
#include <libwebsockets.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "server/cli_args.h"
#include "server/commands.h"
#include "server/protocol.h"
#include "sim/error.h"
#include "sim/json_text.h"
#include "sim/schema.h"

namespace thaw {
namespace {

struct CtlState {
  std::deque<std::string> to_send;  // hello first, then the commands with ids 1..n
  std::size_t expected = 0;         // replies (ack or error) still to come
  bool welcomed = false, failed = false, done = false, refused = false;
  std::string error, rx;
};

int ctl_callback(lws* wsi, lws_callback_reasons reason, void*, void* in, std::size_t len) {
  auto* st = static_cast<CtlState*>(lws_context_user(lws_get_context(wsi)));
  if (!st) return 0;
  switch (reason) {
    case LWS_CALLBACK_CLIENT_CONNECTION_ERROR:
      st->failed = true;
      st->error = in ? std::string(static_cast<const char*>(in), len) : "connection failed";
      st->done = true;
      return 0;
    case LWS_CALLBACK_CLIENT_ESTABLISHED:
      lws_callback_on_writable(wsi);
      return 0;
    case LWS_CALLBACK_CLIENT_RECEIVE: {
      if (lws_frame_is_binary(wsi)) return 0;  // frames: not what a shell wants
      st->rx.append(static_cast<const char*>(in), len);
      if (!lws_is_final_fragment(wsi) || lws_remaining_packet_payload(wsi) != 0) return 0;
      std::string text;
      text.swap(st->rx);
      Json event;
      try {
        event = Json::parse(text);
      } catch (const std::exception&) {
        return 0;
      }
      const std::string type = event.value("type", "");
      if (type == "welcome") {
        st->welcomed = true;
        std::printf("%s\n", text.c_str());
      } else if ((type == "ack" || type == "error") && event.contains("id")) {
        std::printf("%s\n", text.c_str());
        if (type == "error") st->refused = true;
        if (st->expected > 0 && --st->expected == 0) st->done = true;
      }
      std::fflush(stdout);
      if (!st->to_send.empty()) lws_callback_on_writable(wsi);
      return 0;
    }
    case LWS_CALLBACK_CLIENT_WRITEABLE: {
      if (st->to_send.empty()) return 0;
      const std::string m = std::move(st->to_send.front());
      st->to_send.pop_front();
      std::vector<unsigned char> buffer(LWS_PRE + m.size());
      std::memcpy(buffer.data() + LWS_PRE, m.data(), m.size());
      if (lws_write(wsi, buffer.data() + LWS_PRE, m.size(), LWS_WRITE_TEXT) < int(m.size())) return -1;
      if (!st->to_send.empty()) lws_callback_on_writable(wsi);
      return 0;
    }
    case LWS_CALLBACK_CLIENT_CLOSED:
      if (!st->done) {
        st->failed = true;
        st->error = "the server closed the connection";
      }
      st->done = true;
      return 0;
    default:
      return 0;
  }
}

}  // namespace

int cmd_ctl(int argc, char** argv) {
  CliArgs args(argc, argv, 2, {"--token", "--timeout"}, {});
  if (args.positional().empty())
    throw Error(
        "ctl needs a URL, e.g. ws://127.0.0.1:8080/, then JSON commands such as '{\"type\": \"sim.pause\"}'");
  const std::string url = args.positional()[0];
  // ws://HOST:PORT/PATH
  const std::string prefix = "ws://";
  if (url.rfind(prefix, 0) != 0) throw Error("ctl: the URL must start with ws://, got '" + url + "'");
  const std::string rest = url.substr(prefix.size());
  const std::string hostport = rest.substr(0, rest.find('/'));
  const std::string path = rest.find('/') == std::string::npos ? "/" : rest.substr(rest.find('/'));
  const std::string host = hostport.substr(0, hostport.find(':'));
  int port = 80;
  if (hostport.find(':') != std::string::npos) {
    try {
      port = std::stoi(hostport.substr(hostport.find(':') + 1));
    } catch (const std::exception&) {
      throw Error("ctl: bad port in '" + url + "'");
    }
  }

  CtlState st;
  Json hello = {{"type", "hello"}, {"version", protocol::kVersion}};
  if (auto t = args.value("--token")) hello["token"] = *t;
  st.to_send.push_back(hello.dump());
  for (std::size_t i = 1; i < args.positional().size(); ++i) {
    Json command;
    try {
      command = parse_json(args.positional()[i]);
    } catch (const JsonShapeError& e) {
      throw Error("ctl: command " + std::to_string(i) + ": " + e.what());
    } catch (const std::exception&) {
      throw Error("ctl: command " + std::to_string(i) + " is not JSON: " + args.positional()[i]);
    }
    if (!command.is_object()) throw Error("ctl: command " + std::to_string(i) + " is not a JSON object");
    command["id"] = i;
    st.to_send.push_back(command.dump());
    ++st.expected;
  }

  lws_set_log_level(LLL_ERR, nullptr);
  lws_protocols protocols[] = {{protocol::kSubprotocol, ctl_callback, 0, 16384, 0, nullptr, 0},
                               {nullptr, nullptr, 0, 0, 0, nullptr, 0}};
  lws_context_creation_info info{};
  info.port = CONTEXT_PORT_NO_LISTEN;
  info.protocols = protocols;
  info.user = &st;
  lws_context* context = lws_create_context(&info);
  if (!context) throw Error("ctl: cannot start libwebsockets");
  lws_client_connect_info ci{};
  ci.context = context;
  ci.address = host.c_str();
  ci.port = port;
  ci.path = path.c_str();
  ci.host = host.c_str();
  ci.origin = host.c_str();
  ci.protocol = protocol::kSubprotocol;
  if (!lws_client_connect_via_info(&ci)) {
    lws_context_destroy(context);
    throw Error("ctl: cannot connect to " + url);
  }
  const double timeout = args.number("--timeout", 30.0);
  const auto start = std::chrono::steady_clock::now();
  // Without commands, the welcome is the whole answer.
  while (!st.done && !(st.expected == 0 && st.welcomed)) {
    lws_service(context, 50);
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout) {
      st.failed = true;
      st.error = "no answer within " + std::to_string(int(timeout)) + " s";
      break;
    }
  }
  lws_context_destroy(context);
  if (st.failed && !(st.welcomed && st.expected == 0)) {
    std::fprintf(stderr, "thaw ctl: %s: %s\n", url.c_str(), st.error.c_str());
    return 2;
  }
  return st.refused ? 1 : 0;
}

}  // namespace thaw
