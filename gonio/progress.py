"""The one progress bar of microcyl: tqdm on stderr, or a silent stand-in."""

from __future__ import annotations

import contextlib
import sys
import threading
import warnings

with warnings.catch_warnings():    # a notebook without ipywidgets: text bars, without a warning
    warnings.filterwarnings("ignore", message="IProgress not found")
    import tqdm.auto

from gonio.terminal import shown

__all__ = ["progress_bar", "interactive", "progress_line", "LineStream", "PIPE_INTERVAL",
           "heartbeat"]


def interactive(stream=None) -> bool:
    """Whether a bar redrawn in place (carriage returns) reads well on ``stream`` (default
    stderr): a terminal, or a notebook's widget; False for a pipe or a file, where a
    long job writes :func:`progress_line` instead.

    Examples
    --------
    >>> import io
    >>> interactive(io.StringIO())
    False
    """
    stream = sys.stderr if stream is None else stream
    try:
        if stream.isatty():
            return True
    except (AttributeError, ValueError):       # no isatty, or a closed stream
        return False
    # a notebook: tqdm.auto then draws a widget, not text
    return stream is sys.stderr and any(c.__module__ == "tqdm.notebook"
                                        for c in tqdm.auto.tqdm.__mro__)


def progress_line(text: str, stream=None) -> None:
    """One line of progress on ``stream`` (default stderr), flushed: what a job writes to
    a pipe or a log file instead of a bar (escaped by :func:`gonio.terminal.shown`)."""
    stream = sys.stderr if stream is None else stream
    print(shown(text), file=stream, flush=True)


#: Seconds between two lines of a bar on a pipe or a file (:class:`LineStream`).
PIPE_INTERVAL = 10.0


class LineStream:
    """What a bar writes to a pipe or a file: each redraw one line, the redraws that only
    clear the line dropped (tqdm redraws in place with carriage returns, which a log shows
    as one ever longer line).

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> s = LineStream(out)
    >>> s.write("\\rdemo:  50%|#####     | 1/2"); s.write("\\r" + " " * 30 + "\\r")
    >>> out.getvalue()
    'demo:  50%|#####     | 1/2\\n'
    """

    def __init__(self, stream):
        self.stream = stream

    def write(self, text: str) -> None:
        line = text.replace("\r", "").rstrip()
        if line:
            self.stream.write(line + "\n")

    def flush(self) -> None:
        self.stream.flush()


def progress_bar(total: int | None, *, desc: str, unit: str, enabled: bool = True,
                 initial: int = 0):
    """A tqdm bar (``tqdm.auto``: a widget in notebooks) on stderr that vanishes when closed;
    on a pipe or a file (not :func:`interactive`) one line at the start, one every
    :data:`PIPE_INTERVAL` seconds and one at the end (:class:`LineStream`), each whole: no
    width is given to tqdm, which then cuts nothing (a log has no columns to fit).

    Parameters
    ----------
    total : int or None
        Units of work (None while unknown: no ETA is shown).
    desc, unit : str
        Label and unit name (escaped by :func:`gonio.terminal.shown`: a name read from a
        file reaches the terminal as text, never as a control).
    enabled : bool
        False gives tqdm's disabled bar: the same methods (``update``, ``set_postfix``,
        ``set_description``, ``close``, use as a context manager), drawing nothing.
    initial : int
        Units already done (a resumed job).

    Examples
    --------
    >>> with progress_bar(3, desc="demo", unit="item", enabled=False) as bar:
    ...     bar.update(3)
    """
    desc, unit = shown(desc), shown(unit)
    # looked up on each call (not bound at import), so a patched tqdm.auto.tqdm is used
    if enabled and not interactive():
        return tqdm.auto.tqdm(total=total, initial=initial, desc=desc, unit=unit, leave=True,
                              file=LineStream(sys.stderr), mininterval=PIPE_INTERVAL)
    return tqdm.auto.tqdm(total=total, initial=initial, desc=desc, unit=unit, leave=False,
                          file=sys.stderr, disable=not enabled)


@contextlib.contextmanager
def heartbeat(bar, note: str, interval: float | None = None):
    """Redraw ``bar`` every ``interval`` seconds (default :data:`PIPE_INTERVAL` on a pipe or
    a file, 1 s on a terminal) with ``note`` as its postfix while the block runs: a long
    call that updates nothing (Mitsuba compiling its kernel in the first pass) still
    writes a line every 10 s on a pipe, its elapsed time in it. Nothing for a disabled bar.

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> bar = tqdm.auto.tqdm(total=1, desc="demo", file=LineStream(out), mininterval=10)
    >>> import time
    >>> with heartbeat(bar, "compiling", interval=0.05):
    ...     time.sleep(0.18)
    >>> bar.close()
    >>> sum("compiling" in s for s in out.getvalue().splitlines()) >= 2
    True
    """
    if getattr(bar, "disable", False):
        yield
        return
    if interval is None:
        interval = PIPE_INTERVAL if not interactive() else 1.0
    stop = threading.Event()
    bar.set_postfix_str(shown(note), refresh=False)

    def beat():
        while not stop.wait(interval):
            bar.refresh()
    thread = threading.Thread(target=beat, name="microcyl-heartbeat", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        bar.set_postfix_str("", refresh=False)
