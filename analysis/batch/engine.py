"""The batch on Dask: :func:`run_batch` submits one task per table and gathers the rows.

By default a ``distributed.LocalCluster`` of one worker process per core, one thread each
(and Dr.Jit's kernels on cores / workers threads each: :func:`brdf.jit.share_cores`);
with ``scheduler`` the batch runs on an existing cluster (``dask scheduler`` and ``dask
worker ADDRESS``). Dask reschedules the task of a worker that dies, and the fit resumes from
the checkpoint in its folder; a task whose workers die three times (Dask's
``allowed-failures``) becomes an error row. Only this client writes the summaries.
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import logging
import math
import os
import signal
import time
import uuid
from pathlib import Path
from typing import Callable

from analysis.batch.jobs import BatchJob
from analysis.batch.summary import BatchSummary, check_not_batch_file
from analysis.batch.worker import error_row, estimate_job, run_job
from analysis.budget import format_seconds
from analysis.folderlock import output_lock
from brdf import jit
from gonio.progress import progress_bar
from gonio.safenames import check_component
from gonio.terminal import shown

_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3      # glibc's mallopt parameters

__all__ = ["run_batch", "BatchInterrupted", "describe_row", "estimate_batch"]


class BatchInterrupted(KeyboardInterrupt):
    """Ctrl-C during a batch, after the summaries were written; ``str()`` says how to resume."""


@contextlib.contextmanager
def _quiet_dask():
    """Dask's own log (comm timeouts under load, the noise of closing a cluster on Ctrl-C)
    held back to CRITICAL for the batch: the batch reports its tables' errors itself."""
    log = logging.getLogger("distributed")
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        log.setLevel(level)


def _distributed():
    """The ``distributed`` module, imported on first use (the one place it is imported)."""
    # distributed is imported on use: it takes most of a second, and every `microcyl` verb
    # imports this package (for the batch page).
    import distributed
    return distributed


@contextlib.contextmanager
def _client(workers: int | None, scheduler: str | None):
    """A Dask client: of a new LocalCluster, or connected to ``scheduler``."""
    if scheduler is not None:
        try:
            client = _distributed().Client(scheduler, timeout="20s")
        except OSError as exc:
            raise OSError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
        try:
            client.run(steady_allocator)
            _share_cores(client)
            yield client
        finally:
            client.close()
        return
    with _environment_kept(), _local_client(workers or os.cpu_count() or 1) as client:
        yield client


@contextlib.contextmanager
def _environment_kept():
    """This process's environment as it was, once the local cluster has closed: Dask's
    nanny sets its workers' variables (``OMP_NUM_THREADS=1``, ``MALLOC_TRIM_THRESHOLD_``,
    ``PYTHONHASHSEED`` ...) in the parent's own ``os.environ`` before it starts each one,
    and leaves them there for every process the caller starts afterwards."""
    before = dict(os.environ)
    try:
        yield
    finally:
        for key in set(os.environ) - set(before):
            del os.environ[key]
        for key, value in before.items():
            if os.environ.get(key) != value:
                os.environ[key] = value


@contextlib.contextmanager
def _local_client(n: int):
    """A client of a new LocalCluster of ``n`` worker processes."""
    Client, LocalCluster = _distributed().Client, _distributed().LocalCluster
    try:
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.ERROR)
    except KeyboardInterrupt:
        # Ctrl-C while the cluster starts: its worker processes are daemons and end with
        # this process, but distributed's own close at exit would fail on a worker still
        # starting, and asyncio would report the abandoned start (tracebacks after the one
        # line of the interrupt)
        atexit.unregister(_distributed().deploy.spec.close_clusters)
        logging.getLogger("asyncio").setLevel(logging.CRITICAL)
        raise
    try:
        with Client(cluster) as client:
            client.run(_ignore_sigint)
            client.run(steady_allocator)
            client.run(jit.share_cores, n)
            yield client
    finally:
        cluster.close()


def _share_cores(client) -> None:
    """Each worker of a scheduler caps Dr.Jit's threads at its host's cores over the workers
    on that host (:func:`brdf.jit.share_cores`): a worker runs one fit at a time, and N
    workers each with a pool of every core would run N x cores threads."""
    hosts: dict[str, list[str]] = {}
    for addr, info in client.scheduler_info()["workers"].items():
        hosts.setdefault(info.get("host", addr), []).append(addr)
    for addrs in hosts.values():
        client.run(jit.share_cores, len(addrs), workers=addrs)


def steady_allocator() -> bool:
    """Run in each worker: fixed glibc malloc thresholds (mmap 32 MiB, trim 256 MiB).

    Dask's nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which turns off
    glibc's adaptive thresholds: every temporary over 128 KiB is then mapped and unmapped
    afresh (a felt fit took 33 million page faults, a quarter of its CPU in the kernel).
    Returns whether the allocator took the settings (False off glibc)."""
    try:
        libc = ctypes.CDLL("libc.so.6")
        return bool(libc.mallopt(_M_MMAP_THRESHOLD, 32 << 20)
                    and libc.mallopt(_M_TRIM_THRESHOLD, 256 << 20))
    except (OSError, AttributeError):
        return False


def _ignore_sigint():
    """Run in each local worker process: Ctrl-C reaches the whole process group, and the
    client, not the workers, handles it (the workers are closed with the cluster)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def describe_row(row: dict) -> str:
    """One line for a finished table: converged or not, at which step, in what time, and
    whether the model is adequate and how many warnings the fit has, through
    :func:`gonio.terminal.shown` (its name and error may quote the table's file).

    Examples
    --------
    >>> describe_row({"name": "velvet", "status": "not_converged", "steps": 60,
    ...               "wall_s": 4.2, "adequate": False, "warnings": "at_bound gamma_v1; misfit"})
    'velvet: NOT converged at step 60 (4 s); NOT ADEQUATE, 2 warnings'
    >>> print(describe_row({"name": "x", "status": "error", "error": "bad \\x1b[2J"}))
    x: error: bad \\x1b[2J
    """
    if row["status"] == "error":
        return shown(f"{row['name']}: error: {row['error']}")
    verdict = "converged" if row["status"] == "converged" else "NOT converged"
    resumed = (f"; resumed from step {row['resumed_from']}" if row.get("resumed_from")
               else "")
    kinds = [w for w in str(row.get("warnings") or "").split("; ") if w]
    adequacy = {True: "; adequate", False: "; NOT ADEQUATE"}.get(row.get("adequate"), "")
    warned = f", {len(kinds)} warning{'s' * (len(kinds) != 1)}" if kinds else ""
    return shown(f"{row['name']}: {verdict} at step {row['steps']} ({row['wall_s']:.0f} s)"
                 f"{adequacy}{warned}{resumed}")


def estimate_batch(todo: list[BatchJob], workers: int | None = None,
                   scheduler: str | None = None) -> str | None:
    """One line: the estimated time of a batch, before it starts.

    The fit of the first job whose table can be read is timed
    (:func:`~analysis.batch.worker.estimate_job`: its steps and point estimate, at most
    ``max_steps`` steps; at most ``time_limit`` when the job has one), and the batch takes
    ``ceil(tables / workers)`` times that on a local cluster of ``workers`` processes
    (default the cores); on a ``scheduler``, ``tables`` times it, shared by its workers.

    Parameters
    ----------
    todo : list of BatchJob
        The jobs to fit (not those already converged).
    workers : int, optional
        Worker processes of the local cluster (default: the cores).
    scheduler : str, optional
        The address of an existing scheduler (its workers unknown here).

    Returns
    -------
    str or None
        The line; None when there is nothing to fit or no table of ``todo`` can be read
        (each such table's error is then the batch's to report).
    """
    for job in todo:
        try:
            per, _ = estimate_job(job)
        except Exception:               # noqa: BLE001 - the batch reports this table's error
            continue
        break
    else:
        return None
    limit = job.fit.get("time_limit")
    capped = limit is not None and limit < per
    per = min(per, limit) if capped else per
    n = len(todo)
    head = (f"fit-batch: {n} table{'s' * (n != 1)} to fit, up to {format_seconds(per)} each "
            f"(estimated on {job.name}{', --time-limit' if capped else ''})")
    if scheduler is not None:
        return (f"{head}: up to {format_seconds(n * per)} of fitting in all, shared by the "
                f"workers of {scheduler} (convergence usually stops a fit sooner)")
    w = min(workers or os.cpu_count() or 1, n)
    return (f"{head}, so up to {format_seconds(math.ceil(n / w) * per)} on {w} "
            f"worker{'s' * (w != 1)} (convergence usually stops a fit sooner)")


def run_batch(jobs: list[BatchJob], out_dir, *, workers: int | None = None,
              scheduler: str | None = None, progress: bool = True,
              echo: Callable[[str], None] | None = print,
              notify: Callable[[str], None] | None = None,
              locked: bool = False,
              page: Callable[[Path], object] | None = None) -> BatchSummary:
    """Fit every job on Dask into ``out_dir/<name>``, keeping the summaries up to date.

    Jobs that converged before with the same inputs (:meth:`BatchSummary.done`) are not
    submitted again; unfinished ones resume from their checkpoints.

    Parameters
    ----------
    jobs : list of BatchJob
        From :func:`~analysis.batch.jobs.jobs_from_inputs` (names unique).
    out_dir : path
        The batch's folder: ``summary.csv``, ``summary.json`` and one folder per table.
    workers : int, optional
        Worker processes of the local cluster (default: the cores).
    scheduler : str, optional
        Address of an existing Dask scheduler (e.g. ``tcp://127.0.0.1:8786``) instead.
    progress : bool
        One bar over the tables (stderr).
    echo : callable, optional
        Receives one line per table as it ends (None: silent).
    notify : callable, optional
        Receives the batch's estimated time (:func:`estimate_batch`) before it starts.
    locked : bool
        The caller holds ``out_dir``'s lock already (:func:`analysis.fit_measured`, which
        writes measured.json under the same lock); else the batch takes it.
    page : callable, optional
        ``page(out_dir)`` writes the batch's page once the summaries are written (for
        example ``reports.report_batch.write_batch_page``), under the same lock.

    Returns
    -------
    BatchSummary

    Raises
    ------
    BatchInterrupted
        On Ctrl-C, after writing the summaries (every fit resumable from its checkpoint).
    ValueError
        Duplicate job names (case ignored), a name that is not a safe file name
        (:func:`gonio.safenames.check_component`) or is one of the batch's own files
        (:data:`analysis.batch.summary.BATCH_FILES`), or a bad ``workers``.
    FolderBusy
        Another run (batch, fit, report) holds ``out_dir``'s lock
        (:func:`analysis.folderlock.output_lock`).
    """
    names = [j.name for j in jobs]
    for n in names:                     # each names its folder: DIR/<name>
        check_component(n, source="run_batch", entry="job name")
        check_not_batch_file(n, "run_batch", "job name")
    if len(set(n.casefold() for n in names)) != len(names):
        raise ValueError("job names must be unique in a batch (case ignored)")
    if workers is not None and workers < 1:
        raise ValueError(f"workers must be >= 1; got {workers}")
    out = Path(os.path.abspath(out_dir))           # a link there is refused, not followed
    with contextlib.nullcontext() if locked else output_lock(out, "batch"):
        summary = BatchSummary(out)
        todo = [j for j in jobs if not summary.done(j)]
        line = estimate_batch(todo, workers, scheduler) if notify and todo else None
        if line is not None:
            notify(line)
        with progress_bar(len(jobs), desc="fits", unit="table", enabled=progress,
                          initial=len(jobs) - len(todo)) as bar:
            say = (bar.write if progress else echo) if echo is not None else None
            if todo:
                with _quiet_dask(), _client(workers, scheduler) as client:
                    _gather(client, todo, out, summary, names, bar, say)
            summary.write(names)
        if page is not None:
            page(out)
    return summary


def _record(fut, job, summary, names, bar, say):
    """The row of one finished future into the summaries (written at once)."""
    try:
        row = fut.result()
    except Exception as exc:            # noqa: BLE001 - e.g. KilledWorker: record, go on
        row = error_row(job, exc)
    row["key"] = job.key()
    summary.update(row)
    summary.write(names)
    bar.update(1)
    if say is not None:
        say(describe_row(row))


def _gather(client, todo, out, summary, names, bar, say):
    """Submit ``todo`` and record each row as its fit ends."""
    as_completed = _distributed().as_completed
    run = uuid.uuid4().hex[:8]
    futures = {client.submit(run_job, job, str(out), key=f"microcyl-fit-{job.name}-{run}",
                             pure=False): job for job in todo}
    ready = as_completed(futures)
    try:
        while ready.count():
            # Polled, not blocked on: Ctrl-C then lands in this loop, not inside Dask's wait.
            for fut in ready.next_batch(block=False):
                _record(fut, futures[fut], summary, names, bar, say)
            time.sleep(0.1)
    except KeyboardInterrupt:
        for fut in futures:
            fut.cancel()
        summary.write(names)
        done = sum(1 for n in names if n in summary.rows)
        raise BatchInterrupted(f"interrupted with {done} of {len(names)} tables done; the "
                               f"same command resumes the rest from their checkpoints in "
                               f"{out}") from None
