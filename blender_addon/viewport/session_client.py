# SPDX-License-Identifier: MIT
"""A client of `tesela session` that never blocks its caller (Blender's UI thread).

Commands go into a queue that a writer thread drains into the session's stdin; a reader thread
parses the session's frames, keeps only the newest IMAGE and calls `on_change` (the engine's
tag_redraw) after each frame that changes what the viewport draws. No bpy."""

import atexit
import queue
import subprocess
import threading
import weakref

from .. import process
from . import session_protocol as sp

_LIVE = weakref.WeakSet()  # every client with a process, so quitting can end them all


def close_all():
    """End every live session (Blender quits, or loads another file)."""
    for client in list(_LIVE):
        client.close()


atexit.register(close_all)


class SessionClient:
    """One `tesela session` process and its two threads.

    State the UI thread reads (under `lock`): `image` (the newest sp.Image or None), `serial`
    (grows with every new image), `errors` (the ERROR frames not yet taken), `stats`
    (the last STATS object), `dead` (None while the session lives, else why it ended)."""

    def __init__(self, binary, *, threads=0, oidn_lib=None, cwd=None, on_change=None):
        self.args = [binary, "session"]
        if threads > 0:
            self.args += ["--threads", str(threads)]
        if oidn_lib:
            self.args += ["--oidn-lib", oidn_lib]
        self.cwd = cwd
        self.on_change = on_change
        self.lock = threading.Lock()
        self.image = None
        self.serial = 0
        self.errors = []
        self.stats = {}
        self.hello = None
        self.dead = None
        self.proc = None
        self.stderr = None
        self._queue = queue.Queue()
        self._writer = None
        self._reader = None
        self._next_id = 0
        self._closed = False

    # -- life ---------------------------------------------------------------------------------

    def start(self):
        """Start the process; raises OSError when it cannot be started."""
        self.proc = subprocess.Popen(self.args, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, bufsize=0, close_fds=True,
                                     cwd=self.cwd)
        _LIVE.add(self)
        self.stderr = process.StderrTail(self.proc.stderr)
        self._writer = threading.Thread(target=self._write_loop, name="tesela-session-writer",
                                        daemon=True)
        self._reader = threading.Thread(target=self._read_loop, name="tesela-session-reader",
                                        daemon=True)
        self._writer.start()
        self._reader.start()
        return self

    def alive(self):
        return self.proc is not None and not self._closed and self.dead is None

    def close(self):
        """End the process at once (stdin closed, then SIGTERM, SIGKILL) and join the threads.
        Idempotent; safe from any thread but the client's own."""
        if self._closed:
            return
        self._closed = True
        _LIVE.discard(self)
        self._queue.put(None)
        if self.proc is None:
            return
        process.stop_process(self.proc)
        for t in (self._writer, self._reader, self.stderr.thread if self.stderr else None):
            if t is not None and t is not threading.current_thread():
                t.join(timeout=2.0)
        for pipe in (self.proc.stdout, self.proc.stderr):
            try:
                pipe.close()
            except OSError:
                pass

    # -- commands -----------------------------------------------------------------------------

    def send(self, cmd, **fields):
        """Queue one command; returns its id (echoed by an ERROR frame that answers it)."""
        self._next_id += 1
        self._queue.put(sp.command_frame(cmd, id=self._next_id, **fields))
        return self._next_id

    def _write_loop(self):
        stdin = self.proc.stdin
        while True:
            data = self._queue.get()
            if data is None:
                return
            try:
                stdin.write(data)
            except (OSError, ValueError):  # the session is gone; the reader says why
                return

    # -- frames -------------------------------------------------------------------------------

    def take_errors(self):
        """The ERROR frames (session_protocol.Error) that arrived since the last call."""
        with self.lock:
            errors, self.errors = self.errors, []
        return errors

    def _changed(self):
        if self.on_change is not None:
            try:
                self.on_change()
            except (ReferenceError, RuntimeError):  # the engine was freed meanwhile
                pass

    def _read_loop(self):
        reader = sp.FrameReader(self.proc.stdout)
        why = None
        try:
            while True:
                msg = reader.read_message()
                if msg is None:
                    break
                if isinstance(msg, sp.Image):
                    with self.lock:
                        self.image = msg
                        self.serial += 1
                    self._changed()
                elif isinstance(msg, sp.Error):
                    with self.lock:
                        self.errors.append(msg)
                    if msg.fatal:
                        why = msg.text()
                    self._changed()
                elif isinstance(msg, sp.Stats):
                    with self.lock:
                        self.stats = msg.data
                elif isinstance(msg, sp.Hello):
                    self.hello = msg
        except sp.ProtocolError as exc:
            why = str(exc)
        except (OSError, ValueError) as exc:
            why = "pipe read failed: %s" % exc
        if self._closed:
            return
        try:
            code = self.proc.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            code = None
        if self.hello is None and why is None and code == 2:
            msg = ("the renderer %s has no 'session' subcommand (it is older than this add-on; "
                   "install the renderer that came with it)" % self.args[0])
        else:
            msg = "the renderer session ended (%s)" % process._describe_exit(code)
        if why:
            msg = "%s: %s" % (msg, why)
        tail = self.stderr.text(max_lines=3) if self.stderr is not None else ""
        if tail:
            msg += "; stderr: " + tail
        with self.lock:
            self.dead = msg
        self._changed()
