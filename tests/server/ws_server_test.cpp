// The network loop alone: a WebSocket client (Debian's python3-websockets, as the scripted-control tools
// will use) against a WsServer with an echoing handler: the subprotocol, whole messages, oversize
// messages refused without dropping the connection, frames held back until acknowledged, and the static
// client over HTTP. Loopback only, bounded in time.
#include "server/ws_server.h"

#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>

#include "sim/error.h"
#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::TempDir;

class Echo : public WsHandler {
 public:
  WsServer* server = nullptr;
  std::uint64_t frame = 0;
  void on_open(std::uint64_t client, const std::string&) override { server->send_text(client, "welcome"); }
  void on_text(std::uint64_t client, std::string_view m) override {
    const std::string s(m);
    if (s.rfind("ack ", 0) == 0) {
      server->ack_frame(client, std::stoull(s.substr(4)));
    } else if (s.rfind("frames ", 0) == 0) {
      for (int k = std::stoi(s.substr(7)); k > 0; --k) {
        ++frame;
        server->publish_frame(std::make_shared<const std::string>("frame-" + std::to_string(frame)), frame);
      }
    } else {
      server->send_text(client, "echo:" + s);
    }
  }
  void on_oversize(std::uint64_t client, std::size_t bytes) override {
    server->send_text(client, "oversize " + std::to_string(bytes));
  }
  void on_binary(std::uint64_t client, std::size_t bytes) override {
    server->send_text(client, "binary " + std::to_string(bytes));
  }
  void on_close(std::uint64_t) override {}
};

// Runs a Python asyncio client against ws://127.0.0.1:PORT/; its stdout is the test's evidence.
std::string run_client(int port, const std::string& body, const TempDir& dir) {
  const std::string script = R"(import asyncio, sys, urllib.request, websockets
PORT = )" + std::to_string(port) +
                             R"(
async def main():
    async with websockets.connect(f"ws://127.0.0.1:{PORT}/", subprotocols=["thaw.v1"], max_size=None,
                                  open_timeout=5, close_timeout=2) as ws:
        async def recv():
            return await asyncio.wait_for(ws.recv(), 5)
)" + body + R"(
asyncio.run(main())
)";
  testing::write_text(dir.path() / "client.py", script);
  const std::string out = (dir.path() / "client.out").string();
  const std::string cmd = "timeout 30 /usr/bin/python3 " +
                          testing::shell_quote((dir.path() / "client.py").string()) + " >" +
                          testing::shell_quote(out) + " 2>&1";
  const int status = std::system(cmd.c_str());
  return testing::read_file_bytes(out) +
         (status == 0 ? "" : "\n[client exit " + std::to_string(status) + "]");
}

TEST(WsServer, MessagesFramesAndFlowControl) {
  Echo echo;
  ServerOptions o;
  o.port = 0;
  o.web_root = std::string(THAW_SOURCE_DIR) + "/web";
  WsServer server(o, echo);
  echo.server = &server;
  ASSERT_GT(server.port(), 0);
  std::thread loop([&] { server.run(); });
  TempDir dir("ws-server");
  const std::string out = run_client(server.port(), R"(
        print(await recv())
        await ws.send("hello")
        print(await recv())
        await ws.send("x" * 20000)
        print(await recv())
        await ws.send("still here")
        print(await recv())
        await ws.send("frames 1")
        print(await recv())
        await ws.send("frames 3")
        got = []
        try:
            while True:
                got.append(await asyncio.wait_for(ws.recv(), 1.0))
        except asyncio.TimeoutError:
            pass
        print("without ack", len(got))
        await ws.send("ack 4")
        await ws.send("frames 1")
        print("after ack", (await recv()).decode())
        html = urllib.request.urlopen(f"http://127.0.0.1:{PORT}/", timeout=5).read().decode()
        print("http", "thaw" in html)
)",
                                     dir);
  server.request_stop();
  loop.join();
  EXPECT_NE(out.find("welcome\necho:hello\n"), std::string::npos) << out;
  EXPECT_NE(out.find("oversize 20000\necho:still here\n"), std::string::npos)
      << "an oversize message is refused and the connection stays\n"
      << out;
  EXPECT_NE(out.find("b'frame-1'\n"), std::string::npos) << out;
  EXPECT_NE(out.find("without ack 1\n"), std::string::npos)
      << "with frame 1 unacknowledged, the window of two lets one more through\n"
      << out;
  EXPECT_TRUE(out.find("after ack frame-4") != std::string::npos ||
              out.find("after ack frame-5") != std::string::npos)
      << "after the ack the newest frame comes\n"
      << out;
  EXPECT_NE(out.find("http True"), std::string::npos) << out;
  EXPECT_EQ(out.find("[client exit"), std::string::npos) << out;
}

TEST(WsServer, HandshakesWithoutOurSubprotocolAreRefusedAndBinaryIsAnswered) {
  // Upgrades with no subprotocol were accepted with 101 and then left dead (100 held for 30 s were never
  // closed); binary messages got no reply at all.
  Echo echo;
  ServerOptions o;
  o.port = 0;
  WsServer server(o, echo);
  echo.server = &server;
  std::thread loop([&] { server.run(); });
  TempDir dir("ws-handshake");
  const std::string script = R"(import asyncio, websockets
PORT = )" + std::to_string(server.port()) +
                             R"(
async def attempt(sub):
    try:
        ws = await websockets.connect(f"ws://127.0.0.1:{PORT}/", subprotocols=sub, open_timeout=5)
    except websockets.exceptions.InvalidStatusCode as e:
        return "refused %d" % e.status_code
    except Exception as e:
        return "refused " + type(e).__name__
    await ws.close()
    return "accepted"
async def main():
    print("none:", await attempt(None))
    print("other:", await attempt(["chat"]))
    async with websockets.connect(f"ws://127.0.0.1:{PORT}/", subprotocols=["thaw.v1"], open_timeout=5) as ws:
        print(await asyncio.wait_for(ws.recv(), 5))
        await ws.send(b"\x00\x01\x02")
        print(await asyncio.wait_for(ws.recv(), 5))
asyncio.run(main())
)";
  testing::write_text(dir.path() / "client.py", script);
  const std::string cmd = "timeout 30 /usr/bin/python3 " + testing::shell_quote(dir / "client.py") + " >" +
                          testing::shell_quote(dir / "client.out") + " 2>&1";
  const int status = std::system(cmd.c_str());
  server.request_stop();
  loop.join();
  const std::string out = testing::read_file_bytes(dir / "client.out");
  EXPECT_EQ(status, 0) << out;
  // lws closes the connection before any response (it sends no 400 in this phase): no 101, no socket.
  EXPECT_NE(out.find("none: refused"), std::string::npos) << out;
  EXPECT_NE(out.find("other: refused"), std::string::npos) << out;
  EXPECT_NE(out.find("welcome\nbinary 3\n"), std::string::npos) << out;
  EXPECT_EQ(server.clients(), 0u);
}

TEST(WsServer, BindingABusyPortIsAnErrorNamingTheAddress) {
  Echo echo;
  ServerOptions o;
  o.port = 0;
  WsServer first(o, echo);
  o.port = first.port();
  try {
    WsServer second(o, echo);
    FAIL() << "a second server bound the same port";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(o.port)), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace thaw
