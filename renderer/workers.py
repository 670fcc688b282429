"""Worker processes that render tiles beside the calling thread.

Why processes: numpy releases the GIL inside each array operation, but a tile
of a 256^2 frame is a few thousand operations of 10 to 30 microseconds, and
each one takes the GIL back.  Two threads then spend much of their time
handing the GIL to each other.  The calling thread and a worker process, each
with its own interpreter, do not: at 256^2 the threads-only frame takes 1.10
(exact) and 1.20 (central) times as long as with one worker process, in the
same run (benchmarks/results/render.md, "Steady state"; at 1024^2, where
tiles are larger and threads contend less, 0.98 and 1.05: about even).

How: a worker is a child interpreter (``python -m renderer._worker``, started
with `subprocess` in a session of its own, so no ``__main__`` module is
imported again, nothing is forked from a threaded process, and a Ctrl-C at the
terminal reaches only the parent).  It shares with its parent one memory file of
`SLOTS` slots, each holding the outputs of one tile (image, gradient, chamber
and kink flag of at most ``tile_pixels`` pixels), and a socket for small
pickled messages: the parent sends (job id, slot, scene, pipeline, frame size,
rows); the worker renders those rows with the same code the parent runs
(`renderer.render._render_tile`) into the slot and answers (job id, None), or
(job id, traceback text) if it raised.  The parent copies the slot into the
frame.  Each pixel is computed by the same operations on the same numbers in
either process, so the image is the same bits (tests/test_workers.py).

When: `render` uses workers for frames that it splits into tiles, with
``workers`` >= 2.  A process that renders once never starts one; the second
such render starts ``workers - 1`` of them in the background (importing
numpy, sympy and the renderer takes about a second), and until they report
ready the tiles render on threads as before.  The ε sweep (`renderer.sweep`)
stays on threads.

Failure: if a worker answers with an error, dies, or its socket breaks, the
parent renders that tile itself (so a genuine error in the tile is raised
where the caller can see it) and stops using workers for the rest of the
process, with one `RuntimeWarning`.  A worker exits when its parent's end of
the socket closes, including when the parent dies.  A render interrupted
midway (KeyboardInterrupt) leaves stale answers behind; they carry old job
ids and are dropped.

Set the environment variable ``SYMRENDER_WORKER_PROCESSES=0`` to render on
threads only.  Workers need a POSIX system (they are not started elsewhere).
"""

from __future__ import annotations

import atexit
import mmap
import os
import pickle
import socket
import subprocess
import sys
import tempfile
import threading
import time
import traceback
import warnings
from multiprocessing.connection import Connection, wait

import numpy as np

__all__ = ["ENV_VAR", "SLOTS", "START_AFTER", "run_tiles", "wait_ready", "shutdown", "stats"]

#: Environment variable: "0" renders on threads only.
ENV_VAR = "SYMRENDER_WORKER_PROCESSES"
#: Tiles a worker can hold at once: one it renders and one queued behind it.
SLOTS = 2
#: Bytes per pixel in a slot: image (3 float64), gradient (2 float64),
#: chamber (uint8), kink flag (bool).
PIXEL_BYTES = 24 + 16 + 1 + 1
#: The render (of a frame split into tiles) that starts the workers: the
#: second, so that a process that renders once does not pay for them.
START_AFTER = 2
#: Most worker processes at once: one per core besides the caller's.
MAX_WORKERS = max(0, (os.cpu_count() or 1) - 1)
#: Seconds a worker may take to start before it is given up.
START_TIMEOUT = 120.0

_lock = threading.Lock()
_state = {"workers": [], "calls": 0, "disabled": None, "job": 0, "tiles": 0, "fallbacks": 0}


def _slot_views(buf, slot, tile_pixels, n):
    """(image (n, 3), grad (n, 2), chamber (n,), kink (n,)) views of a slot."""
    base = slot * tile_pixels * PIXEL_BYTES
    image = np.frombuffer(buf, np.float64, n * 3, base).reshape(n, 3)
    grad = np.frombuffer(buf, np.float64, n * 2, base + tile_pixels * 24).reshape(n, 2)
    chamber = np.frombuffer(buf, np.uint8, n, base + tile_pixels * 40)
    kink = np.frombuffer(buf, np.bool_, n, base + tile_pixels * 41)
    return image, grad, chamber, kink


class _Worker:
    """The parent's handle on one worker process."""

    def __init__(self, tile_pixels):
        self.tile_pixels = tile_pixels
        size = SLOTS * tile_pixels * PIXEL_BYTES
        if hasattr(os, "memfd_create"):
            fd = os.memfd_create("symrender-tiles")
        else:
            fd = os.dup(tempfile.TemporaryFile().fileno())
        try:
            os.ftruncate(fd, size)
            self.buf = mmap.mmap(fd, size)
            ours, theirs = socket.socketpair()
            package_root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
            env = dict(os.environ)
            env["PYTHONPATH"] = os.pathsep.join([package_root] + [p for p in [env.get("PYTHONPATH")] if p])
            with theirs:
                self.proc = subprocess.Popen(
                    [sys.executable, "-m", "renderer._worker", str(theirs.fileno()), str(fd),
                     str(tile_pixels)],
                    pass_fds=(theirs.fileno(), fd), stdin=subprocess.DEVNULL,
                    stdout=subprocess.DEVNULL, env=env, cwd=package_root, start_new_session=True)
        finally:
            os.close(fd)
        self.conn = Connection(ours.detach())
        self.ready = False
        self.started = time.monotonic()

    def check_ready(self, timeout=0.0):
        """True once the worker has said it is ready (waits up to ``timeout`` s)."""
        if not self.ready and self.conn.poll(timeout):
            msg = self.conn.recv()
            if msg != ("ready",):
                raise RuntimeError(f"unexpected first message from a render worker: {msg!r}")
            self.ready = True
        if not self.ready and time.monotonic() - self.started > START_TIMEOUT:
            raise RuntimeError(f"a render worker did not start within {START_TIMEOUT:g} s")
        return self.ready

    def close(self):
        """Close the socket: a ready worker then exits; one still starting is killed."""
        try:
            self.conn.close()
        finally:
            if not self.ready:
                self.proc.kill()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def _disable(reason):
    """Stop using workers for the rest of the process (warn once)."""
    if _state["disabled"] is None:
        _state["disabled"] = reason
        warnings.warn(f"render worker processes are off for this process ({reason}); "
                      "tiles render on threads", RuntimeWarning, stacklevel=4)
    workers, _state["workers"] = _state["workers"], []
    for w in workers:
        try:
            w.close()
        except Exception:                      # noqa: BLE001 - already giving up on it
            pass


def _enabled():
    return (os.environ.get(ENV_VAR, "1").strip() != "0" and os.name == "posix"
            and bool(sys.executable) and _state["disabled"] is None)


def _ready_workers(count, tile_pixels, start):
    """Up to ``count`` ready workers; starts the missing ones when ``start``."""
    workers = _state["workers"]
    if start:
        try:
            while len(workers) < count:
                workers.append(_Worker(tile_pixels))
        except OSError as exc:
            _disable(f"could not start one: {exc}")
            return []
    try:
        return [w for w in workers[:count] if w.tile_pixels == tile_pixels and w.check_ready()]
    except (OSError, EOFError, RuntimeError) as exc:
        _disable(f"one failed to start: {exc}")
        return []


def wait_ready(count=None, timeout=60.0):
    """Start ``count`` workers if needed and wait until they are ready.

    For tests and benchmarks, which want the steady state at once.  ``count``
    defaults to ``renderer.render.WORKERS - 1`` (what a default `render`
    uses).  Returns the number ready (0 when workers are off, see `ENV_VAR`).
    """
    from .render import TILE_PIXELS, WORKERS
    count = min(MAX_WORKERS, WORKERS - 1 if count is None else count)
    tile_pixels = TILE_PIXELS
    with _lock:
        if not _enabled():
            return 0
        _state["calls"] = max(_state["calls"], START_AFTER)
        _ready_workers(count, tile_pixels, True)
        deadline = time.monotonic() + timeout
        try:
            for w in _state["workers"][:count]:
                w.check_ready(max(0.0, deadline - time.monotonic()))
        except (OSError, EOFError, RuntimeError) as exc:
            _disable(f"one failed to start: {exc}")
            return 0
        return sum(w.ready for w in _state["workers"][:count])


def shutdown():
    """Stop the workers and start afresh: later renders start new ones as
    from a new process (also after a failure turned them off)."""
    with _lock:
        workers, _state["workers"] = _state["workers"], []
        _state["calls"] = 0
        _state["disabled"] = None
        for w in workers:
            w.close()


def stats():
    """Counters: tiles rendered by workers, tiles taken back after a failure,
    the reason workers are off (None while they are on), live workers."""
    return {"tiles": _state["tiles"], "fallbacks": _state["fallbacks"],
            "disabled": _state["disabled"], "workers": len(_state["workers"])}


def run_tiles(bounds, local, job, outputs, width, count, tile_pixels):
    """Render the tiles ``bounds`` on this thread and on up to ``count`` workers.

    Parameters
    ----------
    bounds : list of (j0, j1) row ranges, each at most ``tile_pixels`` pixels
    local : callable(j0, j1) rendering rows j0:j1 of the frame on this thread
    job : tuple (scene, gradient, width, height, zoom, kink, grad, skip)
        what a worker needs to render any rows of the same frame
    outputs : (image (n, 3), chamber (n,), kink (n,) or None, grad (n, 2) or None)
        the frame's flat output arrays
    width : int, pixels per row
    count : int, workers wanted (``workers - 1`` of `render`; at most
        `MAX_WORKERS` are used)

    Returns
    -------
    bool
        False, having rendered nothing, when no worker is ready (workers are
        off, not started yet, or starting): the caller renders on threads.

    Raises
    ------
    Whatever ``local`` raises, also for a tile a failed worker gave back
    (a worker's own failure is a `RuntimeWarning`, not an error).
    """
    if not _lock.acquire(blocking=False):
        return False                           # another thread's render holds the workers
    try:
        count = min(count, MAX_WORKERS)
        if count < 1 or not _enabled():
            return False
        _state["calls"] += 1
        workers = _ready_workers(count, tile_pixels, _state["calls"] >= START_AFTER)
        if not workers:
            return False
        _run(workers, bounds, local, job, outputs, width)
        return True
    finally:
        _lock.release()


def _run(workers, bounds, local, job, outputs, width):
    pending = list(range(len(bounds)))         # the caller takes from the front, workers from the back
    outstanding = {}                           # job id -> (worker, slot, tile index)
    free = [(w, s) for s in range(SLOTS) for w in workers]

    def feed():
        while free and len(pending) > 1:
            w, slot = free.pop(0)
            k = pending.pop()
            _state["job"] += 1
            j0, j1 = bounds[k]
            try:
                w.conn.send((_state["job"], slot, job, j0, j1))
            except OSError as exc:
                pending.append(k)
                raise _Broken(exc) from exc
            outstanding[_state["job"]] = (w, slot, k)

    def collect(block):
        # Copy out every finished tile (with ``block``, until none is left
        # out) and give the freed slots new tiles.
        by_conn = {w.conn: w for w in workers}
        while outstanding:
            ready = wait(list({w.conn for w, _, _ in outstanding.values()}), None if block else 0)
            if not ready:
                return
            for conn in ready:
                w = by_conn[conn]
                try:
                    job_id, error = conn.recv()
                except (OSError, EOFError) as exc:
                    raise _Broken(exc) from exc
                if job_id not in outstanding:
                    continue                   # an answer to an interrupted render
                w, slot, k = outstanding.pop(job_id)
                if error is not None:
                    pending.append(k)
                    raise _Broken(error)
                _copy_out(w, slot, bounds[k], outputs, width)
                _state["tiles"] += 1
                free.append((w, slot))
            feed()

    try:
        feed()
        while pending:
            j0, j1 = bounds[pending.pop(0)]
            local(j0, j1)
            collect(False)
            feed()
        collect(True)
    except _Broken as broken:
        # Take back every tile a worker still holds and render it here.
        for w, slot, k in outstanding.values():
            pending.append(k)
        _state["fallbacks"] += len(pending)
        _disable(f"a worker failed: {broken.reason}")
        for k in sorted(pending):
            local(*bounds[k])


class _Broken(Exception):
    """A worker failed; ``reason`` is the last line of its error."""

    def __init__(self, reason):
        super().__init__(str(reason))
        self.reason = str(reason).strip().splitlines()[-1] if str(reason).strip() else repr(reason)


def _copy_out(worker, slot, bounds, outputs, width):
    j0, j1 = bounds
    n = (j1 - j0) * width
    image, grad, chamber, kink = _slot_views(worker.buf, slot, worker.tile_pixels, n)
    sl = slice(j0 * width, j1 * width)
    out_image, out_chamber, out_kink, out_grad = outputs
    out_image[sl] = image
    out_chamber[sl] = chamber
    if out_kink is not None:
        out_kink[sl] = kink
    if out_grad is not None:
        out_grad[sl] = grad


def _serve(sock_fd, mem_fd, tile_pixels):
    """The worker's loop (runs in the child process)."""
    from .geometry import image_plane
    from .heap import keep_heap
    from .render import _render_tile, render
    from .scene import Scene

    conn = Connection(sock_fd)
    buf = mmap.mmap(mem_fd, SLOTS * tile_pixels * PIXEL_BYTES)
    os.close(mem_fd)
    keep_heap()
    for gradient in ("exact", "central"):      # build the default field's functions now
        render(Scene(), 8, 8, gradient=gradient, workers=1)
    try:
        conn.send(("ready",))
    except OSError:
        return                                 # the parent has gone while we started
    while True:
        try:
            job_id, slot, job, j0, j1 = conn.recv()
        except (EOFError, OSError):
            return                             # the parent has gone
        try:
            scene, gradient, width, height, zoom, want_kink, want_grad, skip = job
            n = (j1 - j0) * width
            if n > tile_pixels:
                raise ValueError(f"a tile of {n} pixels does not fit a slot of {tile_pixels}")
            x, y = image_plane(scene.radius_a, scene.camera_z, width, height, zoom)
            image, grad, chamber, kink = _slot_views(buf, slot, tile_pixels, n)
            # The frame's arrays start as zeros, and a tile writes only the
            # pixels that show an object (and grad and kink only on sphere A).
            image[:] = 0.0
            grad[:] = 0.0
            kink[:] = False
            X = np.tile(x, j1 - j0)
            Y = np.repeat(y[j0:j1], width)
            _render_tile(scene, gradient, X, Y, image, chamber, kink if want_kink else None,
                         grad if want_grad else None, skip, (x, y[j0:j1]))
            answer = (job_id, None)
        except Exception:                      # noqa: BLE001 - reported to the parent
            answer = (job_id, traceback.format_exc())
        try:
            conn.send(answer)
        except (OSError, pickle.PicklingError):
            return


atexit.register(shutdown)
