"""The workflow of ``microcyl plan``: a plan chosen and written as a pairs CSV.

The file is a plan file of :mod:`gonio.pairsfile` (``measure --geometry pairs:FILE`` reads
it): ``# key: value`` lines naming the fabric, the free parameters and the expected standard
deviation of each (in its unit), the budget, the instrument, the candidates, the draws, the
seed, the microcyl version and the date; then the pairs in measurement order (``index``,
the four angles in degrees) with their selection ``rank`` (1 the most informative: an
operator cut short measures by rank). The date is today's in UTC, or that of the
``SOURCE_DATE_EPOCH`` environment variable when it is set (reproducible builds' convention),
so the same options and seed on one day give the same bytes.
"""

from __future__ import annotations

import datetime
import json
import os
from pathlib import Path

from analysis.planning.core import Plan, plan
from gonio.measure import toolkit_version
from gonio.pairsfile import write_pairs_csv

__all__ = ["plan_file", "plan_header"]


def _date() -> str:
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    try:
        when = datetime.datetime.fromtimestamp(int(epoch), datetime.timezone.utc)
    except (TypeError, ValueError, OverflowError, OSError):
        when = datetime.datetime.now(datetime.timezone.utc)
    return when.date().isoformat()


def plan_header(p: Plan, ties=None) -> dict:
    """The ``# key: value`` lines of a plan file (module notes), in order."""
    sds = ", ".join(f"{n}={sd:.4g}{'' if u == '1' else ' ' + u}"
                    for n, u, sd in zip(p.free, p.units, p.natural_sd))
    uni = ", ".join(f"{n}={sd:.4g}" for n, sd in zip(p.free, p.uniform_natural_sd))
    uni3 = ", ".join(f"{n}={sd:.4g}" for n, sd in zip(p.free, p.uniform3_natural_sd))
    return {"fabric": p.fabric, "free": ",".join(p.free),
            "ties": ",".join(ties) if ties else "none",
            "expected_sd": sds,
            f"expected_sd_uniform_{p.budget}": uni,
            f"expected_sd_uniform_{3 * p.budget}": uni3,
            "budget": str(p.budget),
            "measured_before": str(p.n_measured),
            "instrument": json.dumps(p.instrument, sort_keys=True),
            "readings": "grey (one a pair)" if p.grey else "R, G, B (three a pair)",
            "candidates": f"{p.candidates} ({p.n_candidates} reachable pairs)",
            "criterion": "Bayesian D-optimality: expected log det of the posterior precision "
                         f"(Laplace approximation) over {p.draws} draws of the "
                         f"{'fit posterior' if p.source == 'posterior' else 'local prior'}",
            "seed": str(p.seed), "version": toolkit_version(), "date": _date()}


def plan_file(fabric, free, budget: int, out, *, instrument, ties=None, candidates=None,
              measured=None, draws: int | None = None, seed: int = 0, grey: bool = False,
              progress: bool = False) -> tuple[Plan, Path]:
    """Plan (:func:`analysis.planning.plan`) and write the plan file ``out``.

    Returns
    -------
    (Plan, pathlib.Path)
    """
    kw = {} if draws is None else {"draws": draws}
    p = plan(fabric, free, budget, instrument=instrument, candidates=candidates,
             measured=measured, seed=seed, ties=ties, grey=grey, progress=progress, **kw)
    path = write_pairs_csv(out, p.angles, header=plan_header(p, ties),
                           columns={"rank": p.rank}, order=False)
    return p, Path(path)
