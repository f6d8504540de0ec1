"""The suite's ``python -m reports ...`` runs, forked from a process that has already imported
the toolkit, instead of each starting a new interpreter.

A CLI run of the suite spent about 0.7 s of CPU starting Python and importing numpy, scipy,
matplotlib and the toolkit before its first line of work, and a fit as much again importing
arviz, emcee and the plots: on the 2-core CI machine, over several hundred runs, minutes of
``make test``. Here each xdist worker keeps one *fork server*, a Python process that imports
those once and then forks a child for each run. The child is a process of its own as a user's
would be: its own pid, the argv, environment, working directory and standard streams (the
test's pipes or terminal) of the request, SIGINT as the test's ``subprocess`` call would give
it, its exit status or the signal that killed it; it runs ``reports.__main__`` as ``python -m
reports`` does (its children, the Dask workers among them, start the same way). What it does
not repeat is the interpreter's start and the imports: a test of what a verb *imports* must
start a real interpreter (``python -c``, or ``MICROCYL_TEST_SPAWN=1``).

The routing is in :class:`Popen`, which :func:`install` puts in place of
``subprocess.Popen`` for the suite (``subprocess.run`` uses it too). A call is forked only
when it is exactly ``[sys.executable, "-m", "reports", ...]``, its environment differs from
the server's only in variables read after start-up (:data:`LATE_ENV`), and it asks for
nothing a fork cannot give (``preexec_fn`` other than :func:`_signals.default_sigint`, user
or group changes, extra descriptors); every other call starts a real process, as does every
run of the suite with ``MICROCYL_TEST_SPAWN=1`` in its environment (tests/conftest.py then
leaves ``subprocess.Popen`` as it is). ``tests/test_forkcli.py``
holds forked and spawned runs of the same commands to the same output and status.
"""

from __future__ import annotations

import array
import atexit
import collections
import importlib
import io
import json
import os
import runpy
import select
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: What the server imports before it forks: what the verbs import between them (the fit's
#: sampler, diagnostics and plots, the reports, the batch engine's client side; not Dr.Jit
#: or Mitsuba, whose thread pools a fork would lose).
PRELOAD = (
    "numpy", "scipy.stats", "scipy.optimize", "scipy.special", "scipy.fft",
    "scipy.interpolate", "matplotlib", "matplotlib.pyplot", "matplotlib.figure",
    "emcee", "h5py", "tqdm", "jinja2", "distributed",
    "brdf", "gonio", "analysis", "analysis.fit", "analysis.batch", "analysis.planning",
    "reports", "reports.cli", *(m for m in (
        "reports.cli.model", "reports.cli.measure", "reports.cli.plan", "reports.cli.tables",
        "reports.cli.render", "reports.cli.physics", "reports.cli.fit", "reports.cli.compare",
        "reports.cli.measured", "reports.cli.batch", "reports.cli.plot", "reports.cli.export",
    )),
)

#: Variables that may differ between a request's environment and the server's: each is read
#: by the toolkit when it is used, never at import (``MICROCYL_*``: ``brdf.jit``'s backend,
#: the memory limit, the data folder; the terminal's width; stdio's buffering, which the
#: child sets up itself).
LATE_ENV = ("COLUMNS", "LINES", "PYTHONUNBUFFERED", "PYTEST_CURRENT_TEST", "TERM", "NO_COLOR",
            "SOURCE_DATE_EPOCH")


def _late(key: str) -> bool:
    return key in LATE_ENV or key.startswith("MICROCYL_")


# ---------------------------------------------------------------------------------------
# the server


def _preload() -> None:
    from analysis.fit.loo import import_arviz
    for name in PRELOAD:
        importlib.import_module(name)
    import_arviz()
    importlib.import_module("corner")        # after arviz, as the plots import it
    # A fork keeps only the forking thread: no Python thread may run here, and Dr.Jit (whose
    # thread pool a child would need) must not be loaded. OpenBLAS's pool is rebuilt in
    # the child by its own fork handlers, as under multiprocessing.
    if threading.active_count() != 1 or "drjit" in sys.modules:
        raise RuntimeError("fork server: a thread or Dr.Jit after the imports")


def serve(path: str) -> None:
    """Import :data:`PRELOAD`, then fork a child for each request on the Unix socket
    ``path`` until standard input closes (the worker that started it has gone)."""
    _preload()
    srv = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    srv.bind(path)
    srv.listen(64)
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)       # the waiters reap themselves
    sys.stdout.write("ready\n")
    sys.stdout.flush()
    while True:
        ready, _, _ = select.select([srv, sys.stdin], [], [])
        if sys.stdin in ready:                 # the worker has gone: so does its socket
            srv.close()
            os.unlink(path)
            os.rmdir(os.path.dirname(path))
            return
        conn, _ = srv.accept()
        try:
            request, fds = _receive(conn)
        except (OSError, ValueError):
            conn.close()
            continue
        if os.fork() == 0:
            srv.close()
            _wait_for(conn, request, fds)
        conn.close()
        for fd in fds:
            os.close(fd)


def _receive(conn: socket.socket) -> tuple[dict, list[int]]:
    fds = array.array("i")
    data, anc, _, _ = conn.recvmsg(1 << 20, socket.CMSG_SPACE(3 * fds.itemsize))
    for level, kind, payload in anc:
        if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
            fds.frombytes(payload[:len(payload) - len(payload) % fds.itemsize])
    try:
        if len(fds) != 3:
            raise ValueError("a request carries three descriptors")
        return json.loads(data.decode()), list(fds)
    except ValueError:                  # (json's errors are ValueErrors too)
        for fd in fds:
            os.close(fd)
        raise


def _wait_for(conn: socket.socket, request: dict, fds: list[int]) -> None:
    """In the waiter (a fork of the server): fork the run, send its pid, wait for it, send
    its wait status and CPU seconds (its own and its waited-for children's), exit."""
    signal.signal(signal.SIGCHLD, signal.SIG_DFL)
    pid = os.fork()
    if pid == 0:
        conn.close()
        _child(request, fds)
    for fd in fds:
        os.close(fd)
    try:
        conn.sendall(f"{pid}\n".encode())
        _, status, usage = os.wait4(pid, 0)
        conn.sendall(f"{status} {usage.ru_utime + usage.ru_stime}\n".encode())
    finally:
        os._exit(0)


def _stream(fd: int, write: bool, unbuffered: bool, encoding: str, errors: str):
    """A text stream on ``fd`` as the interpreter's start makes one."""
    if not write:
        return io.TextIOWrapper(io.open(fd, "rb", closefd=False), encoding=encoding,
                                errors=errors)
    raw = io.open(fd, "wb", buffering=0, closefd=False)
    tty = os.isatty(fd)
    return io.TextIOWrapper(raw if unbuffered else io.BufferedWriter(raw), encoding=encoding,
                            errors=errors, line_buffering=tty or fd == 2,
                            write_through=unbuffered)


def _child(request: dict, fds: list[int]) -> None:
    """The run: the request's streams, session, directory, environment, signals and argv,
    then ``reports.__main__`` as ``python -m reports`` runs it; exits with its status."""
    code = 1
    try:
        if request["new_session"]:
            os.setsid()
        for target, fd in enumerate(fds):
            if fd != target:
                os.dup2(fd, target)
        for fd in set(fds) - {0, 1, 2}:
            os.close(fd)
        if request["cwd"] is not None:
            os.chdir(request["cwd"])
        os.environ.clear()
        os.environ.update(request["env"])
        signal.signal(signal.SIGINT, signal.SIG_IGN if request["sigint_ignored"]
                      else signal.default_int_handler)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        unbuffered = bool(os.environ.get("PYTHONUNBUFFERED"))
        enc = sys.stdout.encoding
        sys.stdin = sys.__stdin__ = _stream(0, False, unbuffered, enc, "strict")
        sys.stdout = sys.__stdout__ = _stream(1, True, unbuffered, enc, "strict")
        sys.stderr = sys.__stderr__ = _stream(2, True, unbuffered, enc, "backslashreplace")
        sys.path[0] = os.getcwd()                      # as `-m` puts it
        sys.argv = [str(ROOT / "reports" / "__main__.py"), *request["args"]]
        import numpy as np
        np.random.seed()                               # the legacy global state, as a new process
        code = _run_main()
    except BaseException:                              # noqa: BLE001 - a child never returns
        traceback.print_exc()
    finally:
        os._exit(code)


def _run_main() -> int:
    """``reports.__main__`` under ``__main__``; the exit as the interpreter makes it."""
    code = 0
    try:
        runpy.run_module("reports", run_name="__main__", alter_sys=True)
    except SystemExit as exc:
        if exc.code is None:
            code = 0
        elif isinstance(exc.code, int):
            code = exc.code
        else:
            print(exc.code, file=sys.stderr)
            code = 1
    except KeyboardInterrupt:
        traceback.print_exc()
        _finish()
        signal.signal(signal.SIGINT, signal.SIG_DFL)    # dies by SIGINT, as Python does
        os.kill(os.getpid(), signal.SIGINT)
    except BaseException:                               # noqa: BLE001
        traceback.print_exc()
        code = 1
    _finish()
    return code


def _finish() -> None:
    """What the interpreter does at exit: join the non-daemon threads, run atexit, flush."""
    threading._shutdown()               # noqa: SLF001 - the interpreter's own exit step
    atexit._run_exitfuncs()             # noqa: SLF001
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass


# ---------------------------------------------------------------------------------------
# the client


class _Server:
    """This process's fork server, started on first use."""

    def __init__(self):
        self.proc = None
        self.path = None
        self.env = None
        self.broken = False
        self.lock = threading.Lock()

    def start(self) -> None:
        folder = tempfile.mkdtemp(prefix="microcyl-fork-")
        self.path = os.path.join(folder, "s")
        self.env = self._base(self._worker())
        self.proc = SPAWN([sys.executable, "-c", f"import sys; sys.path.insert(0, "
                            f"{str(Path(__file__).parent)!r}); import _forkcli; "
                            f"_forkcli.serve({self.path!r})"],
                           env=self.env, cwd=str(ROOT), stdin=subprocess.PIPE,
                           stdout=subprocess.PIPE, text=True)
        line = self.proc.stdout.readline()
        if line.strip() != "ready":
            self.proc.kill()
            self.proc = None
            raise RuntimeError("the fork server did not start")

    def stop(self) -> None:
        """End the server (its socket goes with it); the runs it forked go on to their end."""
        if self.proc is not None:
            self.proc.stdin.close()
            self.proc.stdout.close()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
            self.proc = None

    @staticmethod
    def _worker() -> dict:
        """The environment of this worker's runs: its own, importing this tree."""
        return dict(os.environ, PYTHONPATH=str(ROOT))

    @staticmethod
    def _base(env) -> dict | None:
        """``env`` without the late variables, or None if it imports another tree."""
        base = {k: v for k, v in env.items() if not _late(k)}
        if base.get("PYTHONPATH", str(ROOT)) != str(ROOT):
            return None
        base["PYTHONPATH"] = str(ROOT)
        return base

    def takes(self, env: dict) -> bool:
        """Whether a run with environment ``env`` is the same as one forked from here. When
        the worker's own environment has changed since the server started (a library
        imported by a test sets a variable, as OpenMP's builds set KMP_DUPLICATE_LIB_OK),
        a run in that environment gets a new server, so the suite's runs still fork."""
        base = self._base(env)
        if base is None:
            UNFORKED["PYTHONPATH"] += 1
            return False
        if base == self.env:
            return True
        if base != self._base(self._worker()):
            UNFORKED.update(k for k in base.keys() | self.env.keys()
                            if base.get(k) != self.env.get(k))
            return False
        with self.lock:
            self.stop()
            self.start()
        return True

    def running(self) -> None:
        """Start the server unless it runs."""
        with self.lock:
            if self.proc is None or self.proc.poll() is not None:
                self.start()

    def connect(self) -> socket.socket:
        self.running()
        conn = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        conn.connect(self.path)
        return conn


_SERVER = _Server()
#: CPU seconds of this process's forked runs that have ended (with their children's), for
#: ``bench/suite_cpu.py``: they are the server's children, not this process's.
CPU_OF_RUNS = 0.0
SPAWN = subprocess.Popen
#: ``python -m reports`` runs that started a new interpreter because their environment was
#: not the server's, by the variable that differed (``bench/suite_cpu.py`` reports them).
UNFORKED: collections.Counter = collections.Counter()


def _routed(args, executable, preexec_fn, pass_fds, shell, gid, gids, uid, umask,
            process_group, env) -> bool:
    from _signals import default_sigint
    if shell or executable is not None:
        return False
    if not isinstance(args, (list, tuple)) or len(args) < 3:
        return False
    if [str(a) for a in args[:3]] != [sys.executable, "-m", "reports"]:
        return False
    if preexec_fn not in (None, default_sigint) or pass_fds:
        return False
    if any(v is not None for v in (gid, gids, uid)) or umask >= 0 or process_group != -1:
        return False
    if _SERVER.broken:
        return False
    if _SERVER.env is None:
        try:
            _SERVER.running()
        except (OSError, RuntimeError):        # e.g. no Unix sockets here: start real ones
            _SERVER.broken = True
            return False
    try:
        return _SERVER.takes(dict(os.environ if env is None else env))
    except (OSError, RuntimeError):            # a new server could not start: so be it
        _SERVER.broken = True
        return False


def _line(conn: socket.socket) -> str:
    """One line from ``conn``, read a byte at a time (nothing of the next is consumed)."""
    out = bytearray()
    while (byte := conn.recv(1)) not in (b"", b"\n"):
        out += byte
    return out.decode().strip()


class Popen(subprocess.Popen):
    """``subprocess.Popen`` that forks ``python -m reports ...`` from the fork server (module
    notes) and starts everything else as usual."""

    _conn = None

    @property
    def forked(self) -> bool:
        """Whether this run was forked from the server (else it is a new process)."""
        return self._conn is not None

    def _execute_child(self, args, executable, preexec_fn, close_fds, pass_fds, cwd, env,
                       startupinfo, creationflags, shell, p2cread, p2cwrite, c2pread,
                       c2pwrite, errread, errwrite, restore_signals, gid, gids, uid, umask,
                       start_new_session, process_group):
        if not _routed(args, executable, preexec_fn, pass_fds, shell, gid, gids, uid, umask,
                       process_group, env):
            return super()._execute_child(
                args, executable, preexec_fn, close_fds, pass_fds, cwd, env, startupinfo,
                creationflags, shell, p2cread, p2cwrite, c2pread, c2pwrite, errread,
                errwrite, restore_signals, gid, gids, uid, umask, start_new_session,
                process_group)
        from _signals import default_sigint
        ignored = signal.getsignal(signal.SIGINT) == signal.SIG_IGN
        request = {"args": [os.fsdecode(a) if isinstance(a, bytes) else str(a)
                            for a in args[3:]],
                   "env": dict(os.environ if env is None else env),
                   "cwd": None if cwd is None else os.fsdecode(cwd),
                   "new_session": bool(start_new_session),
                   "sigint_ignored": ignored and preexec_fn is not default_sigint}
        fds = [p2cread if p2cread != -1 else 0, c2pwrite if c2pwrite != -1 else 1,
               errwrite if errwrite != -1 else 2]
        try:
            conn = _SERVER.connect()
            conn.sendmsg([json.dumps(request).encode()],
                          [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", fds))])
            self._conn = conn
            self.pid = int(_line(conn))
            self._child_created = True
        finally:
            self._close_pipe_fds(p2cread, p2cwrite, c2pread, c2pwrite, errread, errwrite)

    def _status(self, block: bool):
        """The run's wait status from its waiter, or None if it runs on (``block`` False)."""
        if not block and not select.select([self._conn], [], [], 0)[0]:
            return None
        global CPU_OF_RUNS
        line = _line(self._conn).split()
        self._conn.close()
        if not line:
            return 0
        CPU_OF_RUNS += float(line[1])
        return int(line[0])

    def _internal_poll(self, _deadstate=None, **_):
        if self._conn is None:
            return super()._internal_poll(_deadstate=_deadstate)
        if self.returncode is None and self._waitpid_lock.acquire(False):
            try:
                if self.returncode is None:
                    status = self._status(block=False)
                    if status is not None:
                        self._handle_exitstatus(status)
            finally:
                self._waitpid_lock.release()
        return self.returncode

    def _try_wait(self, wait_flags):
        if self._conn is None:
            return super()._try_wait(wait_flags)
        status = self._status(block=not wait_flags & os.WNOHANG)
        return (0, 0) if status is None else (self.pid, status)


def install() -> None:
    """Route the suite's ``python -m reports`` runs through the fork server (module notes)."""
    subprocess.Popen = Popen
    atexit.register(_SERVER.stop)
