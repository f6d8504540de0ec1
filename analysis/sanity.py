"""Sanity scan: finite, non-negative f_r at the edges of the domain.

A BRDF is evaluated on direction sets built to hit its edge cases (grazing angles, phi_d
near pi, retro and mirror pairs, directions along the threads and their tangents, below the
horizon), and, for a fabric, on parameter sets at the edges of their ranges (tangent offsets
of +-90 degrees, tiny gamma, k_d = 0 and 1, eta close to 1, areas summing to 1 or near 0).
A value that is NaN, infinite or negative is a violation, and so is a RuntimeWarning raised
during the evaluation (a division by zero or an invalid operation the model let through).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any

import numpy as np

from brdf.fabric import Fabric
from brdf.frames import from_angles, to_angles
from brdf.presets import check_preset
from brdf.presets import fabric as preset_fabric
from brdf.protocols import BRDF

__all__ = ["SanityResult", "sanity_scan", "edge_pairs"]

_EPS_DEG = (1e-9, 1e-6, 1e-3, 0.1)


@dataclasses.dataclass(frozen=True, eq=False)
class SanityResult:
    """What the sanity scan evaluated and every violation found.

    Attributes
    ----------
    checks : list of dict
        One per (parameter set, direction set): ``params`` (name), ``directions`` (name),
        ``n`` evaluations, ``n_nonfinite``, ``n_negative``, ``warnings`` (messages) and
        ``examples`` (up to ``n_examples`` offending inputs: theta_i, phi_i, theta_o, phi_o
        in degrees, the RGB value).
    ok : bool
        True when no check found a violation.
    """

    checks: list
    ok: bool

    @property
    def violations(self) -> list:
        """The checks that found something."""
        return [c for c in self.checks
                if c["n_nonfinite"] or c["n_negative"] or c["warnings"]]

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return {"ok": self.ok, "checks": self.checks}


def _dirs(theta_deg, phi_deg):
    return from_angles(np.radians(theta_deg), np.radians(phi_deg))


def edge_pairs(offsets_deg=(-90.0, -45.0, 0.0, 45.0, 90.0)) -> dict[str, tuple]:
    """Direction pairs at the edges of the domain, by name.

    Parameters
    ----------
    offsets_deg : sequence of float
        Tangent offsets (degrees) whose tangent directions t = cos(a) t0 + sin(a) n are
        included for both threads (t0 = +x and +y).

    Returns
    -------
    dict
        name -> (wi, wo), each (n, 3) unit vectors.

    Examples
    --------
    >>> sets = edge_pairs()
    >>> sorted(sets)[:3]
    ['along_tangent_i', 'along_tangent_o', 'below_horizon']
    """
    out = {}
    grazing = np.array([89.0, 89.9, 89.99, 89.999, 90.0 - 1e-7, 90.0])
    phis = np.arange(0.0, 360.0, 15.0)
    inner = np.array([0.0, 30.0, 60.0, 85.0])
    G, P, Ti, Pi = np.meshgrid(grazing, phis, inner, phis[::2], indexing="ij")
    a, b = _dirs(G.ravel(), P.ravel()), _dirs(Ti.ravel(), Pi.ravel())
    out["grazing_i"] = (a, b)
    out["grazing_o"] = (b, a)
    G1, P1, G2, P2 = np.meshgrid(grazing, phis, grazing, phis[::3], indexing="ij")
    out["both_grazing"] = (_dirs(G1.ravel(), P1.ravel()), _dirs(G2.ravel(), P2.ravel()))
    # phi_d near pi: opposite azimuths, offsets down to 1e-9 degrees, both signs
    th = np.array([0.0, 1e-6, 10.0, 45.0, 80.0, 89.9])
    d = np.concatenate([[0.0], _EPS_DEG, -np.asarray(_EPS_DEG)])
    T1, T2, PH, D = np.meshgrid(th, th, phis, d, indexing="ij")
    out["phi_d_near_pi"] = (_dirs(T1.ravel(), PH.ravel()),
                            _dirs(T2.ravel(), PH.ravel() + 180.0 + D.ravel()))
    # retro (wi = wo), mirror, and the normal
    T, P = np.meshgrid(np.r_[0.0, 1e-8, np.arange(5.0, 90.0, 5.0), 89.999, 90.0], phis,
                       indexing="ij")
    w = _dirs(T.ravel(), P.ravel())
    out["retro"] = (w, w.copy())
    out["mirror"] = (w, w * np.array([-1.0, -1.0, 1.0]))
    # tangent directions of sampled offsets, and their opposites, against many partners
    tans = []
    for a_ in np.radians(np.asarray(offsets_deg, float)):
        for t0 in (np.array([1.0, 0, 0]), np.array([0, 1.0, 0])):
            for sgn in (1.0, -1.0):
                t = sgn * (math.cos(a_) * t0 + math.sin(a_) * np.array([0, 0, 1.0]))
                tans.append(t)
    tans = np.array(tans)
    tans = tans[tans[:, 2] >= -1e-12]
    tans[:, 2] = np.maximum(tans[:, 2], 0.0)
    partners = _dirs(*[x.ravel() for x in np.meshgrid(np.r_[0.0, 30.0, 60.0, 89.9, 90.0], phis,
                                                        indexing="ij")])
    A, B = np.repeat(tans, len(partners), axis=0), np.tile(partners, (len(tans), 1))
    out["along_tangent_i"] = (A, B)
    out["along_tangent_o"] = (B, A)
    out["tangent_pairs"] = (np.repeat(tans, len(tans), axis=0), np.tile(tans, (len(tans), 1)))
    # below the horizon: must give 0
    below = _dirs(np.array([90.0 + 1e-9, 91.0, 135.0, 180.0]), np.array([0.0, 45.0, 90.0, 200.0]))
    up = _dirs(np.array([0.0, 45.0, 80.0, 89.0]), np.array([10.0, 100.0, 190.0, 280.0]))
    out["below_horizon"] = (np.concatenate([below, up, below]),
                            np.concatenate([up, below, below]))
    for k, (wi, wo) in out.items():
        out[k] = (wi / np.linalg.norm(wi, axis=-1, keepdims=True),
                  wo / np.linalg.norm(wo, axis=-1, keepdims=True))
    return out


def _angles(w):
    th, ph = to_angles(w)
    return np.degrees(th), np.degrees(ph) % 360.0


def _check(brdf, pname, dname, wi, wo, n_examples, below=False):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            f = np.asarray(brdf.eval(wi, wo), dtype=np.float64)
        except Exception as exc:  # noqa: BLE001 - an exception is a finding, reported
            return {"params": pname, "directions": dname, "n": int(wi.shape[0]),
                    "n_nonfinite": int(wi.shape[0]), "n_negative": 0,
                    "warnings": [f"{type(exc).__name__}: {exc}"], "examples": []}
    msgs = sorted({f"{w.category.__name__}: {w.message}" for w in caught
                   if issubclass(w.category, RuntimeWarning)})
    nonfinite = ~np.all(np.isfinite(f), axis=-1)
    negative = np.any(f < 0, axis=-1) & ~nonfinite
    bad = nonfinite | negative
    if below:
        zi, zo = wi[:, 2] <= 0, wo[:, 2] <= 0
        nonzero_below = (zi | zo) & np.any(f != 0, axis=-1) & ~bad
        bad = bad | nonzero_below
    else:
        nonzero_below = np.zeros(wi.shape[0], bool)
    examples = []
    for j in np.flatnonzero(bad)[:n_examples]:
        ti, pi_ = _angles(wi[j])
        to, po = _angles(wo[j])
        examples.append({"theta_i": float(ti), "phi_i": float(pi_), "theta_o": float(to),
                         "phi_o": float(po), "wi": wi[j].tolist(), "wo": wo[j].tolist(),
                         "value": [None if not math.isfinite(x) else float(x) for x in f[j]]})
    return {"params": pname, "directions": dname, "n": int(wi.shape[0]),
            "n_nonfinite": int(nonfinite.sum()), "n_negative": int(negative.sum()),
            "n_nonzero_below_horizon": int(nonzero_below.sum()), "warnings": msgs,
            "examples": examples}


def _parameter_sets(fabric) -> dict[str, Any]:
    """Fabrics at the edges of the parameter ranges, by name."""
    t1, t2 = fabric.threads
    sets = {"as_given": fabric}

    def both(**kw):
        return fabric.replace(threads=(t1.replace(**kw), t2.replace(**kw)))

    cands = {
        "offsets_-90_90": lambda: both(offsets=(-90.0, 90.0), lengths=(1.0,)),
        "offsets_+90": lambda: both(offsets=(90.0, 90.0), lengths=(1.0,)),
        "offsets_-90": lambda: both(offsets=(-90.0, -90.0), lengths=(1.0,)),
        "offsets_jump_-90_+90": lambda: both(offsets=(-90.0, -90.0, 90.0, 90.0),
                                             lengths=(1.0, 0.0, 1.0)),
        "gamma_0.1deg": lambda: both(gamma_s=0.1, gamma_v=0.1),
        "gamma_0.01deg": lambda: both(gamma_s=0.01, gamma_v=0.02),
        "gamma_0.1deg_offsets_0": lambda: both(gamma_s=0.1, gamma_v=0.2, offsets=(0.0, 0.0),
                                               lengths=(1.0,)),
        "kd_0": lambda: both(kd=0.0),
        "kd_1": lambda: both(kd=1.0),
        "eta_1.000001": lambda: both(eta=1.000001),
        "eta_10": lambda: both(eta=10.0),
        "areas_sum_1": lambda: fabric.replace(threads=(t1.replace(area=0.5),
                                                       t2.replace(area=0.5))),
        "areas_0": lambda: both(area=0.0),
        "area_1_0": lambda: fabric.replace(threads=(t1.replace(area=1.0),
                                                    t2.replace(area=0.0))),
        "albedo_0": lambda: both(albedo=(0.0, 0.0, 0.0)),
    }
    for name, make in cands.items():
        try:
            sets[name] = make()
        except ValueError as exc:  # the model refuses the set: worth saying, not a failure
            sets[name] = exc
    if isinstance(fabric, Fabric):
        for opt, val in (("masking", False), ("reweighting", False),
                         ("transmission", "longitudinal"), ("gap", "outgoing"),
                         ("tangent_sampling", "control_points")):
            try:
                sets[f"{opt}={val}"] = fabric.replace(**{opt: val})
            except (ValueError, TypeError) as exc:
                sets[f"{opt}={val}"] = exc
    return sets


def sanity_scan(obj, *, parameters: bool | None = None, n_examples: int = 3) -> SanityResult:
    """Evaluate a BRDF (and, for a fabric, edge parameter sets) at the domain's edges.

    Parameters
    ----------
    obj : object or str
        A BRDF with ``eval(wi, wo)``, a :class:`brdf.Fabric`, or a
        preset name.
    parameters : bool, optional
        Also scan edge parameter sets (default: True for fabrics).
    n_examples : int, default 3
        Offending inputs kept per check.

    Returns
    -------
    SanityResult

    Raises
    ------
    ValueError
        For an object without ``eval`` or an unknown preset name.

    Examples
    --------
    >>> import numpy as np
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         up = (np.asarray(wi)[..., 2] > 0) & (np.asarray(wo)[..., 2] > 0)
    ...         return np.where(up[..., None], np.full(3, 0.3 / np.pi), 0.0)
    >>> sanity_scan(Lambert()).ok
    True
    """
    if isinstance(obj, str):
        obj = preset_fabric(check_preset(obj))
    if not isinstance(obj, BRDF):
        raise ValueError(f"need a BRDF with eval(wi, wo); got {type(obj).__name__}")
    parameters = isinstance(obj, Fabric) if parameters is None else bool(parameters)
    sets = _parameter_sets(obj) if parameters else {"as_given": obj}
    pairs = edge_pairs()
    checks = []
    for pname, brdf_ in sets.items():
        if isinstance(brdf_, Exception):
            checks.append({"params": pname, "directions": None, "n": 0, "n_nonfinite": 0,
                           "n_negative": 0, "n_nonzero_below_horizon": 0, "warnings": [],
                           "examples": [], "refused": str(brdf_)})
            continue
        for dname, (wi, wo) in pairs.items():
            checks.append(_check(brdf_, pname, dname, wi, wo, n_examples,
                                 below=(dname == "below_horizon")))
    ok = not any(c["n_nonfinite"] or c["n_negative"] or c["warnings"]
                 or c.get("n_nonzero_below_horizon") for c in checks)
    return SanityResult(checks=checks, ok=bool(ok))
