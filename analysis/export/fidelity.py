r"""How closely an export follows its source: the numbers written beside every export.

- **Relative L2 error** of f_r cos(theta_i) cos(theta_o) over the stated grid
  (:class:`~analysis.export.grid.HemisphereGrid`), per channel and of the luminance
  (:func:`analysis.colour.luminance`):
  sqrt(sum w (t - s)^2 / sum w s^2), w the pairs' solid-angle weights.
- **Directional albedo** a(theta_i) = integral of f_r cos(theta_o) dwo of source and target at
  :data:`ALBEDO_INCIDENCES` (:func:`~analysis.export.grid.albedo_rule`).
- **CIEDE2000** (colour-science) of a flat patch lit by a directional light at
  :data:`LIGHT_THETA` (azimuth 0): its reflected radiance f_r cos(theta_i) E, relative to a
  white Lambertian patch's under the same light (so Y = 1 is that white), seen from each of
  :data:`VIEWS`; linear sRGB -> XYZ -> CIE Lab (D65), :func:`analysis.colour.albedo_delta_e`.
- **What the target cannot follow** (every target here is isotropic, reciprocal or not, with
  one sheen colour over one base colour):

  anisotropy: the azimuthal variation, the weighted rms over the grid of the luminance of
  f_r cos cos's deviation from its mean as the pair is turned about the normal (6 turns of 30
  degrees), relative to the rms of that mean; flagged where the source's exceeds the
  target's by more than :data:`LIMITS` ``anisotropy``.
  retroreflection: f_r (luminance) at wo = wi over a Lambertian's of the same directional
  albedo (a / pi), at theta = 60 degrees, source against target; flagged when they differ by
  more than :data:`LIMITS` ``retroreflection`` (relative).
  colour shift with angle: the weighted rms over the grid of the rg-chromaticity difference
  between target and source (what the target's one colour pair misses) beside the source's
  own spread; flagged above :data:`LIMITS` ``colour_shift``.

Examples
--------
>>> import brdf
>>> from analysis.export.grid import HemisphereGrid
>>> fab = brdf.fabric("velvet")
>>> fid = fidelity(fab, fab, HemisphereGrid(4, 8))                 # a source against itself
>>> fid["relative_l2"]["luminance"], max(fid["delta_e2000"]["per_view"].values())
(0.0, 0.0)
"""

from __future__ import annotations

import numpy as np

from analysis.colour import albedo_delta_e, luminance
from analysis.export.grid import DEFAULT_GRID, HemisphereGrid, albedo_rule

__all__ = ["fidelity", "summary_lines", "ALBEDO_INCIDENCES", "LIGHT_THETA", "VIEWS", "LIMITS"]

#: Incidences (degrees) of the directional albedos.
ALBEDO_INCIDENCES = (0.0, 30.0, 60.0, 80.0)
#: The light of the patch (degrees from the normal, azimuth 0).
LIGHT_THETA = 45.0
#: The patch's views: name -> (theta_o, phi_o) in degrees.
VIEWS = {"normal": (0.0, 0.0), "mirror_45": (45.0, 180.0), "back_45": (45.0, 0.0),
         "grazing_75": (75.0, 180.0), "side_60": (60.0, 90.0)}
#: Above these the target is said not to follow the source (module notes).
LIMITS = {"anisotropy": 0.05, "retroreflection": 0.25, "colour_shift": 0.01}
_CHANNELS = ("R", "G", "B")


def _dir(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])


def _rel_l2(t, s, w) -> float:
    den = float(np.sum(w * s * s))
    return float(np.sqrt(np.sum(w * (t - s) ** 2) / den)) if den > 0 else float("nan")


def _albedos(brdf_obj) -> dict:
    out = {}
    for th in ALBEDO_INCIDENCES:
        wi, wo, w = albedo_rule(th)
        a = w @ np.asarray(brdf_obj.eval(wi, wo))
        out[f"{th:g}"] = {"rgb": [float(v) for v in a], "luminance": float(luminance(a))}
    return out


def _delta_e(source, target) -> dict:
    wi = _dir(LIGHT_THETA, 0.0)
    white = np.cos(np.radians(LIGHT_THETA)) / np.pi
    out, rad = {}, {}
    for name, (t, p) in VIEWS.items():
        wo = _dir(t, p)
        ls = np.asarray(source.eval(wi[None], wo[None]))[0] * wi[2] / white
        lt = np.asarray(target.eval(wi[None], wo[None]))[0] * wi[2] / white
        out[name] = albedo_delta_e(ls, lt)
        rad[name] = {"source": [float(v) for v in ls], "target": [float(v) for v in lt]}
    return {"light_theta_deg": LIGHT_THETA, "views_deg": {k: list(v) for k, v in VIEWS.items()},
            "per_view": out, "max": max(out.values()), "relative_radiance": rad}


def _anisotropy(source, grid: HemisphereGrid) -> float:
    d, w = grid.wi, grid.weights
    turns = np.radians(np.arange(6) * 30.0)
    ys = []
    for a in turns:
        c, s = np.cos(a), np.sin(a)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        ys.append(luminance(source.eval(d @ rot.T, grid.wo @ rot.T))
                  * grid.wi[:, 2] * grid.wo[:, 2])
    ys = np.array(ys)
    mean = ys.mean(axis=0)
    den = float(np.sum(w * mean * mean))
    return float(np.sqrt(np.sum(w * ys.var(axis=0)) / den)) if den > 0 else 0.0


def _retro(obj, theta=60.0) -> float:
    """f_r's luminance at wo = wi over that of a Lambertian of the same directional albedo
    (a / pi), at incidence ``theta`` degrees."""
    wi = _dir(theta, 0.0)
    back = float(luminance(obj.eval(wi[None], wi[None]))[0])
    qi, qo, w = albedo_rule(theta)
    a = float(luminance(w @ np.asarray(obj.eval(qi, qo))))
    return back * np.pi / a if a > 0 else float("inf")


def _chroma(f):
    tot = f.sum(axis=-1, keepdims=True)
    return np.where(tot > 0, f / np.where(tot > 0, tot, 1.0), 1.0 / 3.0)[..., :2]


def fidelity(source, target, grid: HemisphereGrid = DEFAULT_GRID) -> dict:
    """The fidelity of ``target`` to ``source`` (module notes) as plain data.

    Parameters
    ----------
    source, target : objects with ``eval(wi, wo)`` -> RGB f_r (1/sr)
    grid : HemisphereGrid

    Returns
    -------
    dict
        ``grid``, ``relative_l2`` (R, G, B, luminance; unitless), ``albedo`` (source and
        target a incidence), ``delta_e2000``, ``limits`` (each measure, its threshold, whether
        the target cannot follow) and ``cannot_follow`` (sentences, empty when it can).
    """
    wi, wo, w = grid.wi, grid.wo, grid.weights
    cos = (wi[:, 2] * wo[:, 2])[:, None]
    same = target is source          # the Mitsuba target: the fabric itself, measured once
    fs = np.asarray(source.eval(wi, wo)) * cos
    ft = fs if same else np.asarray(target.eval(wi, wo)) * cos
    rel = {c: _rel_l2(ft[:, k], fs[:, k], w) for k, c in enumerate(_CHANNELS)}
    rel["luminance"] = _rel_l2(luminance(ft), luminance(fs), w)
    lum = luminance(fs)
    wl = w * lum / max(float(np.sum(w * lum)), 1e-300)
    cs, ct = _chroma(fs), _chroma(ft)
    spread = float(np.sqrt(np.sum(wl * np.sum((cs - wl @ cs) ** 2, -1))))
    missed = float(np.sqrt(np.sum(wl * np.sum((ct - cs) ** 2, -1))))
    aniso = _anisotropy(source, grid)
    aniso_t = aniso if same else _anisotropy(target, grid)
    rs, rt = _retro(source), _retro(target)
    retro_err = abs(rt - rs) / max(abs(rs), 1e-300)
    limits = {
        "anisotropy": {"source_azimuthal_variation": aniso,
                       "target_azimuthal_variation": aniso_t,
                       "threshold": LIMITS["anisotropy"],
                       "cannot_follow": aniso - aniso_t > LIMITS["anisotropy"]},
        "retroreflection": {"source_back_over_lambertian_60deg": rs,
                            "target_back_over_lambertian_60deg": rt,
                            "threshold": LIMITS["retroreflection"],
                            "cannot_follow": retro_err > LIMITS["retroreflection"]},
        "colour_shift": {"source_chromaticity_spread": spread,
                         "chromaticity_missed": missed, "threshold": LIMITS["colour_shift"],
                         "cannot_follow": missed > LIMITS["colour_shift"]},
    }
    words = []
    if limits["anisotropy"]["cannot_follow"]:
        words.append(f"anisotropy: the source varies by {aniso:.0%} as it turns about its "
                     f"normal, the target by {aniso_t:.0%}")
    if limits["retroreflection"]["cannot_follow"]:
        words.append(f"retroreflection: back-scatter at 60 deg is {rs:.3g} times a "
                     f"Lambertian's of the same albedo for the source, {rt:.3g} for the target")
    if limits["colour_shift"]["cannot_follow"]:
        words.append(f"colour shift with angle: the target misses {missed:.3f} of rg "
                     f"chromaticity (rms; the source's own spread {spread:.3f})")
    return {"grid": grid.as_dict(), "relative_l2": rel,
            "albedo": {"incidences_deg": list(ALBEDO_INCIDENCES), "source": _albedos(source),
                       "target": _albedos(target)},
            "delta_e2000": _delta_e(source, target), "limits": limits,
            "cannot_follow": words}


def summary_lines(fid: dict) -> list[str]:
    """The fidelity in a few lines for the terminal."""
    rel = fid["relative_l2"]
    lines = [f"relative L2 error of f_r cos cos: luminance {rel['luminance']:.3f} "
             f"(R {rel['R']:.3f}, G {rel['G']:.3f}, B {rel['B']:.3f})",
             "albedo (luminance) source/target: " + ", ".join(
                 f"{k} deg {fid['albedo']['source'][k]['luminance']:.3f}/"
                 f"{fid['albedo']['target'][k]['luminance']:.3f}"
                 for k in fid["albedo"]["source"]),
             f"CIEDE2000 of a patch lit at {fid['delta_e2000']['light_theta_deg']:g} deg: max "
             f"{fid['delta_e2000']['max']:.2f} (" + ", ".join(
                 f"{k} {v:.2f}" for k, v in fid["delta_e2000"]["per_view"].items()) + ")"]
    if fid["cannot_follow"]:
        lines += [f"cannot follow: {w}" for w in fid["cannot_follow"]]
    else:
        lines.append("cannot follow: nothing flagged (anisotropy, retroreflection and colour "
                     "shift within the thresholds)")
    return lines
