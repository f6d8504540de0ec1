r"""The Charlie sheen of Estevez and Kulla (2017) as glTF's KHR_materials_sheen specifies it,
over a Lambertian base with the extension's albedo scaling.

    alpha   = roughness^2                                   (glTF: sheenRoughness^2)
    D(h)    = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi)
    l(x)    = a / (1 + b x^c) + d x + e,   (a, b, c, d, e) = mix(P0, P1, (1 - alpha)^2)
              P0 = (21.5473, 3.82987, 0.19823, -1.97760, -4.32054)
              P1 = (25.3245, 3.32435, 0.16801, -1.27393, -4.85967)
    Lambda(c) = exp(l(c))                     if c < 0.5
              = exp(2 l(0.5) - l(1 - c))      otherwise
    V       = clamp(1 / ((1 + Lambda(cos_o) + Lambda(cos_i)) 4 cos_i cos_o), 0, 1)
    f_sheen = sheen * D * V
    S       = min(1 - max3(sheen) E(cos_o), 1 - max3(sheen) E(cos_i))
    f_r     = f_sheen + S * base / pi                       (1/sr)

Source: KHR_materials_sheen (KhronosGroup/glTF, extensions/2.0/Khronos/KHR_materials_sheen/
README.md at 77b44be7, "Implementation Notes": "Sheen distribution", "Sheen visibility" with the
constants above, "Albedo-scaling technique"); the clamp of V is Khronos's reference
renderer's (KhronosGroup/glTF-Sample-Viewer, source/Renderer/shaders/brdf.glsl at 00536c7d,
V_Sheen); Estevez and Kulla, "Production Friendly Microfacet Sheen BRDF", SIGGRAPH 2017
course notes. E(cos) is the sheen lobe's directional
albedo with colour 1, integral D V cos_i dwi; the spec reads it from a table (Enterprise PBR's
section 6.2.3); here it is computed by quadrature on a grid
(:mod:`brdf.baselines.charlietable`, checked in as charlie_albedo.json;
``bench/charlie_albedo_table.py`` regenerates it) and interpolated.

Readings (docs/guide/baselines.rst): V is clamped to [0, 1] as the Sample Viewer clamps it (the
spec's V has no clamp; its fitted Lambda is finite at cos 0, so unclamped V, and f_r, grow like
1 / cos: up to 4e7 1/sr at theta = 90 deg); with it f_sheen <= sheen * D <= sheen (2 + 1/alpha)
/ (2 pi). E still exceeds 1 at grazing (up to 1.87 in the table, 1.99 at theta_o = 90 deg),
where the spec's S would go negative; E is taken as min(E, 1) in S, as a table stored in an
image (values in [0, 1]) gives it, so S >= 0. Below the table's first node (cos < 1/4096) E
takes that node's value.

Reciprocal: D depends on h; V and S are symmetric in cos_i and cos_o.

Examples
--------
>>> import numpy as np
>>> m = Charlie(base=0.5, sheen=0.0, roughness=0.5)      # no sheen: plain Lambert
>>> wi = np.array([0.0, 0.0, 1.0]); wo = np.array([0.6, 0.0, 0.8])
>>> bool(np.allclose(m.eval(wi, wo), 0.5 / np.pi))
True
>>> 0.0 < float(sheen_albedo(1.0, 1.0)) < 0.2              # the lobe's albedo at normal view
True
>>> grazing = np.array([1.0, 0.0, np.cos(np.pi / 2)])     # theta = 90 deg: cos 6e-17 > 0
>>> f = float(Charlie(base=0.0, sheen=1.0, roughness=1.0).eval(grazing, wo)[0])
>>> 0.0 < f <= 3.0 / (2.0 * np.pi)                         # V <= 1: f <= D's maximum
True
"""

from __future__ import annotations

import math

import numpy as np

from brdf.baselines import charlietable
from brdf.baselines.sheen import SheenModel, lobe_albedo
from brdf.schema import ParamInfo

__all__ = ["Charlie", "ROUGHNESS_CHARLIE", "charlie_d", "charlie_lambda", "charlie_v",
           "sheen_albedo"]

#: glTF's sheenRoughness (alpha = roughness^2).
ROUGHNESS_CHARLIE = ParamInfo(
    "roughness", "scalar", "1", charlietable.R_MIN, 1.0, "r", "sheen roughness (glTF's "
    "sheenRoughness; alpha = r^2)", typical=(0.2, 1.0), typical_value=0.6,
    note="glTF allows [0, 1] but D is singular at 0; the lower bound is Filament's "
         "MIN_PERCEPTUAL_ROUGHNESS (0.045), the albedo table's first roughness")

_P0 = np.array([21.5473, 3.82987, 0.19823, -1.97760, -4.32054])
_P1 = np.array([25.3245, 3.32435, 0.16801, -1.27393, -4.85967])


def charlie_d(cos_h, alpha):
    """The Charlie distribution D(theta_h) (1/sr); broadcasts."""
    s2 = np.maximum(1.0 - np.asarray(cos_h) ** 2, 0.0)
    inv = 1.0 / np.asarray(alpha)
    return (2.0 + inv) * s2 ** (0.5 * inv) / (2.0 * math.pi)


def _l(x, alpha):
    t = (1.0 - np.asarray(alpha)) ** 2
    a, b, c, d, e = (p0 + (p1 - p0) * t for p0, p1 in zip(_P0, _P1))
    return a / (1.0 + b * np.power(x, c)) + d * x + e


def charlie_lambda(cos, alpha):
    """The spec's Lambda(cos theta) for alpha; broadcasts."""
    cos = np.asarray(cos, dtype=np.float64)
    low = np.abs(cos) < 0.5
    lx = _l(np.where(low, np.abs(cos), np.clip(1.0 - cos, 0.0, 0.5)), alpha)
    return np.exp(np.where(low, lx, 2.0 * _l(0.5, alpha) - lx))


def charlie_v(cos_i, cos_o, alpha):
    """The Charlie visibility G / (4 cos_i cos_o) clamped to [0, 1] as the glTF Sample
    Viewer's V_Sheen clamps it (dimensionless); broadcasts over directions above the horizon
    (cos_i, cos_o > 0)."""
    v = 1.0 / ((1.0 + charlie_lambda(cos_o, alpha) + charlie_lambda(cos_i, alpha))
               * (4.0 * cos_i * cos_o))
    return np.clip(v, 0.0, 1.0)


def sheen_albedo(cos, roughness):
    """E(cos theta, roughness): the Charlie lobe's directional albedo (colour 1), bilinear in
    the checked-in table (sqrt(cos), sqrt(roughness)); broadcasts. Not clamped to 1."""
    return charlietable.interpolate(cos, roughness)


class Charlie(SheenModel):
    """Charlie sheen with glTF's visibility and albedo scaling over a Lambertian base; see
    the module notes. Parameters: ``base`` and ``sheen`` (RGB in [0, 1]), ``roughness``."""

    name = "charlie"
    ROUGHNESS = ROUGHNESS_CHARLIE
    reciprocal = True

    @classmethod
    def geometry(cls, wi, wo):
        h = wi + wo
        return {"cos_h": h[:, 2] / np.linalg.norm(h, axis=-1), "cos_i": wi[:, 2],
                "cos_o": wo[:, 2], "nodes_i": charlietable.cos_nodes(wi[:, 2]),
                "nodes_o": charlietable.cos_nodes(wo[:, 2])}

    @classmethod
    def lobe(cls, geom, roughness):
        alpha = roughness * roughness
        return charlie_d(geom["cos_h"], alpha) * charlie_v(geom["cos_i"], geom["cos_o"], alpha)

    @classmethod
    def layer(cls, geom, roughness, sheen):
        m = np.max(sheen, axis=-1)[..., None]
        e_o = np.minimum(charlietable.interpolate_nodes(*geom["nodes_o"], roughness), 1.0)
        e_i = np.minimum(charlietable.interpolate_nodes(*geom["nodes_i"], roughness), 1.0)
        return np.minimum(1.0 - m * e_o, 1.0 - m * e_i)


def albedo_table(n_mu: int = 160, n_phi: int = 160) -> np.ndarray:
    """E on :mod:`~brdf.baselines.charlietable`'s grid by quadrature
    (:func:`brdf.baselines.sheen.lobe_albedo`): array (N_U, N_R)."""
    return lobe_albedo(Charlie, charlietable.U ** 2, charlietable.R, n_mu, n_phi)

