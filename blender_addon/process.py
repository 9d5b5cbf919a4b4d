# SPDX-License-Identifier: MIT
"""Child processes of the add-on: draining stderr, stopping a renderer, private temp folders.

No bpy: the final render (engine.py) and the viewport session client share it, and tests drive
it outside Blender."""

import collections
import os
import shutil
import signal
import subprocess
import tempfile
import threading

STDERR_TAIL_BYTES = 64 * 1024
STOP_GRACE_SECONDS = 0.15  # stdin closed -> SIGTERM -> SIGKILL, each this long


class StderrTail:
    """Drains a pipe in a thread, keeping only the last `limit` bytes."""

    def __init__(self, pipe, limit=STDERR_TAIL_BYTES):
        self.pipe = pipe
        self.limit = limit
        self.chunks = collections.deque()
        self.size = 0
        self.total = 0
        self.lock = threading.Lock()
        self.thread = threading.Thread(target=self._run, name="tesela-stderr", daemon=True)
        self.thread.start()

    def _run(self):
        fd = self.pipe.fileno()
        try:
            while True:
                chunk = os.read(fd, 65536)
                if not chunk:
                    break
                with self.lock:
                    self.chunks.append(chunk)
                    self.size += len(chunk)
                    self.total += len(chunk)
                    while self.size > self.limit and len(self.chunks) > 1:
                        self.size -= len(self.chunks.popleft())
        except (OSError, ValueError):
            pass

    def text(self, max_lines=8):
        with self.lock:
            data = b"".join(self.chunks)[-self.limit:]
        lines = [ln for ln in data.decode("utf-8", errors="replace").splitlines() if ln.strip()]
        return "\n".join(lines[-max_lines:])


TMP_PREFIX = "tesela-render-"


def make_tmpdir():
    """A fresh private folder for one render, named after this Blender's pid so that a later
    render can remove what a killed Blender left behind."""
    return tempfile.mkdtemp(prefix="%s%d-" % (TMP_PREFIX, os.getpid()))


def _pid_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:  # a zombie (dead, not yet reaped) counts as dead
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return True


def sweep_stale_tmpdirs():
    """Remove render folders of Blender processes that no longer exist (killed mid-render)."""
    base = tempfile.gettempdir()
    try:
        names = os.listdir(base)
    except OSError:
        return
    me = os.getpid()
    uid = os.getuid() if hasattr(os, "getuid") else None
    for name in names:
        if not name.startswith(TMP_PREFIX):
            continue
        pid = name[len(TMP_PREFIX):].split("-", 1)[0]
        if not pid.isdigit() or int(pid) == me or _pid_alive(int(pid)):
            continue
        path = os.path.join(base, name)
        try:
            if uid is not None and os.stat(path).st_uid != uid:
                continue
        except OSError:
            continue
        shutil.rmtree(path, ignore_errors=True)


def _describe_exit(code):
    if code is None:
        return "still running"
    if code < 0:
        try:
            return "killed by signal %s" % signal.Signals(-code).name
        except ValueError:
            return "killed by signal %d" % -code
    return "exit code %d" % code


def stop_process(proc, grace=STOP_GRACE_SECONDS):
    """Close stdin, then SIGTERM, then SIGKILL; always reap. Returns the exit code."""
    if proc is None:
        return None
    try:
        if proc.stdin is not None and not proc.stdin.closed:
            proc.stdin.close()
    except OSError:
        pass
    for step in ("wait", "terminate", "kill"):
        if step == "terminate":
            try:
                proc.terminate()
            except OSError:
                pass
        elif step == "kill":
            try:
                proc.kill()
            except OSError:
                pass
            return proc.wait()
        try:
            return proc.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            continue
    return proc.wait()
