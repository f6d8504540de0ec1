"""The ``microcyl compare`` verb: rank fits of one table by PSIS-LOO.

``microcyl compare DIR DIR... [--json]``

Each DIR is the output folder of ``microcyl fit`` (or one table's folder of a fit-batch). The
work is :func:`analysis.fit.compare.compare_fits` (``arviz.compare`` on the pointwise elpd in
each folder's ``loo.npz``); this module parses the arguments and prints.
"""

from __future__ import annotations

import json
import logging

from analysis.fit.compare import FIT_KEYS, compare_fits, difference_in_se
from analysis.fit.loo import HIGH_K
from gonio.jsonplain import plain
from gonio.terminal import shown

__all__ = ["register", "run", "format_table"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``compare`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "compare", help="rank fits of one table by PSIS-LOO elpd (arviz.compare)",
        description="Rank two or more fits of the same table (other models, presets, "
                    "variants, free sets or likelihoods) by their expected log predictive density under "
                    "leave-one-out cross-validation (PSIS-LOO, stored by `microcyl fit` in "
                    "DIR/loo.npz), with the difference to the best fit (d_elpd: the best's "
                    "elpd minus each fit's) and its standard error (d_se, from the paired "
                    "pointwise values). Fits of different tables are refused.")
    p.add_argument("fits", nargs="+", metavar="DIR", help="output folders of `microcyl fit`")
    p.add_argument("--json", action="store_true",
                   help="print a JSON list, best first, of {fit, model, elpd, se, d_elpd, "
                        "d_se}")
    p.set_defaults(func=run)


def format_table(rows: list[dict]) -> str:
    """The ranking as a text table, then one line per fit behind the best (names and the
    table's digest, read from the fits' files, through :func:`gonio.terminal.shown`).

    Examples
    --------
    >>> rows = [{"fit": "a", "model": "microcylinder", "elpd": 10.0, "se": 2.0, "d_elpd": 0.0, "d_se": 0.0,
    ...          "p_loo": 2.1, "weight": 1.0, "n_high_k": 0, "pareto_k_max": 0.2,
    ...          "converged": True, "values": 30, "table": "ab12"},
    ...         {"fit": "b", "model": "lambert", "elpd": 4.0, "se": 2.5, "d_elpd": 6.0, "d_se": 1.5,
    ...          "p_loo": 2.0, "weight": 0.0, "n_high_k": 1, "pareto_k_max": 0.8,
    ...          "converged": False, "values": 30, "table": "ab12"}]
    >>> print(format_table(rows))  # doctest: +NORMALIZE_WHITESPACE
    rank fit model         elpd   se d_elpd d_se p_loo k>0.7 converged
       1 a   microcylinder 10.0  2.0    0.0  0.0   2.1     0       yes
       2 b   lambert        4.0  2.5    6.0  1.5   2.0     1        no
    30 values of table ab12; d_elpd: the best fit's elpd minus each fit's, d_se its standard error
    b (lambert): behind a (microcylinder) by 6.0 ± 1.5 (4.0 standard errors)
    """
    head = ["rank", "fit", "model", "elpd", "se", "d_elpd", "d_se", "p_loo", f"k>{HIGH_K}",
            "converged"]
    body = [[str(i + 1), shown(r["fit"]), shown(r["model"]), f"{r['elpd']:.1f}", f"{r['se']:.1f}",
             f"{r['d_elpd']:.1f}", f"{r['d_se']:.1f}", f"{r['p_loo']:.1f}",
             str(r["n_high_k"]),
             {True: "yes", False: "no", None: "-"}[r["converged"]]] for i, r in enumerate(rows)]
    width = [max(len(x[c]) for x in [head] + body) for c in range(len(head))]
    lines = [" ".join(x[c].ljust(width[c]) if c in (1, 2) else x[c].rjust(width[c])
                      for c in range(len(head))).rstrip() for x in [head] + body]
    best = rows[0]
    lines.append(f"{best['values']} values of table {shown(best['table'])}; d_elpd: the best fit's "
                 f"elpd minus each fit's, d_se its standard error")
    for r in rows[1:]:
        n_se = difference_in_se(r)
        lines.append(f"{shown(r['fit'])} ({shown(r['model'])}): behind {shown(best['fit'])} "
                     f"({shown(best['model'])}) by "
                     f"{r['d_elpd']:.1f} ± "
                     f"{r['d_se']:.1f} ({n_se:.1f} standard errors)")
    return "\n".join(lines)


def run(args) -> int:
    """Compare the fits; print the table (or JSON); warn of unreliable elpd on stderr."""
    rows = compare_fits(args.fits)
    for r in rows:
        if r["n_high_k"]:
            log.warning(f"compare: {r['fit']}: {r['n_high_k']} of {r['values']} values have "
                        f"Pareto k > {HIGH_K} (largest {r['pareto_k_max']:.2f}): its elpd is "
                        f"unreliable")
        if r["converged"] is False:
            log.warning(f"compare: {r['fit']}: the fit did not converge; its elpd is that of "
                        f"its chains as they are")
    if args.json:
        print(json.dumps(plain([{k: r[k] for k in FIT_KEYS} for r in rows],
                               nonfinite="null"), indent=1))
    else:
        print(format_table(rows))
    return 0
