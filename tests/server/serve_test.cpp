// The service end to end, headless: `thaw serve` on a free loopback port, a scripted client
// (tools/thaw_client.py on Debian's python3-websockets) that receives frames, turns the default scene's
// hair dryer up at the ice and sees the ice mass fall in the stats, saves a state, and a SIGINT that
// shuts the server down cleanly with its --state-out written. Bounded in time throughout.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "tests/test_support.h"

namespace thaw {
namespace {

using testing::shell_quote;
using testing::TempDir;

// The port from the server's first line ("... on http://127.0.0.1:PORT/ ..."), waiting up to `seconds`.
int wait_for_port(const TempDir& dir, int seconds) {
  for (int i = 0; i < seconds * 10; ++i) {
    const std::string log = testing::read_file_bytes(dir.path() / "serve.log");
    const auto at = log.find("127.0.0.1:");
    if (at != std::string::npos) return std::stoi(log.substr(at + 10));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return 0;
}

TEST(ServeSmoke, FramesDryerMeltsIceStateAndCleanShutdown) {
  TempDir dir("serve-smoke");
  const std::string start = "cd " + shell_quote(dir.path().string()) + " && (timeout 300 " + shell_quote(THAW_BINARY) +
                            " serve default --port 0 --state-dir states --state-out final.state"
                            " >serve.log 2>&1 & echo $! >serve.pid)";
  ASSERT_EQ(std::system(start.c_str()), 0);
  const int port = wait_for_port(dir, 60);
  ASSERT_GT(port, 0) << testing::read_file_bytes(dir.path() / "serve.log");

  testing::write_text(dir.path() / "client.py", R"(import asyncio, json, sys
sys.path.insert(0, sys.argv[2])
import thaw_client
async def main():
    async with thaw_client.connect(f"ws://127.0.0.1:{sys.argv[1]}/") as thaw:
        print("role", thaw.welcome["role"], "dryers", len(thaw.welcome["dryers"]))
        header = await thaw.save_frame("frame.jpg")
        print("frame", header["width"], header["height"])
        first = await thaw.stats()
        await thaw.command("dryer.set", dryer=0, on=True, temperature=150, speed=25)
        later = await thaw.stats(lambda s: s["ice_mass"] < first["ice_mass"] * 0.995, timeout=150)
        print("ice mass fell", later["ice_mass"] < first["ice_mass"])
        print("closure", abs(later["energy"]["closure_relative"]) < 1e-6)
        await thaw.command("state.save", name="smoke")
        try:
            await thaw.command("state.save", name="../escape")
        except thaw_client.CommandError as e:
            print("refused", e.code)
asyncio.run(main())
)");
  const std::string client = "cd " + shell_quote(dir.path().string()) + " && timeout 200 /usr/bin/python3 client.py " +
                             std::to_string(port) + " " + shell_quote(std::string(THAW_SOURCE_DIR) + "/tools") +
                             " >client.log 2>&1";
  const int client_status = std::system(client.c_str());
  const std::string out = testing::read_file_bytes(dir.path() / "client.log");

  // SIGINT to the server (the timeout wrapper passes it on), then wait for it to go.
  const std::string pid = testing::read_file_bytes(dir.path() / "serve.pid");
  const std::string stop = "kill -INT " + pid.substr(0, pid.find('\n')) + " 2>/dev/null; pkill -INT -P " +
                           pid.substr(0, pid.find('\n')) + " 2>/dev/null";
  std::system(stop.c_str());
  std::string log;
  for (int i = 0; i < 100 && log.find("stopped") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    log = testing::read_file_bytes(dir.path() / "serve.log");
  }

  EXPECT_EQ(client_status, 0) << out;
  EXPECT_NE(out.find("role controller dryers 1"), std::string::npos) << out;
  EXPECT_NE(out.find("frame 640 480"), std::string::npos) << out;
  EXPECT_NE(out.find("ice mass fell True"), std::string::npos) << out;
  EXPECT_NE(out.find("closure True"), std::string::npos) << out;
  EXPECT_NE(out.find("refused bad_field"), std::string::npos) << out;
  const std::string jpeg = testing::read_file_bytes(dir.path() / "frame.jpg");
  ASSERT_GT(jpeg.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[0]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[1]), 0xD8);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "states" / "smoke.state"));
  EXPECT_NE(log.find("thaw serve: stopped"), std::string::npos) << log;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "final.state")) << "--state-out is written on SIGINT";
}

}  // namespace
}  // namespace thaw
