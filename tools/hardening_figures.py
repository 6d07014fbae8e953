#!/usr/bin/python3
"""Figures of a running `thaw serve` under abuse (issue 14): what a viewer sees while others misbehave.

    tools/hardening_figures.py ws://127.0.0.1:8080/ backlog
        A viewer counts frames per 5 s: 5 s alone, then while one client sends sim.reset at 19 a second
        (under the rate limit) for 10 s, then 25 s more. Prints the counts, the slowest answer to a reset
        and how the resets were answered.
    tools/hardening_figures.py ws://127.0.0.1:8080/ viewer --token TOKEN
        On a server started with --token TOKEN: a viewer's frames and the simulation's steps a second,
        quiet; after another viewer's quality.set 1920x1080 full 60 (refused or not) and 30 camera.orbit
        with zoom 100; after the controller asks for 1920x1080 full at 60.
    tools/hardening_figures.py ws://127.0.0.1:8080/ flood
        40 clients each send 40 sim.reset as fast as they can, then close; time SIGTERM after it with
        e.g. `kill -TERM $PID; while grep -q 'State:.*[RSD]' /proc/$PID/status; do sleep 0.01; done`.
"""
import argparse
import asyncio
import json
import os
import sys
import time

import websockets

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import thaw_client


async def frames_per_window(url, seconds, window=5):
    """Frames a viewer receives in each `window` seconds over `seconds`."""
    counts = [0] * int(seconds // window)
    async with thaw_client.connect(url) as thaw:
        await thaw.frame()
        t0 = time.time()
        while time.time() - t0 < seconds:
            try:
                await thaw.frame(timeout=max(0.1, seconds - (time.time() - t0)))
            except asyncio.TimeoutError:
                break
            k = int((time.time() - t0) // window)
            if k < len(counts):
                counts[k] += 1
    return counts


async def resets(url, rate, seconds, deadline=120):
    """sim.reset at `rate` a second for `seconds`: the slowest answer [s], how many of each kind, and how
    many were still unanswered `deadline` seconds after the last."""
    async with websockets.connect(url, subprotocols=["thaw.v1"], max_size=None) as ws:
        sent, slowest, kinds = {}, 0.0, {}

        async def read():
            nonlocal slowest
            async for m in ws:
                if isinstance(m, str):
                    j = json.loads(m)
                    if j.get("id") in sent:
                        slowest = max(slowest, time.time() - sent.pop(j["id"]))
                        kind = j["type"] if j["type"] == "ack" else j["message"].split(":")[0]
                        kinds[kind] = kinds.get(kind, 0) + 1

        reader = asyncio.ensure_future(read())
        t0, k = time.time(), 0
        while time.time() - t0 < seconds:
            sent[k] = time.time()
            await ws.send(json.dumps({"type": "sim.reset", "id": k}))
            k += 1
            await asyncio.sleep(1 / rate)
        end = time.time() + deadline
        while sent and time.time() < end:
            await asyncio.sleep(0.05)
        reader.cancel()
        return slowest, kinds, len(sent)


async def backlog(url):
    counts = asyncio.ensure_future(frames_per_window(url, 40))
    await asyncio.sleep(5)
    slowest, kinds, unanswered = await resets(url, 19, 10)
    print("viewer frames per 5 s (alone, then resets from 5 s to 15 s):", await counts)
    print("slowest answer %.2f s, unanswered %d, answers %s" % (slowest, unanswered, kinds))


async def measure(thaw, label, seconds=8):
    fps, steps = await thaw.rates(seconds)
    print("%-50s %5.1f frames/s, %4.0f steps/s" % (label, fps, steps))


async def viewer(url, token):
    big = dict(width=1920, height=1080, surface="full", fps=60)
    async with thaw_client.connect(url) as watcher, thaw_client.connect(url) as other, \
            thaw_client.connect(url, token=token) as controller:
        await measure(watcher, "quiet")
        try:
            await other.command("quality.set", **big)
            print("a viewer's quality.set: accepted")
        except thaw_client.CommandError as e:
            print("a viewer's quality.set:", e.code)
        for _ in range(30):
            await other.command("camera.orbit", zoom=100)
        await measure(watcher, "after a viewer's quality.set and 30 zooms x100")
        ack = await controller.command("quality.set", **big)
        print("controller's quality.set ack:", {k: ack.get(k) for k in ("width", "height", "fps", "fps_limit")})
        await measure(watcher, "after the controller's 1920x1080 full 60")


async def flood(url):
    async def one():
        async with websockets.connect(url, subprotocols=["thaw.v1"], max_size=None) as ws:
            for k in range(40):
                await ws.send(json.dumps({"type": "sim.reset", "id": k}))
            await asyncio.sleep(0.5)
    await asyncio.gather(*[one() for _ in range(40)])
    print("sent 40 x 40 sim.reset")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("url")
    p.add_argument("figure", choices=["backlog", "viewer", "flood"])
    p.add_argument("--token", default=None, help="the server's --token (viewer)")
    a = p.parse_args()
    if a.figure == "backlog":
        asyncio.run(backlog(a.url))
    elif a.figure == "viewer":
        asyncio.run(viewer(a.url, a.token))
    else:
        asyncio.run(flood(a.url))


if __name__ == "__main__":
    main()
