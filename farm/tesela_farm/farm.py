"""Running a render on a Dask cluster: a still split into sample ranges and merged, or one
task per scene file (the frames of an animation, or a batch)."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from . import jobs, worker

#: `tesela`'s exit statuses (its --help).
EXIT_RENDER = 1
EXIT_USAGE = 2
EXIT_LOAD = 3
EXIT_CANCELLED = 130

#: Passes the denoiser is guided by: rendered into the parts when the still is denoised.
DENOISE_GUIDES = ("denoising_albedo", "denoising_normal")


class FarmError(Exception):
    """A farm render that did not finish: `message` for the user, `code` the exit status."""

    def __init__(self, message: str, code: int = EXIT_RENDER):
        super().__init__(message)
        self.message = message
        self.code = code


def _stderr(line: str) -> None:
    print(f"tesela-farm: {line}", file=sys.stderr, flush=True)


@dataclass
class Settings:
    """How tasks run their renderer."""

    #: The `tesela` binary on the workers (None: their TESELA_BIN, else PATH).
    tesela: str | None = None
    #: The scene files lie on a path every worker reads (else they travel with the tasks).
    shared: bool = False
    #: Extra `tesela render` arguments for every task.
    render_args: list[str] = field(default_factory=list)
    #: Report a line of progress.
    progress: Callable[[str], None] = _stderr


def connect(scheduler: str | None = None, local: int | None = None, timeout: float = 5.0,
            threads_per_worker: int = 1):
    """A Dask client: of the scheduler at `scheduler` (an unreachable one is a FarmError
    after `timeout` seconds), or of a new local cluster of `local` worker processes.
    Returns `(client, cluster or None)`; close both when done."""
    from distributed import Client, LocalCluster

    if local is not None:
        if local < 1:
            raise FarmError(f"--local {local}: a local cluster needs at least 1 worker",
                            EXIT_USAGE)
        cluster = LocalCluster(n_workers=local, threads_per_worker=threads_per_worker,
                               processes=True, dashboard_address=None)
        return Client(cluster), cluster
    try:
        return Client(scheduler, timeout=timeout), None
    except (OSError, ValueError, TypeError) as exc:
        raise FarmError(f"cannot reach the Dask scheduler at {scheduler} within "
                        f"{timeout:g} s ({type(exc).__name__}: {exc}); is `dask scheduler` "
                        "running there, and is the address tcp://HOST:PORT?") from exc
    except Exception as exc:  # distributed raises its own timeout types too
        raise FarmError(f"cannot reach the Dask scheduler at {scheduler} within "
                        f"{timeout:g} s ({type(exc).__name__}: {exc})") from exc


def _scene_for_task(path: Path, settings: Settings) -> dict:
    if settings.shared:
        return {"path": str(path.resolve())}
    return jobs.bundle(path)


def _run(client, tasks: Sequence[tuple[str, dict, list[str], str]], settings: Settings,
         on_result: Callable[[int, dict], None]) -> None:
    """Submits `(label, scene, args, output name)` tasks, reports each as it finishes, and
    hands each result to `on_result(index, result)`. The first failure cancels the rest and
    raises FarmError with the renderer's message and exit status."""
    from distributed import Event, as_completed

    run = os.urandom(4).hex()
    cancel = f"tesela-farm-cancel-{run}"
    futures = {}
    for i, (label, scene, args, out_name) in enumerate(tasks):
        fut = client.submit(worker.render, scene, args, out_name, settings.tesela, cancel,
                            pure=False, key=f"tesela-{label.replace(' ', '-')}-{run}")
        futures[fut] = (i, label)
    settings.progress(f"{len(futures)} tasks submitted to {client.scheduler.address}")
    done = 0
    try:
        for fut in as_completed(futures):
            i, label = futures[fut]
            try:
                result = fut.result()
            except Exception as exc:
                raise FarmError(f"{label}: the task failed on the cluster "
                                f"({type(exc).__name__}: {exc})") from exc
            if result["returncode"] != 0:
                msg = result["stderr"] or "(no message)"
                raise FarmError(f"{label} failed on {result['host']} with exit status "
                                f"{result['returncode']}: {msg}", result["returncode"])
            done += 1
            settings.progress(f"[{done}/{len(futures)}] {label} done on {result['host']} in "
                              f"{result['seconds']:.2f} s")
            on_result(i, result)
    except BaseException:
        # Dask cancels the tasks that wait; the event stops the renderers already running.
        try:
            Event(cancel, client=client).set()
        except Exception:  # noqa: BLE001 - the scheduler may be gone: nothing more to stop
            pass
        client.cancel(list(futures))
        raise


def _has_option(args: Sequence[str], *names: str) -> bool:
    return any(a == n or a.startswith(n + "=") for a in args for n in names)


def _check_args(args: Sequence[str]) -> None:
    for opt in ("-o", "--output", "--sample-range", "--accumulators", "--pipe"):
        if _has_option(args, opt):
            raise FarmError(f"{opt} is the farm's to set, not a renderer argument", EXIT_USAGE)


def render_still(client, scene: Path, output: Path, settings: Settings, parts: int,
                 spp: int | None = None, passes: Sequence[str] = (), denoise: bool = False,
                 merge_tesela: str | None = None) -> None:
    """Renders one still as `parts` sample ranges on the cluster and merges them into
    `output` with the local `tesela merge` (denoising after the merge if asked)."""
    _check_args(settings.render_args)
    if _has_option(settings.render_args, "--denoise"):
        raise FarmError("--denoise is the farm's option for a still (it denoises after the "
                        "merge), not a renderer argument", EXIT_USAGE)
    merger = worker.find_tesela(merge_tesela or settings.tesela)
    if merger is None:
        raise FarmError("no local tesela binary to merge the parts (set TESELA_BIN or pass "
                        "--tesela)", EXIT_USAGE)
    spp = spp or jobs.scene_spp(scene)
    task_scene = _scene_for_task(scene, settings)
    rendered = list(passes) + [g for g in DENOISE_GUIDES if denoise and g not in passes]
    base = ["--spp", str(spp)] + settings.render_args
    if rendered:
        base += ["--passes", ",".join(rendered)]
    plan = jobs.split_samples(spp, parts)
    tasks = [(f"{scene.name} part {p.index} (samples {p.range})", task_scene,
              base + ["--sample-range", p.range, "--accumulators", "{out}"], "part.exr")
             for p in plan]
    with tempfile.TemporaryDirectory(prefix="tesela-farm-merge-") as tmp:
        files = [Path(tmp) / f"part{p.index:04d}.exr" for p in plan]

        def keep(i: int, result: dict) -> None:
            files[i].write_bytes(result["output"])

        _run(client, tasks, settings, keep)
        cmd = [merger, "merge", *map(str, files), "-o", str(output), "--quiet"]
        if denoise:
            cmd += ["--denoise", "--passes", ",".join(passes)]
        started = time.monotonic()
        proc = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              check=False)
        if proc.stderr.strip():
            settings.progress(proc.stderr.strip())
        if proc.returncode != 0:
            raise FarmError(f"merging the parts failed: {proc.stderr.strip()}",
                            proc.returncode if proc.returncode > 0 else EXIT_RENDER)
    settings.progress(f"merged {len(plan)} parts ({spp} spp) -> {output} in "
                      f"{time.monotonic() - started:.2f} s")


def render_each(client, scenes: Sequence[Path], outputs: Sequence[Path],
                settings: Settings) -> None:
    """Renders every scene whole as its own task (frames of an animation, or a batch),
    writing `outputs[i]` for `scenes[i]` as each finishes."""
    _check_args(settings.render_args)
    if len(scenes) != len(outputs):
        raise ValueError("one output per scene")
    for out in outputs:
        if out.suffix.lower() not in (".exr", ".png"):
            raise FarmError(f"{out}: unknown output format (use a .exr or .png file name)",
                            EXIT_USAGE)
    tasks = []
    for scene, out in zip(scenes, outputs):
        tasks.append((f"{scene.name}", _scene_for_task(scene, settings),
                      ["-o", "{out}"] + settings.render_args, f"image{out.suffix.lower()}"))

    def keep(i: int, result: dict) -> None:
        outputs[i].parent.mkdir(parents=True, exist_ok=True)
        outputs[i].write_bytes(result["output"])

    _run(client, tasks, settings, keep)
