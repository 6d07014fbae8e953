#!/usr/bin/python3
"""Streaming figures of a running `thaw serve`: frames per second with one viewer and with ten, and the
time from a dryer command to the first frame drawn from a simulated time at or after it.

    tools/stream_figures.py ws://127.0.0.1:8080/ [--fast]

The command's simulated time is taken from the next stats event after its ack (stats come at most ten
times a second), so the latency includes up to 100 ms of that wait and overstates the true delay.
"""
import asyncio
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import thaw_client


async def viewer(url, seconds):
    async with thaw_client.connect(url) as thaw:
        await thaw.frame()
        t0, frames = time.time(), 0
        while time.time() - t0 < seconds:
            await thaw.frame()
            frames += 1
        return frames / (time.time() - t0)


async def latencies(url, tries=5):
    out = []
    async with thaw_client.connect(url) as thaw:
        await thaw.frame()
        for k in range(tries):
            t0 = time.time()
            await thaw.command("dryer.set", dryer=0, on=(k % 2 == 0))
            t_command = (await thaw.stats())["time"]
            while (await thaw.frame())[0]["time"] < t_command:
                pass
            out.append(time.time() - t0)
            await asyncio.sleep(0.3)
    return out


async def main(url, fast):
    async with thaw_client.connect(url) as thaw:
        await thaw.command("quality.set", surface="fast" if fast else "full")
    print("surface quality", "fast" if fast else "full")
    print("1 viewer: %.1f frames/s" % await viewer(url, 8))
    rates = await asyncio.gather(*[viewer(url, 8) for _ in range(10)])
    print("10 viewers: " + " ".join("%.1f" % r for r in rates) + " frames/s")
    print("dryer command to frame: " + " ".join("%.0f" % (1000 * x) for x in await latencies(url)) + " ms")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: stream_figures.py ws://HOST:PORT/ [--fast]")
    asyncio.run(main(sys.argv[1], "--fast" in sys.argv[2:]))
