r"""Two threads that can trade places: one mode, not two.

A fabric whose two threads have the same tangent curve, symmetric under a half turn
(``linen_plain``: (-25, 25) for both; :meth:`brdf.Fabric.thread_swap`), is unchanged when the
threads trade their parameters and the fabric turns by a quarter: ``area1`` = a at
``rotation`` r gives the same f_r as ``area1`` = 1 - a at r + 90 degrees when the threads'
other parameters are equal (to 2e-15 relative; ``tests/test_analysis_fit_swap.py``). A fit
that frees ``rotation`` and ``area1`` (with ``area2 = 1 - area1``) and ties or fixes every
other parameter of thread 2 to thread 1's then has two equal posterior modes, and which one a
fit reports depends on its start: two fits of one table could give area1 = 0.3 at -4 degrees
and 0.7 at 86 degrees, and an ensemble spread over both would never pass its convergence
checks.

:func:`fold_thread_swap` keeps one of them: ``area1`` on [0, 0.5] (thread 1 is the thread
with the smaller share of the surface, and ``rotation`` says where it runs). The two halves
are the same model, so nothing is lost, and 0.5 is a fold, not a limit: an interval that
reaches it is no ``at_bound`` (:attr:`analysis.params.ParamSpec.folds`). The spec says so in
its notes, which ``results.json`` carries.

Examples
--------
>>> import brdf
>>> from analysis.params import ParamSpec, defaults_from_fabric
>>> fab = brdf.fabric("linen_plain")
>>> spec = ParamSpec("eta1,kd1,area1,rotation", defaults=defaults_from_fabric(fab),
...                  ties="eta2=eta1,kd2=kd1,area2=1-area1", periods=fab.periods())
>>> folded = fold_thread_swap(spec, fab)
>>> folded.params["area1"].hi, folded.folds
(0.5, {'area1': 0.5})
>>> fold_thread_swap(spec.with_free(["gamma_s2"]), fab) is not None   # gamma_s2 differs
True
>>> fold_thread_swap(spec.with_free(["gamma_s2"]), fab).folds
{}
"""

from __future__ import annotations

from analysis.families import family_of
from analysis.params import ParamSpec

__all__ = ["fold_thread_swap", "with_symmetries", "AREA"]

#: The area shares of the two threads (``area2 = 1 - area1`` when they cover the surface).
AREA = ("area1", "area2")


def _partner(name: str) -> str | None:
    """Thread 2's name of thread 1's parameter ``name`` (``albedo1_r`` -> ``albedo2_r``)."""
    return name.replace("1", "2", 1) if name.count("1") == 1 else None


def _equal(spec: ParamSpec, a: str, b: str) -> bool:
    """Parameters ``a`` and ``b`` equal at every point of the fit: tied equal, or both fixed
    at one value."""
    if spec.ties.get(b) == (a, "equal") or spec.ties.get(a) == (b, "equal"):
        return True
    fixed = a not in spec.free and b not in spec.free and a not in spec.ties \
        and b not in spec.ties
    return fixed and spec.params[a].default == spec.params[b].default


def _free_area(spec: ParamSpec) -> str | None:
    """The free area share whose complement is the other (``area1`` with
    ``area2 = 1 - area1``), or None."""
    for a, b in (AREA, AREA[::-1]):
        if a in spec.free and spec.ties.get(b) == (a, "complement"):
            return a
    return None


def fold_thread_swap(spec: ParamSpec, fabric) -> ParamSpec:
    """``spec`` with its free area share kept to [0, 0.5] when the fabric's threads can trade
    places in this fit (see the module notes), else ``spec`` itself.

    Parameters
    ----------
    spec : ParamSpec
        The fit's spec, its periods set (:meth:`ParamSpec.with_periods`).
    fabric : brdf.Model
        The model fitted; only a fabric with :meth:`brdf.Fabric.thread_swap` can fold.

    Returns
    -------
    ParamSpec
        The folded copy (its start moved to the kept half when it lay in the other: the area
        share a -> 1 - a and the rotation turned by a quarter), or ``spec``.
    """
    swap = getattr(fabric, "thread_swap", None)
    turn = swap() if callable(swap) else None
    area = _free_area(spec)
    if turn is None or area is None or spec.period("rotation") is None \
            or "rotation" not in spec.free:
        return spec
    p = spec.params[area]
    family_bounds = spec.family.entry(area)[:2]
    if (p.lo, p.hi) != family_bounds or not p.lo < 0.5 < p.hi:
        return spec                       # the user's own bounds are kept as given
    pairs = [(n, _partner(n)) for n in spec.params if n not in AREA and _partner(n)]
    if not all(b in spec.params and _equal(spec, a, b) for a, b in pairs):
        return spec
    ps = spec.params.values()
    defaults = {q.name: q.default for q in ps}
    if defaults[area] > 0.5:              # the start moved into the kept half
        rot = spec.params["rotation"]
        r = defaults["rotation"] + turn
        defaults["rotation"] = r - spec.period("rotation") if r > rot.hi else r
        defaults[area] = 1.0 - defaults[area]
    own = {q.name: (q.lo, q.hi) for q in ps if (q.lo, q.hi) != spec.family.entry(q.name)[:2]}
    note = (f"{area} kept to [0, 0.5]: the fabric's two threads have the same tangent curve "
            f"and are tied, so {area} = a at rotation r and {area} = 1 - a at r + {turn:g} "
            f"degrees are the same fabric; thread {area[-1]} is the thread with the smaller "
            f"share, and rotation gives its direction")
    return ParamSpec(list(spec.free), defaults=defaults, bounds={**own, area: (p.lo, 0.5)},
                     priors={q.name: q.prior for q in ps}, ties=spec.ties,
                     family=spec.family, notes=(*spec.notes, note), periods=spec.periods,
                     folds={**spec.folds, area: 0.5})


def with_symmetries(spec: ParamSpec, model) -> ParamSpec:
    """``spec`` with what the model repeats applied: its periods (a fabric's ``rotation``,
    circular over one whole period, :meth:`ParamSpec.with_periods`), then the fold of two
    threads that trade places (:func:`fold_thread_swap`); the one way ``microcyl fit`` and
    ``fit-measured`` build a spec from a model.

    Examples
    --------
    >>> import brdf
    >>> spec = with_symmetries(ParamSpec("area1,rotation", ties="area2=1-area1"),
    ...                        brdf.fabric("linen_plain"))
    >>> spec.period("rotation"), spec.folds
    (180.0, {'area1': 0.5})
    """
    return fold_thread_swap(spec.with_periods(family_of(model).periods(model)), model)
