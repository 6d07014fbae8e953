// The service under abuse and load, loopback only and bounded: several clients sending thousands of
// random and malformed messages (the server stays up and still answers correctly), and ten viewers
// beside a client that never acknowledges a frame (the others keep their frame rate; the server's memory
// stays flat).
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "tests/server/serve_support.h"

namespace thaw {
namespace {

using testing::ServedScene;
using testing::TempDir;

// Resident memory of a process [kB], from /proc.
long rss_kb(const std::string& pid) {
  std::ifstream in("/proc/" + pid + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

TEST(ServeLoad, FuzzFromSeveralClientsLeavesTheServerUpAndCorrect) {
  TempDir dir("serve-fuzz");
  ServedScene served(dir, "ice-on-plate --set spacing=0.006 --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(R"(
import asyncio, json, random, websockets, thaw_client
VALID = [{"type": "sim.pause"}, {"type": "sim.resume"}, {"type": "dryer.set", "dryer": 0, "on": True},
         {"type": "camera.orbit", "d_azimuth": 5}, {"type": "view.set", "view": "particles"},
         {"type": "quality.set", "width": 320, "height": 240}, {"type": "state.save", "name": "fz"},
         {"type": "param.set", "path": "heat.time_scale", "value": 50}, {"type": "sim.step", "n": 2}]
def mutate(rng):
    m = dict(rng.choice(VALID))
    kind = rng.randrange(7)
    if kind == 0: return bytes(rng.randrange(256) for _ in range(rng.randrange(1, 200)))
    if kind == 1: return json.dumps(m)[: rng.randrange(1, 30)]
    if kind == 2: m[rng.choice(list(m))] = rng.choice([None, [], {}, "x" * 300, -1e308, 1e308, True, "../../etc"])
    if kind == 3: m["type"] = rng.choice(["", "dryer", "sim.step.", "x" * 100, 7])
    if kind == 4: return "x" * rng.choice([16 * 1024 + 1, 70000])
    if kind == 5: m["extra" + str(rng.randrange(9))] = rng.random()
    return json.dumps(m)
async def fuzzer(seed, count):
    rng = random.Random(seed)
    async with websockets.connect(f"ws://127.0.0.1:{PORT}/", subprotocols=["thaw.v1"], max_size=None) as ws:
        for _ in range(count):
            await ws.send(mutate(rng))
        # Drain what came back for a moment: errors and acks, never a closed socket.
        replies = 0
        try:
            while True:
                msg = await asyncio.wait_for(ws.recv(), 0.5)
                replies += isinstance(msg, str)
        except asyncio.TimeoutError:
            pass
        return replies
async def main():
    replies = await asyncio.gather(*[fuzzer(seed, 1500) for seed in range(4)])
    print("replies", all(r > 0 for r in replies))
    async with thaw_client.connect(f"ws://127.0.0.1:{PORT}/") as thaw:
        await thaw.command("sim.resume")
        before = (await thaw.stats())["steps"]
        after = (await thaw.stats(lambda s: s["steps"] > before, timeout=30))["steps"]
        print("still stepping", after > before)
        try:
            await thaw.command("dryer.set", dryer=0, speed=1000)
        except thaw_client.CommandError as e:
            print("still checking", e.code)
asyncio.run(main())
)", 240, &status);
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("replies True"), std::string::npos) << out;
  EXPECT_NE(out.find("still stepping True"), std::string::npos) << out;
  EXPECT_NE(out.find("still checking bad_field"), std::string::npos) << out;
  EXPECT_TRUE(served.stop()) << served.log();
}

TEST(ServeLoad, TenViewersKeepTheirFramesBesideASlowClient) {
  TempDir dir("serve-viewers");
  ServedScene served(dir, "ice-on-plate --set spacing=0.006 --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  const std::string pid = served.server_pid();
  int status = 0;
  const std::string script = R"(
import asyncio, time, websockets, thaw_client
async def viewer(seconds):
    async with thaw_client.connect(f"ws://127.0.0.1:{PORT}/") as thaw:
        await thaw.frame()
        t0, n = time.time(), 0
        while time.time() - t0 < seconds:
            await thaw.frame()
            n += 1
        return n / (time.time() - t0)
async def slow(seconds):
    # Connects, says hello and never reads again: its socket fills, it acknowledges nothing.
    ws = await websockets.connect(f"ws://127.0.0.1:{PORT}/", subprotocols=["thaw.v1"], max_size=None)
    await ws.send('{"type": "hello", "version": 1}')
    await asyncio.sleep(seconds + 2)
    ws.transport.abort()
async def main():
    alone = await viewer(5)
    rates = await asyncio.gather(slow(12), *[viewer(12) for _ in range(10)])
    print("alone %.2f" % alone)
    print("with slow", " ".join("%.2f" % r for r in rates[1:]))
    print("min ratio %.2f" % (min(rates[1:]) / alone))
asyncio.run(main())
)";
  // Memory before and after the crowd.
  const long before = rss_kb(pid);
  const std::string out = served.run_python(script, 120, &status);
  const long after = rss_kb(pid);
  EXPECT_EQ(status, 0) << out;
  std::printf("%s[ info ] server RSS %ld kB before, %ld kB after\n", out.c_str(), before, after);
  const auto at = out.find("min ratio ");
  ASSERT_NE(at, std::string::npos) << out;
  // One render serves everyone: ten viewers each keep most of the rate one had alone, and the client
  // that never acknowledges costs them nothing beyond that.
  EXPECT_GT(std::stod(out.substr(at + 10)), 0.6) << out;
  ASSERT_GT(before, 0);
  EXPECT_LT(after, before + 32 * 1024) << "memory stays flat (within 32 MB) with a client that never reads";
  EXPECT_TRUE(served.stop()) << served.log();
}

}  // namespace
}  // namespace thaw
