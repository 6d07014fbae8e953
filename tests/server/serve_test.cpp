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
)", 200, &client_status);
  const bool stopped = served.stop();
  const std::string log = served.log();

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
  EXPECT_TRUE(stopped) << log;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "final.state")) << "--state-out is written on SIGINT";
}

}  // namespace
}  // namespace thaw
