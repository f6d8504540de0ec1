"""Errors raised by the gonio readers, and the warning of a table that reads but looks wrong."""

from __future__ import annotations

import os

from gonio.terminal import shown

__all__ = ["FormatError", "TableWarning"]


class FormatError(ValueError):
    """A file is truncated, corrupt or not in the format its name says.

    The message names the file and what is wrong (wrong magic, wrong size, missing channel,
    bad CSV row with its line number). Readers raise it before returning anything: a table
    is never returned partially read.

    Parameters
    ----------
    path : str or os.PathLike
        The offending file.
    problem : str
        What is wrong with it. The message (file name and problem, which may quote the
        file: a column name, a metadata key) is one line through
        :func:`gonio.terminal.shown`: what the file holds reaches a terminal escaped.

    Examples
    --------
    >>> err = FormatError("t.csv", "line 3: expected 7 columns, got 5")
    >>> str(err)
    't.csv: line 3: expected 7 columns, got 5'
    >>> isinstance(err, ValueError), err.path
    (True, 't.csv')
    >>> print(FormatError("t.csv", "line 1: unknown column(s) \\x1b[2J"))
    t.csv: line 1: unknown column(s) \\x1b[2J
    """

    def __init__(self, path, problem: str):
        self.path = os.fspath(path)
        self.problem = problem
        super().__init__(shown(f"{self.path}: {problem}"))


class TableWarning(UserWarning):
    """A table that reads but looks wrong (angles in radians where degrees are meant).

    The message names the file and what looks wrong, on one line; ``microcyl`` prints it as
    ``microcyl VERB: warning: MESSAGE``.
    """
