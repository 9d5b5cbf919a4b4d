"""What a Dask worker runs: one `tesela render` of a scene that travelled with the task.

The task function returns a plain dict (never raises for a renderer failure), so the client
sees the renderer's exit status and message whatever the worker's Python can pickle.
"""

from __future__ import annotations

import ctypes
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from pathlib import Path

#: Exit status of `tesela` when the renderer could not be started at all.
EXIT_RENDER = 1

_PR_SET_PDEATHSIG = 1

#: How often a running renderer's task looks at the run's cancel event.
CANCEL_POLL_SECONDS = 0.5


def find_tesela(explicit: str | None = None) -> str | None:
    """The renderer on this machine: `explicit`, else env TESELA_BIN, else `tesela` on PATH."""
    for candidate in (explicit, os.environ.get("TESELA_BIN")):
        if candidate:
            return candidate
    return shutil.which("tesela")


def _worker_name() -> str:
    """The Dask worker's address (the host name outside a worker)."""
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return socket.gethostname()


def _die_with_parent():
    """Runs in the child before exec: the kernel kills the renderer when the worker process
    dies (a farm killing a worker must not leave a renderer running on)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):
        pass


def unpack(files: dict[str, bytes], into: Path) -> None:
    """Writes the scene's files (relative paths -> bytes) under `into`."""
    for rel, data in files.items():
        path = (into / rel).resolve()
        if into.resolve() not in path.parents:
            raise ValueError(f"{rel}: a scene file must lie below the scene's folder")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)


def _cancelled(event_name: str | None) -> bool:
    """Whether the client set the run's cancel event (Dask cannot stop a running task)."""
    if event_name is None:
        return False
    try:
        from distributed import Event

        return Event(event_name).is_set()
    except (ImportError, ValueError, OSError):
        return False


def _run(cmd: list[str], cancel: str | None) -> tuple[int, bytes]:
    """Runs the renderer to its end, or until the run is cancelled (then SIGTERM, which the
    renderer answers by stopping at once). Returns (exit status, stderr)."""
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, preexec_fn=_die_with_parent)
    try:
        while True:
            try:
                _, err = proc.communicate(timeout=CANCEL_POLL_SECONDS)
                return proc.returncode, err
            except subprocess.TimeoutExpired:
                if _cancelled(cancel):
                    proc.terminate()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def render(scene: dict, args: list[str], output_name: str, tesela: str | None = None,
           cancel: str | None = None) -> dict:
    """Renders `scene` with `tesela render SCENE ARGS`, writing `output_name` (a file name the
    args refer to as `{out}`), and returns `{"returncode", "stderr", "output", "host",
    "seconds"}` with the output file's bytes (None on failure).

    `scene` is `{"main": relative path of the scene file, "files": {relative path: bytes}}`
    (the scene travels with the task) or `{"path": a path every worker can read}`.
    `cancel` names a Dask Event the client sets to stop the run's renderers.
    """
    started = time.monotonic()
    host = _worker_name()
    binary = find_tesela(tesela)
    result = {"returncode": EXIT_RENDER, "stderr": "", "output": None, "host": host}
    if binary is None:
        result["stderr"] = (f"tesela-farm worker on {host}: no tesela binary (set TESELA_BIN "
                            "on the worker, put tesela on its PATH, or pass --tesela)")
        return result
    with tempfile.TemporaryDirectory(prefix="tesela-farm-") as tmp:
        tmp = Path(tmp)
        if "path" in scene:
            scene_path = scene["path"]
        else:
            try:
                unpack(scene["files"], tmp / "scene")
            except (OSError, ValueError) as exc:
                result["stderr"] = f"tesela-farm worker on {host}: {exc}"
                return result
            scene_path = str(tmp / "scene" / scene["main"])
        out = tmp / output_name
        cmd = [binary, "render", scene_path, "--quiet"]
        cmd += [str(out) if a == "{out}" else a for a in args]
        try:
            returncode, stderr = _run(cmd, cancel)
        except OSError as exc:
            result["stderr"] = f"tesela-farm worker on {host}: cannot run {binary}: {exc}"
            return result
        result["returncode"] = returncode
        result["stderr"] = stderr.decode("utf-8", "replace").strip()
        if "path" not in scene:
            # Name the scene's files as the user named them, not by this worker's temp folder.
            result["stderr"] = result["stderr"].replace(str(tmp / "scene") + os.sep, "")
        if returncode < 0:
            # Killed by a signal (a crash, or the machine's OOM killer): a failed render.
            result["returncode"] = EXIT_RENDER
            result["stderr"] += (f"\ntesela-farm worker on {host}: the renderer was killed "
                                 f"by signal {-returncode}")
        if returncode == 0:
            try:
                result["output"] = out.read_bytes()
            except OSError as exc:
                result["returncode"] = EXIT_RENDER
                result["stderr"] += f"\ntesela-farm worker on {host}: no output: {exc}"
    result["seconds"] = time.monotonic() - started
    return result
