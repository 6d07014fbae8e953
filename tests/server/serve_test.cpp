// The service end to end, headless: `thaw serve` on a free loopback port, a scripted client
// (tools/thaw_client.py on Debian's python3-websockets) that receives frames, turns the default scene's
// hair dryer up at the ice and sees the ice mass fall in the stats, saves a state, and a SIGINT that
// shuts the server down cleanly with its --state-out written. Bounded in time throughout.
#include <gtest/gtest.h>

#include <string>

#include "tests/server/serve_support.h"

namespace thaw {
namespace {

using testing::ServedScene;
using testing::TempDir;

TEST(ServeSmoke, FramesDryerMeltsIceStateAndCleanShutdown) {
  TempDir dir("serve-smoke");
  // The scene's own pace (heat x1000): the ice visibly melts within seconds of streaming.
  ServedScene served(dir, "default --state-dir states --state-out final.state");
  ASSERT_GT(served.port(), 0) << served.log();
  int client_status = 0;
  const std::string out = served.run_python(R"(import asyncio, json, thaw_client
async def main():
    async with thaw_client.connect(f"ws://127.0.0.1:{PORT}/") as thaw:
        print("role", thaw.welcome["role"], "dryers", len(thaw.welcome["dryers"]))
        header = await thaw.save_frame("frame.jpg")
        print("frame", header["width"], header["height"])
        first = await thaw.stats()
        ack = await thaw.command("dryer.set", dryer=0, on=True, temperature=150, speed=25)
        shown, _ = await thaw.frame_from(ack["time"])
        print("frame shows the command", shown["time"] >= ack["time"] and ack["steps"] >= first["steps"])
        print("frame rate in stats", (await thaw.stats(lambda s: s.get("fps", 0) > 0))["fps"] > 0)
        q = await thaw.command("quality.set", fps=20, jpeg_quality=70)
        print("quality", q["width"], q["height"], q["fps"], q["jpeg_quality"], q["surface"])
        later = await thaw.stats(lambda s: s["ice_mass"] < first["ice_mass"] * 0.995, timeout=150)
        print("ice mass fell", later["ice_mass"] < first["ice_mass"])
        print("closure", abs(later["energy"]["closure_relative"]) < 1e-6)
        await thaw.command("state.save", name="smoke")
        try:
            await thaw.command("state.save", name="../escape")
        except thaw_client.CommandError as e:
            print("refused", e.code)
asyncio.run(main())
)",
                                            200, &client_status);
  const bool stopped = served.stop();
  const std::string log = served.log();

  EXPECT_EQ(client_status, 0) << out;
  EXPECT_NE(out.find("role controller dryers 1"), std::string::npos) << out;
  EXPECT_NE(out.find("frame 640 480"), std::string::npos) << out;
  EXPECT_NE(out.find("frame shows the command True"), std::string::npos) << out;
  EXPECT_NE(out.find("frame rate in stats True"), std::string::npos) << out;
  EXPECT_NE(out.find("quality 640 480 20.0 70 fast"), std::string::npos) << out;
  EXPECT_NE(out.find("ice mass fell True"), std::string::npos) << out;
  EXPECT_NE(out.find("closure True"), std::string::npos) << out;
  EXPECT_NE(out.find("refused bad_field"), std::string::npos) << out;
  const std::string jpeg = testing::read_file_bytes(dir.path() / "frame.jpg");
  ASSERT_GT(jpeg.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[0]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[1]), 0xD8);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "states" / "smoke.state"));
  EXPECT_TRUE(stopped) << log;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "final.state")) << "--state-out is written on SIGINT";
}

// What a page shows is the server's state: welcome carries the scene, its dryers, the view, quality and
// camera; a scene.load by one client sends every client a `scene` event with the new scene's all, the
// camera back at the scene's own; a client that connects later (a reload) gets the quality in force,
// and camera.reset puts the scene's camera back.
TEST(ServeScene, EveryClientIsToldOfASceneChangeWithEverythingThePageShows) {
  TempDir dir("serve-scene");
  ServedScene served(dir, "default --set spacing=0.006 --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(R"(import asyncio, json, thaw_client
URL = f"ws://127.0.0.1:{PORT}/"
async def main():
    async with thaw_client.connect(URL) as ctl, thaw_client.connect(URL) as other:
        w = ctl.welcome
        print("welcome", w["scene"], len(w["dryers"]), w["camera"]["elevation"], w["view"]["view"],
              w["quality"]["surface"], w["heat_time_scale"], w["paused"])
        await ctl.command("camera.orbit", d_azimuth=40, zoom=0.5)
        await ctl.command("quality.set", surface="full")
        waiter = asyncio.ensure_future(other.scene_event())
        await asyncio.sleep(0)
        await ctl.command("scene.load", name="ice-on-plate")
        ev = await waiter
        c = ev["camera"]
        print("scene event", ev["scene"], len(ev["dryers"]), len(ev["lamps"]), c["azimuth"], c["elevation"],
              c["distance"], c["target"])
        print("quality kept", ev["quality"]["surface"], "description", len(ev["description"]) > 20)
    async with thaw_client.connect(URL) as again:
        print("reload", again.welcome["scene"], again.welcome["quality"]["surface"])
        await again.command("camera.orbit", d_azimuth=10)
        r = await again.command("camera.reset")
        print("reset", r["camera"]["azimuth"], r["camera"]["elevation"])
asyncio.run(main())
)",
                                            120, &status);
  EXPECT_EQ(status, 0) << out;
  for (const char* line :
       {"welcome default 1 40.0 surface fast 1000.0 False",
        "scene event ice-on-plate 0 0 -60.0 35.0 0.0 None", "quality kept full description True",
        "reload ice-on-plate full", "reset -60.0 35.0"})
    EXPECT_NE(out.find(line), std::string::npos) << line << "\n" << out;
  EXPECT_TRUE(served.stop()) << served.log();
}

// A run that stops tells every client at once, on every path (issue 44: a blow-up's stats came within the
// stats rate's interval of the ones before and were dropped, so viewers kept `paused: false, error: null`,
// and a later client's welcome said paused with no error). The dam break with a speed limit of 0.3 m/s blows
// up within a few dozen steps, before a client connects and again after its sim.reset.
TEST(ServeBlowUp, EveryClientHearsThatTheRunStoppedAndWhy) {
  TempDir dir("serve-blowup");
  ServedScene served(dir, "dam-break --set spacing=0.04 --set solver.max_speed=0.3");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(R"(import asyncio, thaw_client
URL = f"ws://127.0.0.1:{PORT}/"
async def main():
    welcome = None
    for _ in range(150):  # until the run has blown up (a paused run publishes no stats)
        async with thaw_client.connect(URL) as probe:
            welcome = probe.welcome
        if welcome["error"] is not None:
            break
        await asyncio.sleep(0.2)
    print("welcome", welcome["paused"], "above the limit" in (welcome["error"] or ""))
    async with thaw_client.connect(URL) as ctl, thaw_client.connect(URL) as viewer:
        waiter = asyncio.ensure_future(viewer.stats(lambda s: "error" in s, timeout=60))
        await asyncio.sleep(0)
        await ctl.command("sim.reset")  # runs again (the blow-up paused it, not a user), and blows up again
        s = await waiter
        print("stats", s["paused"], "above the limit" in s["error"])
asyncio.run(main())
)",
                                            120, &status);
  EXPECT_EQ(status, 0) << out << served.log();
  EXPECT_NE(out.find("welcome True True"), std::string::npos) << out;
  EXPECT_NE(out.find("stats True True"), std::string::npos) << out;
  EXPECT_TRUE(served.stop()) << served.log();
}

// `thaw ctl` from a shell: replies as JSON lines, the exit status says whether all were acknowledged.
TEST(ServeCtl, SendsCommandsAndPrintsTheReplies) {
  TempDir dir("serve-ctl");
  ServedScene served(dir, "ice-on-plate --set spacing=0.006 --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  const std::string url = "ws://127.0.0.1:" + std::to_string(served.port()) + "/";
  const auto ok = testing::run_thaw(
      "ctl " + url + " '{\"type\": \"sim.pause\"}' '{\"type\": \"sim.step\", \"n\": 3}'", dir);
  ASSERT_TRUE(ok.exited) << ok.err;
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find("\"type\":\"welcome\""), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("\"of\":\"sim.pause\""), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("\"of\":\"sim.step\""), std::string::npos) << ok.out;
  const auto refused = testing::run_thaw("ctl " + url + " '{\"type\": \"sim.step\", \"n\": 0}'", dir);
  EXPECT_EQ(refused.exit_code, 1) << refused.out;
  EXPECT_NE(refused.out.find("\"code\":\"bad_field\""), std::string::npos) << refused.out;
  const auto bad = testing::run_thaw("ctl " + url + " 'not json'", dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("not JSON"), std::string::npos) << bad.err;
  EXPECT_TRUE(served.stop());
  const auto gone = testing::run_thaw("ctl " + url + " '{\"type\": \"sim.pause\"}' --timeout 5", dir);
  EXPECT_EQ(gone.exit_code, 2) << gone.out;
  EXPECT_NE(gone.err.find(url), std::string::npos) << gone.err;
}

// The token bucket stops a command flood, but not frame acknowledgements, which come with every frame.
TEST(ServeRateLimit, FloodsAreRefusedButFrameAcksAreNotCounted) {
  TempDir dir("serve-rate");
  ServedScene served(dir, "ice-on-plate --set spacing=0.006");
  ASSERT_GT(served.port(), 0) << served.log();
  int client_status = 0;
  const std::string out = served.run_python(R"(import asyncio, json, thaw_client
async def main():
    async with thaw_client.connect(f"ws://127.0.0.1:{PORT}/") as thaw:
        burst = thaw.welcome["limits"]["command_burst"]
        for k in range(int(3 * burst)):
            await thaw.ws.send(json.dumps({"type": "frame.ack", "frame": k}))
        ack = await thaw.command("view.set", view="surface")
        print("after acks", ack["type"])
        replies = [thaw.send({"type": "view.set", "view": "surface"}) for _ in range(int(2 * burst))]
        kinds = [r.get("code", r["type"]) for r in await asyncio.gather(*replies)]
        # hello and the view.set above took two tokens of the full bucket
        print("flood", kinds.count("ack") >= burst - 2, kinds.count("rate_limited") > 0)
        await asyncio.sleep(1.5)
        print("later", (await thaw.command("view.set", view="surface"))["type"])
asyncio.run(main())
)",
                                            60, &client_status);
  EXPECT_TRUE(served.stop()) << served.log();
  EXPECT_EQ(client_status, 0) << out;
  EXPECT_NE(out.find("after acks ack"), std::string::npos) << out;
  EXPECT_NE(out.find("flood True True"), std::string::npos) << out;
  EXPECT_NE(out.find("later ack"), std::string::npos) << out;
}

}  // namespace
}  // namespace thaw
