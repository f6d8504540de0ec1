"""The one progress bar of microcyl: tqdm on stderr, or a silent stand-in."""

from __future__ import annotations

import sys

import tqdm.auto

__all__ = ["progress_bar", "interactive", "progress_line"]


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
    a pipe or a log file instead of a bar."""
    stream = sys.stderr if stream is None else stream
    print(text, file=stream, flush=True)


def progress_bar(total: int | None, *, desc: str, unit: str, enabled: bool = True,
                 initial: int = 0):
    """A tqdm bar (``tqdm.auto``: a widget in notebooks) on stderr that vanishes when closed.

    Parameters
    ----------
    total : int or None
        Units of work (None while unknown: no ETA is shown).
    desc, unit : str
        Label and unit name.
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
    # looked up on each call (not bound at import), so a patched tqdm.auto.tqdm is used
    return tqdm.auto.tqdm(total=total, initial=initial, desc=desc, unit=unit, leave=False,
                          file=sys.stderr, disable=not enabled)
