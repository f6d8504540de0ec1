"""The ``microcyl compare`` verb: rank fits of one table by PSIS-LOO.

``microcyl compare DIR DIR... [--json]``

Each DIR is the output folder of ``microcyl fit`` (or one table's folder of a fit-batch). The
work is :func:`analysis.fit.compare.compare_fits` (``arviz.compare`` on the pointwise elpd in
each folder's ``loo.npz``); this module parses the arguments and prints.
"""

from __future__ import annotations

import json
import logging

from analysis.fit.compare import FIT_KEYS, compare_fits
from gonio.jsonplain import plain
from gonio.terminal import shown
from reports.fitwords import gap_sentence

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
                   help="print a JSON list, best first, of {" + ", ".join(FIT_KEYS) + "}")
    p.set_defaults(func=run)


def format_table(rows: list[dict]) -> str:
    """The ranking as a text table (with each fit's adequacy), then the gap of each fit behind
    the best in the words of the measured page (:func:`reports.fitwords.gap_sentence`); names
    and the table's digest, read from the fits' files, through :func:`gonio.terminal.shown`.

    Examples
    --------
    >>> rows = [{"fit": "a", "model": "microcylinder", "elpd": 10.0, "se": 2.0, "d_elpd": 0.0,
    ...          "d_se": 0.0, "d_se_block": 0.0, "d_lag1": None, "p_loo": 2.1, "weight": 1.0,
    ...          "n_high_k": 0, "pareto_k_max": 0.2, "k_threshold": 0.62, "converged": True,
    ...          "adequate": False, "values": 30, "table": "ab12"},
    ...         {"fit": "b", "model": "lambert", "elpd": 4.0, "se": 2.5, "d_elpd": 6.0,
    ...          "d_se": 1.5, "d_se_block": 1.6, "d_lag1": 0.1, "p_loo": 2.0, "weight": 0.0,
    ...          "n_high_k": 1, "pareto_k_max": 0.8, "k_threshold": 0.62, "converged": False,
    ...          "adequate": None, "values": 30, "table": "ab12"}]
    >>> print(format_table(rows))  # doctest: +NORMALIZE_WHITESPACE
    rank fit model         elpd   se d_elpd d_se block_se p_loo high_k converged adequate
       1 a   microcylinder 10.0  2.0    0.0  0.0        -   2.1      0       yes       NO
       2 b   lambert        4.0  2.5    6.0  1.5      1.6   2.0      1        no        -
    30 values of table ab12; d_elpd: the best fit's elpd minus each fit's, d_se its standard error (values taken as independent), block_se one over runs of consecutive values; high_k: values with Pareto k above 0.62 (min(1 - 1/log10 S, 0.7) for S draws)
    a (microcylinder) is preferred over b (lambert) by 6.0 ± 1.5 (4.0 se; block se 1.6: 3.8 se)
    not adequate (the model does not describe the data to within its noise): a
    """
    head = ["rank", "fit", "model", "elpd", "se", "d_elpd", "d_se", "block_se", "p_loo",
            "high_k", "converged", "adequate"]
    yes = {True: "yes", False: "no", None: "-"}
    body = [[str(i + 1), shown(r["fit"]), shown(r["model"]), f"{r['elpd']:.1f}",
             f"{r['se']:.1f}",
             f"{r['d_elpd']:.1f}", f"{r['d_se']:.1f}",
             "-" if i == 0 or r.get("d_se_block") is None else f"{r['d_se_block']:.1f}",
             f"{r['p_loo']:.1f}", str(r["n_high_k"]), yes[r["converged"]],
             {True: "yes", False: "NO", None: "-"}[r.get("adequate")]]
            for i, r in enumerate(rows)]
    width = [max(len(x[c]) for x in [head] + body) for c in range(len(head))]
    lines = [" ".join(x[c].ljust(width[c]) if c in (1, 2) else x[c].rjust(width[c])
                      for c in range(len(head))).rstrip() for x in [head] + body]
    best = rows[0]
    ks = sorted({f"{r['k_threshold']:.2f}" for r in rows})
    lines.append(f"{best['values']} values of table {shown(best['table'])}; d_elpd: the best "
                 f"fit's "
                 f"elpd minus each fit's, d_se its standard error (values taken as "
                 f"independent), block_se one over runs of consecutive values; high_k: values "
                 f"with Pareto k above {' or '.join(ks)} (min(1 - 1/log10 S, 0.7) for S draws)")
    name = shown(f"{best['fit']} ({best['model']})")
    for r in rows[1:]:
        lines.append(gap_sentence(name, shown(f"{r['fit']} ({r['model']})"), r["d_elpd"],
                                  r["d_se"],
                                  block_se=r.get("d_se_block"), lag1=r.get("d_lag1")))
    bad = [shown(r["fit"]) for r in rows if r.get("adequate") is False]
    if bad:
        lines.append("not adequate (the model does not describe the data to within its "
                     "noise): " + ", ".join(bad))
    return "\n".join(lines)


def run(args) -> int:
    """Compare the fits; print the table (or JSON); warn of unreliable elpd on stderr."""
    rows = compare_fits(args.fits)
    for r in rows:
        if r["n_high_k"]:
            log.warning(f"compare: {r['fit']}: {r['n_high_k']} of {r['values']} values have "
                        f"Pareto k > {r['k_threshold']:.2f} (largest {r['pareto_k_max']:.2f}): its elpd is "
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
