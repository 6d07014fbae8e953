#!/usr/bin/python3
"""Streaming figures of a running `thaw serve`: frames per second with one viewer and with ten, and the
time from sending a dryer command to the arrival of the first frame drawn from the simulated time at
which the command took effect (its ack says when) or later.

    tools/stream_figures.py ws://127.0.0.1:8080/ [--fast] [--scale S] [--fps F] [--tries N]

With --melt F it instead watches as one viewer until the scene's ice has lost the fraction F of its mass
(the stats' ice_fraction, from the moment it connects), or for --limit seconds, and prints the frames per
second it received, the simulated seconds per wall second meanwhile and the wall time the melt took.
"""
import argparse
import asyncio
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import thaw_client


async def viewer(url, seconds):
    """Frames per second this viewer receives, and the simulation's steps per second meanwhile."""
    async with thaw_client.connect(url) as thaw:
        return await thaw.rates(seconds)


async def latencies(url, tries):
    out = []
    async with thaw_client.connect(url) as thaw:
        await thaw.frame()
        for k in range(tries):
            t0 = time.monotonic()
            ack = await thaw.command("dryer.set", dryer=0, on=(k % 2 == 0))
            header, _ = await thaw.frame_from(ack["time"])
            out.append(header["received"] - t0)
            await asyncio.sleep(0.3)
    return out


def summary(latencies_s):
    ms = sorted(1000 * x for x in latencies_s)
    return "median %.0f ms, max %.0f ms (%s)" % (statistics.median(ms), ms[-1], " ".join("%.0f" % x for x in ms))


async def main(url, fast, tries, settings):
    async with thaw_client.connect(url) as thaw:
        ack = await thaw.command("quality.set", surface="fast" if fast else "full", **settings)
    print("surface quality %s marched at %g of %dx%d, frame rate cap %g/s" %
          (ack["surface"], ack["scale"], ack["width"], ack["height"], ack["fps"]))
    fps, steps = await viewer(url, 8)
    print("1 viewer: %.1f frames/s; simulation %.0f steps/s" % (fps, steps))
    print("1 viewer: dryer command to frame: " + summary(await latencies(url, tries)))
    # Ten clients: nine watch while the tenth (also a viewer) sends the commands and times them.
    watchers = [asyncio.create_task(viewer(url, 8 + 0.5 * tries)) for _ in range(9)]
    await asyncio.sleep(1)
    timed = await latencies(url, tries)
    rates = await asyncio.gather(*watchers)
    print("10 viewers: " + " ".join("%.1f" % r[0] for r in rates) + " frames/s (the nine watchers); "
          "simulation %.0f steps/s" % statistics.mean(r[1] for r in rates))
    print("10 viewers: dryer command to frame: " + summary(timed))

async def melt(url, fraction, limit, settings):
    """One viewer until ice_fraction falls by `fraction`: frames/s, simulated s per wall s, wall time."""
    async with thaw_client.connect(url) as thaw:
        if settings:
            await thaw.command("quality.set", **settings)
        await thaw.frame()
        s0 = await thaw.stats()
        if s0.get("ice_fraction") is None:
            print("--melt: scene '%s' has no ice to melt" % s0.get("scene"))
            return False
        t0, frames, s1 = time.monotonic(), 0, s0
        while s1["ice_fraction"] > s0["ice_fraction"] - fraction and time.monotonic() - t0 < limit:
            await thaw.frame()
            frames += 1
            s1 = thaw.latest_stats or s1
        wall = time.monotonic() - t0
        melted = s0["ice_fraction"] - s1["ice_fraction"]
        print("1 viewer: %.1f frames/s; %.4f simulated s per wall s (%.1f wall s per simulated s), %.0f steps/s" %
              (frames / wall, (s1["time"] - s0["time"]) / wall, wall / max(s1["time"] - s0["time"], 1e-12),
               (s1["steps"] - s0["steps"]) / wall))
        print("ice fraction %.4f -> %.4f (%.1f %% of the start lost) in %.1f s of wall time, %.4f -> %.4f s "
              "simulated%s" % (s0["ice_fraction"], s1["ice_fraction"], 100 * melted, wall, s0["time"], s1["time"],
                               "" if melted >= fraction else "; stopped at --limit before the melt"))
        return melted >= fraction


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("url", help="ws://HOST:PORT/ of a running thaw serve")
    parser.add_argument("--fast", action="store_true", help="ask for fast surface quality first")
    parser.add_argument("--tries", type=int, default=10, help="dryer commands timed per case")
    parser.add_argument("--fps", type=float, help="ask for this frame rate cap first")
    parser.add_argument("--scale", type=float, help="ask for this fraction of width and height marched first")
    parser.add_argument("--melt", type=float, help="watch until the ice has lost this fraction of its mass")
    parser.add_argument("--limit", type=float, default=1800, help="longest wall time to watch with --melt [s]")
    args = parser.parse_args()
    settings = {k: v for k, v in (("fps", args.fps), ("scale", args.scale)) if v}
    if args.melt:
        if args.fast:
            settings["surface"] = "fast"
        sys.exit(0 if asyncio.run(melt(args.url, args.melt, args.limit, settings)) else 1)
    asyncio.run(main(args.url, args.fast, args.tries, settings))
