"""The verdict of fits in words: one fit's adequacy and warnings (what ``microcyl fit`` and
``microcyl fit-measured`` print), and the gap between two fits' PSIS-LOO elpd (what
``microcyl compare`` prints and the measured page's models table says).

Every sentence is made from the numbers it cites. A gap of elpd within :data:`SEPARATION_SE`
standard errors does not separate two fits; one past it but within :data:`CLOSE_SE`, in the
naive se or in the block standard error (:func:`analysis.fit.compare.paired_structure`), is a
close call, and is worded so: the naive se treats the values
as independent, and the residuals of a model that misses a feature run in streaks.
"""

from __future__ import annotations

import math

from gonio.jsonplain import meta_text

__all__ = ["verdict_lines", "gap_sentence", "gap_in_se", "SEPARATION_SE", "CLOSE_SE"]

#: A difference of elpd within this many standard errors does not separate two fits.
SEPARATION_SE = 2.0
#: ... and one up to this many is a close call (Sivula et al. 2022: with model misfit the
#: normal approximation of the difference is unreliable near the threshold).
CLOSE_SE = 2.7

_VERDICT = {True: "ADEQUATE", False: "NOT ADEQUATE", None: "adequacy not checked"}


def verdict_lines(adequate, reason, warnings) -> list[str]:
    """A fit's adequacy verdict, then each warning, one line each (text from a file made
    one printable line by :func:`gonio.jsonplain.meta_text`).

    Parameters
    ----------
    adequate : bool or None
        ``results.json``'s ``adequate``.
    reason : str or None
        Its ``adequate_reason``.
    warnings : list of dict
        Its ``warnings`` (``kind``, ``message``).

    Examples
    --------
    >>> print("\\n".join(verdict_lines(False, "residuals differ between incidences",
    ...                               [{"kind": "at_bound", "message": "eta1 at 2.0"}])))
    NOT ADEQUATE: residuals differ between incidences
    warning (at_bound): eta1 at 2.0
    """
    verdict = _VERDICT.get(adequate if isinstance(adequate, bool) else None)
    lines = [f"{verdict}: {meta_text(reason or 'not checked')}"]
    lines += [f"warning ({meta_text(w.get('kind', ''))}): {meta_text(w.get('message', ''))}"
              for w in warnings or [] if isinstance(w, dict)]
    return lines


def gap_in_se(d_elpd, d_se) -> float:
    """``d_elpd / d_se`` (inf for an exact nonzero difference, 0 for none).

    Examples
    --------
    >>> gap_in_se(6.0, 1.5), gap_in_se(2.0, 0.0), gap_in_se(0.0, 0.0)
    (4.0, inf, 0.0)
    """
    d, se = float(d_elpd or 0.0), float(d_se or 0.0)
    if se > 0:
        return d / se
    return math.inf if d > 0 else 0.0


def gap_sentence(best: str, other: str, d_elpd, d_se, *, block_se=None, lag1=None) -> str:
    """The gap from ``best`` to ``other`` in words (no final full stop).

    Parameters
    ----------
    best, other : str
        How the two fits are named.
    d_elpd, d_se : float
        The best's elpd minus the other's, and its (naive, paired) standard error.
    block_se : float, optional
        The block standard error of the difference (allows for correlated residuals).
    lag1 : float, optional
        The lag-1 autocorrelation of the pointwise differences along the table.

    Examples
    --------
    >>> gap_sentence("a", "b", 1.0, 2.0)
    'The data cannot separate a and b (difference 1.0 ± 2.0, within 2 se)'
    >>> gap_sentence("a", "b", 12.0, 3.0, block_se=3.3, lag1=0.05)
    'a is preferred over b by 12.0 ± 3.0 (4.0 se; block se 3.3: 3.6 se)'
    >>> print(gap_sentence("a", "b", 5.0, 2.0, block_se=4.0, lag1=0.6))
    a is ahead of b by 5.0 ± 2.0 (2.5 se), a close call: the pointwise differences are correlated along the table (lag-1 autocorrelation 0.60), and with a block se of 4.0 the gap is 1.2 se, within 2 se
    """
    d, se = float(d_elpd or 0.0), float(d_se or 0.0)
    z = gap_in_se(d, se)
    if z <= SEPARATION_SE:
        return (f"The data cannot separate {best} and {other} (difference {d:.1f} ± {se:.1f}, "
                f"within {SEPARATION_SE:g} se)")
    zb = None if block_se is None else gap_in_se(d, block_se)
    if z <= CLOSE_SE or (zb is not None and zb <= CLOSE_SE):
        text = f"{best} is ahead of {other} by {d:.1f} ± {se:.1f} ({z:.1f} se), a close call: "
        if zb is None:
            return text + "that se treats the values as independent, and residuals that run " \
                          "in streaks make it too small"
        corr = ("" if lag1 is None else
                f"the pointwise differences are {'' if lag1 > 0.1 else 'barely '}correlated "
                f"along the table (lag-1 autocorrelation {lag1:.2f}), and ")
        where = (f"within {SEPARATION_SE:g} se" if zb <= SEPARATION_SE else
                 f"past {SEPARATION_SE:g} se but within {CLOSE_SE:g}" if zb <= CLOSE_SE else
                 f"past {CLOSE_SE:g} se")
        return text + f"{corr}with a block se of {float(block_se):.1f} the gap is {zb:.1f} se, " \
                      f"{where}"
    text = f"{best} is preferred over {other} by {d:.1f} ± {se:.1f} ({z:.1f} se"
    if zb is not None:
        text += f"; block se {float(block_se):.1f}: {zb:.1f} se"
    return text + ")"
