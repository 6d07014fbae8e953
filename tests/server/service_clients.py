#!/usr/bin/python3
"""Clients that exercise a running `thaw serve`, shared by the service's tests (serve_load_test.cpp and
the AddressSanitizer run, asan_service.sh).

    service_clients.py PORT fuzz [smoke]

fuzz: four clients send 6,000 random and malformed messages; then the server must still step and still
refuse a bad command. smoke: a dryer change, a state save, a refused path. Each prints what it saw,
one line per check ("... True" or the refusal code), which the caller checks.
"""
import asyncio, json, os, random, sys, time, websockets

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import hardening_figures, thaw_client
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
# How long a reply may take at most: an event is waited for, not a fixed moment, so a machine many
# times slower than ours (load 10-15 from other jobs) only takes longer. Scaled by THAW_TEST_TIME_SCALE.
DEADLINE = 120 * float(os.environ.get("THAW_TEST_TIME_SCALE", "1"))
async def fuzzer(PORT, seed, count):
    rng = random.Random(seed)
    async with websockets.connect(f"ws://127.0.0.1:{PORT}/", subprotocols=["thaw.v1"], max_size=None) as ws:
        for _ in range(count):
            await ws.send(mutate(rng))
        # The last message carries a marker id, answered at once by the network thread (an ack, or a
        # refusal for the rate): once it is in, the server has read everything sent before it. Errors
        # and acks come back, never a closed socket.
        marker = f"end-{seed}"
        await ws.send(json.dumps({"type": "hello", "version": 1, "id": marker}))
        replies, end = 0, asyncio.get_running_loop().time() + DEADLINE
        while True:
            left = end - asyncio.get_running_loop().time()
            if left <= 0:
                break
            try:
                msg = await asyncio.wait_for(ws.recv(), left)
            except asyncio.TimeoutError:
                break
            if not isinstance(msg, str):
                continue
            replies += 1
            if json.loads(msg).get("id") == marker:
                break
        return replies
async def fuzz(PORT):
    replies = await asyncio.gather(*[fuzzer(PORT, seed, 1500) for seed in range(4)])
    print("replies", all(r > 0 for r in replies))
    async with thaw_client.connect(f"ws://127.0.0.1:{PORT}/") as thaw:
        await thaw.command("sim.resume")
        before = (await thaw.stats())["steps"]
        after = (await thaw.stats(lambda s: s["steps"] > before, timeout=DEADLINE))["steps"]
        print("still stepping", after > before)
        try:
            await thaw.command("dryer.set", dryer=0, speed=1000)
        except thaw_client.CommandError as e:
            print("still checking", e.code)

async def backlog(PORT):
    """A viewer's frames alone, then beside one client sending sim.reset at 19/s (under the rate limit)."""
    url = f"ws://127.0.0.1:{PORT}/"
    alone = sum(await hardening_figures.frames_per_window(url, 4, 4))
    # One reset on its own, timed in the same run: what a rebuild costs on this machine, loaded or not.
    async with thaw_client.connect(url) as thaw:
        t0 = time.time()
        await thaw.command("sim.reset", timeout=DEADLINE)
        print("one reset %.2f s" % (time.time() - t0))
    flood = asyncio.ensure_future(hardening_figures.resets(url, 19, 6, DEADLINE))
    during = sum(await hardening_figures.frames_per_window(url, 6, 6))
    slowest, kinds, unanswered = await flood
    print("frames alone %d in 4 s, during resets %d in 6 s" % (alone, during))
    print("ratio %.2f" % ((during / 6) / max(alone / 4, 1e-9)))
    print("slowest answer %.2f s, unanswered %d, kinds %s" % (slowest, unanswered, kinds))
async def flood(PORT):
    """40 clients each send 40 sim.reset as fast as they can."""
    await hardening_figures.flood(f"ws://127.0.0.1:{PORT}/")
    print("flooded")

async def smoke(PORT):
    async with thaw_client.connect(f"ws://127.0.0.1:{PORT}/") as thaw:
        header = await thaw.frame()
        print("frame", header[0]["width"] > 0)
        await thaw.command("sim.resume")
        await thaw.command("param.set", path="heat.time_scale", value=20)
        await thaw.command("state.save", name="smoke")
        try:
            await thaw.command("state.load", name="../../etc/passwd")
        except thaw_client.CommandError as e:
            print("refused", e.code)


if __name__ == "__main__":
    port = int(sys.argv[1])
    checks = {"fuzz": fuzz, "smoke": smoke}
    for name in sys.argv[2:]:
        asyncio.run(checks[name](port))
