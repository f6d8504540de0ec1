"""Text from files made safe to show on a terminal: :func:`shown`, the one way a name, a
metadata value or a message that holds text read from a file reaches stdout or stderr.

A terminal obeys what it prints: ``ESC ] 0 ; ... BEL`` sets its title, ``ESC [ 2 J`` clears
the screen, ``U+009B`` (CSI) starts the same sequences in one character, and the
bidirectional controls (``U+202E`` RIGHT-TO-LEFT OVERRIDE, the isolates ``U+2066..2069``, the
marks ``U+200E``, ``U+200F``, ``U+061C``) reorder what is shown, so that a file name reads as
another. :func:`shown` writes every character Python does not call printable (C0 controls,
DEL, C1 controls, format characters, line and paragraph separators, surrogates, private-use
and unassigned code points) as its escape (``\\x1b``, ``\\u202e``), so the text stays one
visible line and the terminal receives no control.
"""

from __future__ import annotations

__all__ = ["shown"]


def _escaped(text: str) -> str:
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def shown(text, *, lines: bool = False) -> str:
    """``text`` (``str()`` of any value) with every unprintable character written as its
    Python escape: what a terminal may show of text read from a file.

    Parameters
    ----------
    text : object
        A name, a value or a message; ``str(text)`` is escaped.
    lines : bool
        Keep the line breaks (``\\n``) of a multi-line text a command prints (a table),
        escaping each line; by default a line break is escaped too (one line).

    Returns
    -------
    str
        Printable characters and spaces only (and ``\\n`` with ``lines``); unchanged when
        ``text`` held nothing else.

    Examples
    --------
    >>> shown("velvet")
    'velvet'
    >>> print(shown("\\x1b]0;pwned\\x07\\x1b[2J"))
    \\x1b]0;pwned\\x07\\x1b[2J
    >>> print(shown("gpj.\\u202eexe"), shown("a\\x9b2Jb"), shown("two\\nlines"))
    gpj.\\u202eexe a\\x9b2Jb two\\nlines
    >>> print(shown("r\\tg\\nb\\x1b", lines=True))
    r\\tg
    b\\x1b
    """
    text = str(text)
    if lines:
        return "\n".join(_escaped(line) for line in text.split("\n"))
    return _escaped(text)
