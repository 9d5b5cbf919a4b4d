"""`tesela-farm render`: a Tesela render distributed over a Dask cluster.

Exit status as `tesela`'s: 0 success, 1 render failed (or the scheduler could not be
reached), 2 bad usage, 3 scene could not be loaded, 130 cancelled.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from pathlib import Path

from . import farm, jobs, worker

_EPILOG = """\
Arguments after `--` go to every `tesela render` (e.g. -- --width 640 --integrator path_mis).
A single scene is a still: its samples are split into --parts ranges rendered on the workers
and merged exactly. --frames renders one task per scene file into OUT with #### for the
frame number; --batch renders one task per scene file into the folder OUT.
Exit status: 0 success, 1 render failed or scheduler unreachable, 2 bad usage, 3 scene could
not be loaded, 130 cancelled."""


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="tesela-farm",
                                description="Distribute Tesela renders over a Dask cluster.")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("render", help="render a still, a frame sequence or a batch of scenes",
                       epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    r.add_argument("scenes", nargs="+", type=Path, metavar="SCENE",
                   help=".gltf/.glb scene files")
    where = r.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                       help="address of a running `dask scheduler`")
    where.add_argument("--local", type=int, metavar="N",
                       help="start a local cluster of N worker processes")
    r.add_argument("-o", "--output", required=True, type=Path,
                   help="output image (still), pattern with # (--frames) or folder (--batch)")
    mode = r.add_mutually_exclusive_group()
    mode.add_argument("--frames", action="store_true",
                      help="the scenes are the frames of an animation, one task each")
    mode.add_argument("--batch", action="store_true",
                      help="independent scenes, one task each, OUT is a folder")
    r.add_argument("--frame-start", type=int, default=1, metavar="F",
                   help="frame number of the first scene with --frames (default 1)")
    r.add_argument("--format", choices=["exr", "png"], default="exr",
                   help="image format of --batch outputs (default exr)")
    r.add_argument("--parts", type=int, metavar="K",
                   help="sample ranges of a still (default: 2 per worker thread)")
    r.add_argument("--spp", type=int, metavar="N",
                   help="samples per pixel (default: the scene's setting, else 64)")
    r.add_argument("--passes", default="", metavar="LIST",
                   help="render passes, as `tesela render --passes`")
    r.add_argument("--denoise", action="store_true",
                   help="denoise (a still: after merging the parts)")
    r.add_argument("--tesela", metavar="PATH",
                   help="the tesela binary on the workers and here (default: env TESELA_BIN, "
                        "else tesela on PATH)")
    r.add_argument("--shared", action="store_true",
                   help="the scene paths are readable by every worker (default: the scene "
                        "files travel with the tasks)")
    r.add_argument("--threads", type=int, metavar="N",
                   help="render threads per task (default: all cores; with --local, the "
                        "cores divided among the workers)")
    r.add_argument("--connect-timeout", type=float, default=5.0, metavar="S",
                   help="seconds to wait for the scheduler (default 5)")
    return p


def _run_render(a: argparse.Namespace, render_args: list[str]) -> None:
    scenes: list[Path] = a.scenes
    for s in scenes:
        if not s.is_file():
            raise farm.FarmError(f"{s}: no such scene file", farm.EXIT_LOAD)
    still = not (a.frames or a.batch)
    if still and len(scenes) != 1:
        raise farm.FarmError(f"{len(scenes)} scenes given: a still is one scene (use --frames "
                             "for an animation or --batch for independent scenes)",
                             farm.EXIT_USAGE)
    if a.parts is not None and a.parts < 1:
        raise farm.FarmError(f"--parts {a.parts} must be at least 1", farm.EXIT_USAGE)
    if a.spp is not None and a.spp < 1:
        raise farm.FarmError(f"--spp {a.spp} must be at least 1", farm.EXIT_USAGE)
    if still and not a.output.parent.is_dir():
        raise farm.FarmError(f"{a.output}: the output folder {a.output.parent} does not exist",
                             farm.EXIT_USAGE)
    passes = [p for p in a.passes.split(",") if p.strip()]
    args = list(render_args)
    threads = a.threads
    if threads is None and a.local:
        threads = max(1, (os.cpu_count() or 1) // a.local)
    if threads is not None:
        args += ["--threads", str(threads)]
    if not still:
        if a.spp is not None:
            args += ["--spp", str(a.spp)]
        if passes:
            args += ["--passes", ",".join(passes)]
        if a.denoise:
            args += ["--denoise"]
        if a.frames:
            try:
                outputs = [Path(jobs.frame_output(str(a.output), a.frame_start + i))
                           for i in range(len(scenes))]
            except ValueError as exc:
                raise farm.FarmError(str(exc), farm.EXIT_USAGE) from exc
        else:
            outputs = [a.output / f"{s.stem}.{a.format}" for s in scenes]
            if len({o.name for o in outputs}) != len(outputs):
                raise farm.FarmError("--batch: two scenes have the same file name",
                                     farm.EXIT_USAGE)
    if still and worker.find_tesela(a.tesela) is None:
        # Before the cluster is reached or started: the parts could not be merged here.
        raise farm.FarmError("no local tesela binary to merge the parts (set TESELA_BIN or "
                             "pass --tesela)", farm.EXIT_USAGE)
    settings = farm.Settings(tesela=a.tesela, shared=a.shared, render_args=args)
    client, cluster = farm.connect(a.scheduler, a.local, a.connect_timeout)
    try:
        if still:
            workers = sum(w.get("nthreads", 1)
                          for w in client.scheduler_info()["workers"].values())
            parts = a.parts or max(2, 2 * workers)
            farm.render_still(client, scenes[0], a.output, settings, parts, spp=a.spp,
                              passes=passes, denoise=a.denoise)
        else:
            farm.render_each(client, scenes, outputs, settings)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    render_args: list[str] = []
    if "--" in argv:
        cut = argv.index("--")
        argv, render_args = argv[:cut], argv[cut + 1:]
    a = _parser().parse_args(argv)
    # SIGTERM (a farm manager stopping the job) ends the run as Ctrl-C does: tasks cancelled.
    # The caller's handler comes back afterwards (main() may run inside another program).
    try:
        previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
    except ValueError:  # not the main thread: signals stay as they are
        previous = None
    try:
        _run_render(a, render_args)
    except farm.FarmError as exc:
        print(f"tesela-farm: error: {exc.message}", file=sys.stderr, flush=True)
        return exc.code
    except jobs.SceneError as exc:
        print(f"tesela-farm: error: {exc}", file=sys.stderr, flush=True)
        return farm.EXIT_LOAD
    except KeyboardInterrupt:
        print("tesela-farm: cancelled", file=sys.stderr, flush=True)
        return farm.EXIT_CANCELLED
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    return 0


if __name__ == "__main__":
    sys.exit(main())
