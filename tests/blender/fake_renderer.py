#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A stand-in for `tesela render SCENE --pipe`, written from docs/protocol.md
alone (it does not import the add-on), with fault modes for the tests.

Environment:
  FAKE_TESELA_MODE   ok (default) | garbage | version | truncated | die | flood |
                     silent | error | errorhang | loaderror | slow | bench
  FAKE_TESELA_LOG    append one JSON line per run: pid, argv, scene facts
  FAKE_TESELA_TILE   tile edge in pixels (default 16)
  FAKE_TESELA_DELAY  seconds to sleep after each tile (default 0; 'slow' uses 0.05)

Image: pixel (X, Y) of the full frame (top-left origin, Y down) is
  R = (X + 0.5) / W, G = (Y + 0.5) / H, B = 0.25, A = 1,
so tests can check orientation, region offsets and percentage scaling.
"""

import json
import os
import signal
import struct
import sys
import threading
import time

STOP = threading.Event()


def frame(kind, payload):
    return struct.pack("<II", kind, len(payload)) + payload


def parse_args(argv):
    if len(argv) < 2 or argv[0] != "render":
        sys.stderr.write("usage: tesela render SCENE --pipe [options]\n")
        sys.exit(2)
    opts = {"scene": argv[1], "pipe": False, "region": None}
    i = 2
    while i < len(argv):
        a = argv[i]
        if a == "--pipe":
            opts["pipe"] = True
            i += 1
        elif a in ("--denoise", "--no-caustics-reflective", "--no-caustics-refractive"):
            opts[a[2:].replace("-", "_")] = True
            i += 1
        elif a == "--region":
            opts["region"] = [int(v) for v in argv[i + 1:i + 5]]
            i += 5
        elif a in ("--integrator", "--spp", "--max-depth", "--width", "--height",
                   "--seed", "--threads", "--pipe-version", "--passes", "--adaptive-threshold",
                   "--adaptive-min-samples", "--time-limit", "--denoise-prefilter", "--filter",
                   "--filter-width", "--diffuse-bounces", "--glossy-bounces",
                   "--transmission-bounces", "--volume-bounces", "--transparent-bounces",
                   "--clamp-direct",
                   "--clamp-indirect", "--blur-glossy", "--tile-size"):
            opts[a[2:].replace("-", "_")] = argv[i + 1]
            i += 2
        else:
            sys.stderr.write("error: unknown option %s\n" % a)
            sys.exit(2)
    return opts


def watch_stdin():
    try:
        while True:
            if not os.read(0, 4096):
                break
    except OSError:
        pass
    STOP.set()


def cancelled(out):
    log = os.environ.get("FAKE_TESELA_LOG")
    if log:
        with open(log, "a", encoding="utf-8") as f:
            f.write(json.dumps({"pid": os.getpid(), "cancelled_at": time.time()}) + "\n")
    sys.stderr.write("CANCELLED\n")
    sys.stderr.flush()
    os._exit(130)


def main():
    mode = os.environ.get("FAKE_TESELA_MODE", "ok")
    opts = parse_args(sys.argv[1:])
    out = sys.stdout.buffer

    try:
        with open(opts["scene"], "rb") as f:
            doc = json.loads(f.read().decode("utf-8"))
    except (OSError, ValueError) as exc:
        if opts["pipe"]:
            out.write(frame(5, ("cannot load scene %s: %s" % (opts["scene"], exc)).encode()))
            out.flush()
        sys.exit(3)

    render_ext = doc.get("extensions", {}).get("TESELA_render", {})
    width = int(opts.get("width") or render_ext.get("width", 64))
    height = int(opts.get("height") or render_ext.get("height", 64))
    spp = int(opts.get("spp") or render_ext.get("spp", 16))
    region = opts["region"] or [0, 0, width, height]
    rx, ry, rw, rh = region

    log = os.environ.get("FAKE_TESELA_LOG")
    if log:
        bins = [b.get("uri") for b in doc.get("buffers", [])]
        scene_dir = os.path.dirname(os.path.abspath(opts["scene"]))
        with open(log, "a", encoding="utf-8") as f:
            f.write(json.dumps({
                "pid": os.getpid(), "argv": sys.argv[1:], "mode": mode,
                "scene_dir": scene_dir,
                "bin_exists": all(os.path.exists(os.path.join(scene_dir, b)) for b in bins if b),
                "has_camera": bool(doc.get("cameras")),
            }) + "\n")

    signal.signal(signal.SIGTERM, lambda *a: cancelled(out))
    threading.Thread(target=watch_stdin, daemon=True).start()

    if mode == "silent":
        # Never writes a frame and ignores both stdin EOF and SIGTERM:
        # only SIGKILL ends it.
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        while True:
            time.sleep(1)
    if mode == "garbage":
        out.write(b"Segmentation fault? no, just text on stdout\n" * 4)
        out.flush()
        sys.exit(0)
    if mode == "loaderror":
        out.write(frame(5, b"scene load error: accessor 3 is out of bounds"))
        out.flush()
        sys.exit(3)

    version = 7 if mode == "version" else 2
    tile = int(os.environ.get("FAKE_TESELA_TILE", "16"))
    tiles = [(x, y, min(tile, rw - x), min(tile, rh - y))
             for y in range(0, rh, tile) for x in range(0, rw, tile)]
    if mode == "oldcli":
        # A renderer from before protocol 2: clap refuses the option it does not know.
        sys.stderr.write("error: unexpected argument '--pipe-version' found\n\n"
                         "Usage: tesela render [OPTIONS] [SCENE]\n")
        sys.exit(2)
    hello = b"TSLA" + struct.pack("<IIIII", version, rw, rh, spp, len(tiles))
    if version == 2:
        hello += struct.pack("<II", 1, 8) + b"Combined" + struct.pack("<I", 4) + b"RGBA"
    out.write(frame(1, hello))
    out.flush()
    if mode == "errorhang":
        # Reports an error, then neither exits nor honours stdin EOF or SIGTERM.
        out.write(frame(5, b"device lost (fake), and now I hang"))
        out.flush()
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        while True:
            time.sleep(1)
    if mode == "version":
        time.sleep(0.2)
        sys.exit(0)
    if mode == "flood":
        chunk = ("renderer chatter " * 64 + "\n").encode()
        for _ in range(4 * 1024 * 1024 // len(chunk)):  # 4 MiB on stderr
            sys.stderr.buffer.write(chunk)
        sys.stderr.flush()
    out.write(frame(4, struct.pack("<I", 1) + "fake renderer, mode %s".encode() % mode.encode()))

    delay = float(os.environ.get("FAKE_TESELA_DELAY", "0.05" if mode == "slow" else "0"))
    t0 = time.time()
    if mode == "bench":
        # As fast as possible: each tile is filled with one value (its index), so the
        # cost measured on the reading side is the pipe's, not this script's.
        import array
        cache = {}
        for i, (tx, ty, tw, th) in enumerate(tiles):
            if STOP.is_set():
                cancelled(out)
            if (tw, th) not in cache:
                cache[(tw, th)] = array.array("f", [0.5]) * (tw * th * 4)
            px = cache[(tw, th)]
            out.write(frame(2, struct.pack("<IIII", tx, ty, tw, th) + px.tobytes()))
            out.write(frame(3, struct.pack("<IIId", i + 1, len(tiles), spp, time.time() - t0)))
        out.write(frame(6, json.dumps({"seconds": time.time() - t0}).encode()))
        out.flush()
        return 0
    for i, (tx, ty, tw, th) in enumerate(tiles):
        if STOP.is_set():
            cancelled(out)
        px = bytearray()
        for yy in range(th):
            gy = (ry + ty + yy + 0.5) / height
            for xx in range(tw):
                gx = (rx + tx + xx + 0.5) / width
                px += struct.pack("<ffff", gx, gy, 0.25, 1.0)
        payload = struct.pack("<IIII", tx, ty, tw, th) + bytes(px)
        data = frame(2, payload)
        if mode == "truncated" and i == len(tiles) // 2:
            out.write(data[: len(data) // 2])
            out.flush()
            sys.exit(0)
        if mode == "die" and i == len(tiles) // 2:
            out.write(data[: len(data) // 3])
            out.flush()
            os.kill(os.getpid(), signal.SIGKILL)
        if mode == "error" and i == len(tiles) // 2:
            out.write(frame(5, "out of memory while building the BVH (fake)".encode()))
            out.flush()
            sys.stderr.write("error: out of memory while building the BVH (fake)\n")
            sys.exit(1)
        out.write(data)
        out.write(frame(3, struct.pack("<IIId", i + 1, len(tiles), spp, time.time() - t0)))
        out.flush()
        if delay:
            time.sleep(delay)
    stats = {"seconds": time.time() - t0, "samples": rw * rh * spp, "rays": rw * rh * spp,
             "samples_per_second": 0.0, "rays_per_second": 0.0, "rejected_samples": 0}
    out.write(frame(6, json.dumps(stats).encode()))
    out.flush()
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BrokenPipeError:
        os._exit(141)
