"""The absolute level of an export's f_r: measured, assumed, or given by the user.

A fit of a table of relative values (CUReT's reflectance, any table whose meta says
``units: relative``) frees an overall factor ``scale`` that maps the model's f_r onto the
table's units: the data fix the product, not the model's own level, which then rests on
whatever held the model's albedo parameters (fixed at the preset's values, or free with
their level traded against ``scale``). The fit folder's median fabric, which ``export``
projects, leaves ``scale`` out: its absolute level is an assumption. :func:`scale_report`
says so in the fidelity file (``scale``) and on the terminal, with the source's directional
albedo at normal incidence, and ``--albedo-scale K`` (:class:`Scaled`) multiplies the
source's f_r by K for a user who knows the cloth's albedo (K = measured / that albedo).

Examples
--------
>>> import brdf
>>> s = Scaled(brdf.fabric("velvet"), 2.0)
>>> import numpy as np
>>> wi = wo = np.array([[0.0, 0.0, 1.0]])
>>> bool(np.allclose(s.eval(wi, wo), 2.0 * brdf.fabric("velvet").eval(wi, wo)))
True
"""

from __future__ import annotations

import math

import numpy as np


__all__ = ["Scaled", "check_albedo_scale", "relative_fit", "scale_report"]

#: Names of the parameters that set a model's level (albedos, base and sheen colours).
_LEVEL = ("albedo", "base", "sheen")


class Scaled:
    """A BRDF whose f_r is ``k`` times another's (``--albedo-scale``); ``eval`` only."""

    def __init__(self, inner, k: float):
        self.inner, self.k = inner, float(k)

    def eval(self, wi, wo) -> np.ndarray:
        """``k`` x the inner f_r (1/sr), shape (..., 3)."""
        return self.k * np.asarray(self.inner.eval(wi, wo))


def check_albedo_scale(k) -> float | None:
    """``k`` as a float when it is a finite positive number (None passes); a ValueError
    naming ``--albedo-scale`` otherwise.

    Examples
    --------
    >>> check_albedo_scale(None), check_albedo_scale(2)
    (None, 2.0)
    >>> check_albedo_scale(0)
    Traceback (most recent call last):
    ...
    ValueError: --albedo-scale 0: must be a finite number > 0 (the factor on f_r)
    """
    if k is None:
        return None
    try:
        v = float(k)
    except (TypeError, ValueError):
        v = float("nan")
    if not (math.isfinite(v) and v > 0) or isinstance(k, bool):
        raise ValueError(f"--albedo-scale {k!r}: must be a finite number > 0 (the factor on "
                         f"f_r)")
    return v


def relative_fit(src) -> dict | None:
    """For a fit folder whose fit freed ``scale`` (a relative table): its median ``scale``,
    the parameters that set the model's level and whether any was free; None otherwise."""
    if src.kind != "fit":
        return None
    med = src.median                    # read once, when the folder was resolved
    if "scale" not in med.free:
        return None
    level = [n for n in med.values if n.startswith(_LEVEL)]
    return {"fit_scale": med.scale, "level_parameters": level,
            "level_free": [n for n in level if n in med.free],
            "start": med.preset or med.model_name}


def scale_report(src, rel: dict | None, k: float | None, fid: dict) -> tuple[dict, str | None]:
    """The fidelity file's ``scale`` section and the terminal's sentence (None when there is
    nothing to say: an absolute source, unscaled).

    ``fid`` is the export's fidelity (:func:`analysis.export.fidelity.fidelity`), measured
    on the source as exported (times ``k`` when given): its directional albedo at normal
    incidence is quoted.
    """
    a0 = fid["albedo"]["source"]["0"]["luminance"]
    doc = {"absolute": rel is None, "albedo_scale": k,
           "source_albedo_normal_luminance": a0}
    if rel is not None:
        how = (f"free ({', '.join(rel['level_free'])}: their medians, a level the relative "
               f"data cannot tell from scale's)" if rel["level_free"]
               else f"fixed at {rel['start']}'s values")
        doc.update(fit_scale=rel["fit_scale"], level_parameters=rel["level_parameters"],
                   level_free=rel["level_free"],
                   assumed=f"the model's level parameters {how}")
    if rel is None and k is None:
        return doc, None
    if rel is None:
        return doc, (f"f_r multiplied by {k:g} (--albedo-scale): directional albedo at "
                     f"normal incidence {a0:.3g} (luminance)")
    head = (f"relative scale: the fit {src.label!r} was made to relative values (its scale "
            f"{rel['fit_scale']:.3g} maps f_r onto them), so f_r's absolute level was not "
            f"measured")
    if k is not None:
        return doc, (f"{head}; f_r multiplied by {k:g} (--albedo-scale), the model's level "
                     f"parameters {how}: directional albedo at normal incidence {a0:.3g} "
                     f"(luminance)")
    return doc, (f"{head}. This export assumes the model's level parameters {how}: a "
                 f"directional albedo at normal incidence of {a0:.3g} (luminance). Give "
                 f"--albedo-scale K to multiply f_r by K (K = the cloth's measured albedo / "
                 f"{a0:.3g})")
