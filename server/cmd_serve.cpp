// `thaw serve [SCENE]`: the live service. One port: HTTP for web/ and the thaw.v1 WebSocket protocol.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <exception>
#include <optional>
#include <thread>

#include "server/cli_args.h"
#include "server/commands.h"
#include "server/render_worker.h"
#include "server/service.h"
#include "server/session.h"
#include "server/thread_priority.h"
#include "server/ws_server.h"
#include "sim/error.h"

namespace thaw {
namespace {

// How much lower the simulation's threads run than the render thread's (nice steps; 5 gives the
// renderer about three times the simulation's share of a contended core).
constexpr int kSimulationNice = 5;

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

}  // namespace

int cmd_serve(int argc, char** argv) {
  CliArgs args(argc, argv, 2,
               {"--host", "--port", "--token", "--state-dir", "--state-out", "--device", "--web"},
               {"--quiet"});
  if (args.positional().size() > 1) throw Error("serve takes at most one scene");
  const std::string scene = args.positional().empty() ? "default" : args.positional()[0];
  ServerOptions net;
  net.host = args.value("--host").value_or("127.0.0.1");
  const long long port = args.integer("--port", 8080);
  if (port < 0 || port > 65535) throw Error("--port: expected 0..65535 (0: any free port)");
  net.port = static_cast<int>(port);
  net.web_root = args.value("--web").value_or(std::string(THAW_SOURCE_DIR) + "/web");
  ServiceOptions service_options;
  service_options.token = args.value("--token").value_or("");
  service_options.loopback = net.host == "127.0.0.1" || net.host == "localhost";
  // Anyone who can reach a non-loopback address could steer the simulation: require a token there.
  if (!service_options.loopback && service_options.token.empty())
    throw Error("--host " + net.host +
                ": serving beyond 127.0.0.1 needs --token TOKEN (clients without it watch)");

  // Frames go ahead of steps: a picture that answers a command within 200 ms matters more to someone
  // steering than the last few steps a second. The OpenCL runtime starts in a thread at a lower
  // priority, so a CPU driver's workers (pocl's) inherit it, and the simulation thread runs there too;
  // the render thread and its rasteriser's workers keep the normal priority.
  std::optional<ClRuntime> cl;
  const std::string device = args.value("--device").value_or("");
  std::exception_ptr failed;
  std::thread([&] {
    try {
      lower_this_thread_priority(kSimulationNice);
      cl.emplace(device);
    } catch (...) {
      failed = std::current_exception();
    }
  }).join();
  if (failed) std::rethrow_exception(failed);
  Session session(*cl, scene, args.sets(), args.value("--state-dir").value_or("thaw-states"));
  session.set_thread_nice(kSimulationNice);
  std::atomic<Service*> service_ptr{nullptr};
  // The scene's own camera (its `camera` block); on every scene change the service puts it back.
  RenderOptions view;
  use_camera(view, session.scene()->camera);
  // Fast surfaces marched at 3/4 of the width and height keep the stream at 12+ frames a second on 2
  // cores while the simulation runs (every pixel: 10; docs/RENDERING.md); a client can ask for full
  // quality and every pixel with quality.set.
  view.quality = "fast";
  view.scale = 0.75;
  RenderWorker renderer(session, view, [&] {
    if (Service* s = service_ptr.load()) s->frame_ready();
  });
  Service service(session, renderer, service_options);
  WsServer server(net, service);
  service.attach(server);
  service_ptr = &service;

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  session.start();
  renderer.start();
  // The signal handler only sets a flag; this thread turns it into a wake-up of the loop.
  std::thread watcher([&] {
    while (!g_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    server.request_stop();
  });
  if (!args.flag("--quiet")) {
    std::printf("thaw serve: scene '%s' on http://%s:%d/ (WebSocket subprotocol %s)%s\n", scene.c_str(),
                net.host.c_str(), server.port(), protocol::kSubprotocol,
                service_options.token.empty() ? "" : "; controller token required");
    std::fflush(stdout);
  }
  server.run();
  g_stop = true;
  watcher.join();
  renderer.stop();
  service_ptr = nullptr;
  // Stop first, then save: queued behind a backlog, the save waited for every command before it (40
  // clients x 40 resets kept the server up 90 s after SIGTERM). stop() ends after the step or rebuild
  // under way and fails the rest; the state written is the one the last finished command left.
  session.stop();
  if (auto out = args.value("--state-out")) session.save_state(*out);
  if (!args.flag("--quiet")) std::printf("thaw serve: stopped\n");
  return 0;
}

}  // namespace thaw
