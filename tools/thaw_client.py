#!/usr/bin/python3
"""A scripting client for `thaw serve` (docs/PROTOCOL.md), on Debian's python3-websockets.

    import asyncio, thaw_client

    async def main():
        async with thaw_client.connect("ws://127.0.0.1:8080/") as thaw:
            print(thaw.welcome["scene"], thaw.welcome["role"])
            await thaw.command("dryer.set", dryer=0, on=True, temperature=80, speed=12)
            stats = await thaw.stats(lambda s: s["time"] > 0.5)   # wait for a condition
            await thaw.save_frame("frame.jpg")

    asyncio.run(main())

Run as a script it is a small command line: `tools/thaw_client.py URL '{"type": "sim.pause"}' ...` sends
each JSON command and prints the server's reply to it (as `thaw ctl` does).
"""

import asyncio
import collections
import contextlib
import json
import struct
import sys
import time as _time

import websockets

FRAME_HEADER = struct.Struct("<4sQdHHI")  # "THF1", frame, sim time, width, height, JPEG bytes


class CommandError(Exception):
    """The server refused a command: `code` and `message` as in the protocol's error event."""

    def __init__(self, event):
        super().__init__(f"{event.get('of', '')} {event['code']}: {event['message']}")
        self.code = event["code"]
        self.event = event


class Thaw:
    def __init__(self, ws):
        self.ws = ws
        self.welcome = None
        self.scene = None  # the newest scene state: the welcome's, then each `scene` event's
        self.latest_stats = None
        self.latest_frame = None  # (header dict, JPEG bytes)
        self._recent_frames = collections.deque(maxlen=8)
        self._next_id = 1
        self._replies = {}
        self._stats_waiters = []
        self._scene_waiters = []
        self._frame_waiters = []
        self._reader = None

    async def _read(self):
        async for message in self.ws:
            if isinstance(message, bytes):
                magic, frame, time, width, height, length = FRAME_HEADER.unpack_from(message)
                if magic != b"THF1":
                    continue
                header = {"frame": frame, "time": time, "width": width, "height": height,
                          "received": _time.monotonic()}
                self.latest_frame = (header, message[FRAME_HEADER.size:FRAME_HEADER.size + length])
                self._recent_frames.append(self.latest_frame)
                await self.ws.send(json.dumps({"type": "frame.ack", "frame": frame}))
                for waiter in self._frame_waiters:
                    if not waiter.done():
                        waiter.set_result(self.latest_frame)
                self._frame_waiters.clear()
                continue
            event = json.loads(message)
            kind = event.get("type")
            if kind == "welcome":
                self.welcome = event
                self.scene = event
                if self._welcome_waiter and not self._welcome_waiter.done():
                    self._welcome_waiter.set_result(event)
            elif kind == "scene":
                self.scene = event
                for future in self._scene_waiters:
                    if not future.done():
                        future.set_result(event)
                self._scene_waiters.clear()
            elif kind == "stats":
                self.latest_stats = event
                for waiter in list(self._stats_waiters):
                    predicate, future = waiter
                    if not future.done() and predicate(event):
                        future.set_result(event)
                        self._stats_waiters.remove(waiter)
            elif kind in ("ack", "error") and event.get("id") in self._replies:
                future = self._replies.pop(event["id"])
                if not future.done():
                    future.set_result(event)

    async def start(self, token=None, timeout=10):
        self._welcome_waiter = asyncio.get_running_loop().create_future()
        self._reader = asyncio.create_task(self._read())
        hello = {"type": "hello", "version": 1}
        if token:
            hello["token"] = token
        await self.ws.send(json.dumps(hello))
        await asyncio.wait_for(self._welcome_waiter, timeout)
        return self

    async def send(self, message, timeout=30):
        """Sends one command (a dict with `type`); returns the ack or error event."""
        message = dict(message)
        message["id"] = self._next_id
        self._next_id += 1
        future = asyncio.get_running_loop().create_future()
        self._replies[message["id"]] = future
        await self.ws.send(json.dumps(message))
        return await asyncio.wait_for(future, timeout)

    async def command(self, kind, timeout=30, **fields):
        """Sends a command; returns its ack, raises CommandError on an error event."""
        reply = await self.send(dict(type=kind, **fields), timeout)
        if reply["type"] == "error":
            raise CommandError(reply)
        return reply

    async def stats(self, predicate=lambda s: True, timeout=60):
        """The next stats event for which predicate(stats) holds."""
        future = asyncio.get_running_loop().create_future()
        self._stats_waiters.append((predicate, future))
        return await asyncio.wait_for(future, timeout)

    async def scene_event(self, timeout=60):
        """The next `scene` event (after a scene.load, state.load or sim.reset by any client)."""
        future = asyncio.get_running_loop().create_future()
        self._scene_waiters.append(future)
        return await asyncio.wait_for(future, timeout)

    async def frame(self, timeout=30):
        """The next frame: (header, JPEG bytes)."""
        future = asyncio.get_running_loop().create_future()
        self._frame_waiters.append(future)
        return await asyncio.wait_for(future, timeout)

    async def frame_from(self, sim_time, timeout=30):
        """The first frame drawn from simulated time sim_time or later (an ack's `time` says when a
        command took effect), whether it has already arrived or not. Its header's `received` is the
        time.monotonic() at which it arrived."""
        deadline = _time.monotonic() + timeout
        while True:
            for f in self._recent_frames:
                if f[0]["time"] >= sim_time:
                    return f
            await self.frame(max(0.0, deadline - _time.monotonic()))

    async def rates(self, seconds):
        """Frames a second this client receives over `seconds`, and the simulation's steps a second
        meanwhile (from the stats before and after)."""
        await self.frame()
        s0 = await self.stats()
        t0, frames = _time.monotonic(), 0
        while _time.monotonic() - t0 < seconds:
            await self.frame()
            frames += 1
        s1 = await self.stats()
        wall = _time.monotonic() - t0
        return frames / wall, (s1["steps"] - s0["steps"]) / wall

    async def save_frame(self, path, timeout=30):
        header, jpeg = await self.frame(timeout)
        with open(path, "wb") as f:
            f.write(jpeg)
        return header

    async def close(self):
        if self._reader:
            self._reader.cancel()
        await self.ws.close()


@contextlib.asynccontextmanager
async def connect(url, token=None, timeout=10):
    """Connects with the thaw.v1 subprotocol, says hello and waits for the welcome."""
    ws = await websockets.connect(url, subprotocols=["thaw.v1"], max_size=None, open_timeout=timeout,
                                  close_timeout=2)
    thaw = Thaw(ws)
    try:
        await thaw.start(token, timeout)
        yield thaw
    finally:
        await thaw.close()


async def _main(url, commands):
    async with connect(url) as thaw:
        print(json.dumps(thaw.welcome))
        status = 0
        for text in commands:
            try:
                reply = await thaw.send(json.loads(text))
            except json.JSONDecodeError as e:
                print(json.dumps({"type": "error", "code": "bad_json", "message": f"not JSON: {e}"}))
                status = 1
                continue
            print(json.dumps(reply))
            status |= reply["type"] == "error"
        return status


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: thaw_client.py ws://HOST:PORT/ [JSON-COMMAND ...]")
    sys.exit(asyncio.run(_main(sys.argv[1], sys.argv[2:])))
