"""The one progress bar of microcyl: tqdm on stderr, or a silent stand-in."""

from __future__ import annotations

import sys

import tqdm.auto

__all__ = ["progress_bar"]


def progress_bar(total: int, *, desc: str, unit: str, enabled: bool = True, initial: int = 0):
    """A tqdm bar (``tqdm.auto``: a widget in notebooks) on stderr that vanishes when closed.

    Parameters
    ----------
    total : int
        Units of work.
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
