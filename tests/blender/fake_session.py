#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A stand-in for `tesela session`, written from docs/session.md alone (it does not import the
add-on), with fault modes for the viewport tests.

Environment:
  FAKE_SESSION_MODE   ok (default) | die (killed by SIGKILL while sending its first image of
                      the second view) | error (answers every `material` with an ERROR frame)
                      | oldversion (HELLO of version 99) | nosession (exits 2 with a usage
                      message, as a renderer without the subcommand)
  FAKE_SESSION_LOG    append one JSON line per command received (plus a "start" line with
                      the pid and argv)
  FAKE_SESSION_DELAY  seconds to wait before taking each command (default 0)

A `mesh` or `load` whose file does not exist is answered by an ERROR frame, as the real session
answers a file it cannot read.

After each `view` (once it has a `load`) it sends two IMAGE frames: pixel size 2, then 1
(flag "last"). Pixel (X, Y) of the view (top-left origin) is
  R = (X + 0.5) / W, G = (Y + 0.5) / H, B = (generation mod 8) / 8, A = 1
(a data pixel at pixel size 2 takes the value of its top-left view pixel).
"""

import array
import json
import os
import signal
import struct
import sys
import time

COMMAND, HELLO, ERROR, IMAGE, STATS = 32, 1, 5, 16, 17


def frame(kind, payload):
    return struct.pack("<II", kind, len(payload)) + payload


def read_exact(stream, n):
    data = b""
    while len(data) < n:
        chunk = stream.read(n - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def log(entry):
    path = os.environ.get("FAKE_SESSION_LOG")
    if path:
        with open(path, "a") as f:
            f.write(json.dumps(entry) + "\n")


def image(generation, view, pixel_size, last):
    w, h = view["width"], view["height"]
    x0, y0, bw, bh = view.get("border") or (0, 0, w, h)
    dw, dh = -(-bw // pixel_size), -(-bh // pixel_size)
    samples = 4 if pixel_size == 1 else 1
    head = struct.pack("<Q11I", generation, w, h, x0, y0, bw, bh, pixel_size, dw, dh, samples,
                       1 if last else 0)
    row = array.array("f", bytes(16 * dw))
    row[0::4] = array.array("f", [(x0 + i * pixel_size + 0.5) / w for i in range(dw)])
    row[2::4] = array.array("f", [(generation % 8) / 8.0]) * dw
    row[3::4] = array.array("f", [1.0]) * dw
    rows = []
    for j in range(dh):
        row[1::4] = array.array("f", [(y0 + j * pixel_size + 0.5) / h]) * dw
        rows.append(row.tobytes())
    return frame(IMAGE, head + b"".join(rows))


def main():
    mode = os.environ.get("FAKE_SESSION_MODE", "ok")
    if len(sys.argv) < 2 or sys.argv[1] != "session" or mode == "nosession":
        sys.stderr.write("error: unrecognized subcommand 'session'\n")
        sys.exit(2)
    log({"start": os.getpid(), "argv": sys.argv[1:]})
    out = sys.stdout.buffer
    inp = sys.stdin.buffer
    version = 99 if mode == "oldversion" else 1
    out.write(frame(HELLO, b"TSLS" + struct.pack("<I", version)
                    + json.dumps({"renderer": "fake", "threads": 1}).encode()))
    out.flush()
    generation = 0
    loaded = False
    views = 0
    while True:
        header = read_exact(inp, 8)
        if header is None:
            sys.exit(0)
        kind, length = struct.unpack("<II", header)
        payload = read_exact(inp, length)
        if payload is None:
            sys.exit(0)
        if kind != COMMAND:
            continue
        time.sleep(float(os.environ.get("FAKE_SESSION_DELAY", "0")))
        (n,) = struct.unpack_from("<I", payload, 0)
        cmd = json.loads(payload[4:4 + n].decode("utf-8"))
        log(cmd)
        name = cmd.get("cmd")
        if name == "stop":
            sys.exit(0)
        path = cmd.get("path")
        if name in ("mesh", "load") and not os.path.isfile(str(path)):
            out.write(frame(ERROR, json.dumps({"command": name, "id": cmd.get("id"),
                                               "message": "cannot read %s" % path,
                                               "fatal": False}).encode()))
            out.flush()
            continue
        if mode == "error" and name == "material":
            out.write(frame(ERROR, json.dumps({"command": "material", "id": cmd.get("id"),
                                               "message": "no material named '%s'" % cmd.get("name"),
                                               "fatal": False}).encode()))
            out.flush()
            continue
        if name in ("load", "view", "settings", "transform", "material", "light", "world",
                    "visibility", "mesh"):
            generation += 1
        if name == "load":
            loaded = True
        if name == "view":
            cmd_view = cmd
            views += 1
        if name in ("view", "load", "transform", "material", "light", "world", "visibility",
                    "mesh") and loaded and views:
            first = image(generation, cmd_view, 2, False)
            if mode == "die" and views == 2:
                out.write(first[:len(first) // 2])  # killed mid-frame
                out.flush()
                os.kill(os.getpid(), signal.SIGKILL)
            out.write(first)
            out.write(image(generation, cmd_view, 1, True))
            out.write(frame(STATS, json.dumps({"generation": generation, "samples": 4,
                                               "state": "done"}).encode()))
            out.flush()


if __name__ == "__main__":
    main()
