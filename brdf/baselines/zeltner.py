r"""The LTC sheen of Zeltner, Burley and Chiang (2022) as MaterialX's ``sheen_bsdf`` (mode
``zeltner``) evaluates it, over a Lambertian base layered by albedo scaling (OpenPBR's fuzz).

With x = cos_o (clamped to [1e-8, 1] as MaterialX's NdotV) and y = roughness, MaterialX's
rational fits (libraries/pbrlib/genglsl/lib/mx_microfacet_sheen.glsl, AcademySoftwareFoundation/
MaterialX at 4177b2cb; "adapted from https://github.com/tizian/ltc-sheen"):

    aInv(x, y) = (2.58126 x + 0.813703 y) y / (1 + 0.310327 x^2 + 2.60994 x y)
    bInv(x, y) = sqrt(1 - x) (y - 1) y^3 / (0.0000254053 + 1.71228 x - 1.71506 x y + 1.34174 y^2)
    R(x, y)    = exp(-(x - m)^2 / (2 s^2)) / (s sqrt(2 pi)) + o,   with
        s = y (0.0206607 + 1.58491 y) / (0.0379424 + y (1.32227 + y))
        m = y (-0.193854 + y (-1.14885 + y (1.7932 - 0.95943 y^2))) / (0.046391 + y)
        o = y (0.000654023 + (-0.0207818 + 0.119681 y) y) / (1.26264 + y (-1.92021 + y))

In the frame X = (wo - n cos_o) / |wo - n cos_o|, Y = n x X, n (any frame when wo = n: bInv = 0
there), wi = (w_x, w_y, w_z) and the LTC's inverse maps it to

    w' = (aInv w_x + bInv w_z, aInv w_y, w_z),    D(wi) = max(w_z, 0) / pi * (aInv / |w'|^2)^2

(mx_zeltner_sheen_brdf), a density over directions (integral D dwi = 1). MaterialX's
``mx_sheen_bsdf`` returns ``response = dirAlbedo * color * D`` as the radiance factor, which
carries the cosine: f_r cos(theta_i) = R sheen D. Hence

    R+      = max(R(cos_o, y), 0)
    f_sheen = sheen * R+ * D(wi) / cos(theta_i)
    f_r     = f_sheen + (1 - R+) * base / pi                   (1/sr)

the base scaled by ``throughput = 1 - dirAlbedo * weight`` (weight 1), colourless: a black
sheen still darkens the base, as a black fuzz absorbs. R+ is a reading: MaterialX's fit of R
dips to -2.1e-5 at roughness 0.04 to 0.13 (MaterialX clamps the Imageworks albedo in the same
file, not this one), which would make f_r negative (to -2.8e-3 1/sr over a black base); the
clamp changes the albedo by at most 2.1e-5 and keeps f_r >= 0. The sheen lobe's own albedo
is R+ exactly (D integrates to 1), so white sheen over a white base reflects R+ + (1 - R+) = 1.
MaterialX clamps roughness to [0.01, 1] ("the range of original impl."), the validated range
here.

Not reciprocal: the lobe's shape and R follow wo alone (``reciprocal = False``).

Sampling (:meth:`Zeltner.sample_directions`): with probability p the cosine hemisphere (the
base), otherwise the LTC lobe exactly (a cosine sample mapped by the LTC, as
mx_zeltner_sheen_importance_sample does); pdf = p cos(theta_i) / pi + (1 - p) D(wi).

Examples
--------
>>> import numpy as np
>>> from brdf.baselines.sheen import hemisphere_rule
>>> m = Zeltner(base=0.0, sheen=1.0, roughness=0.5)
>>> wo = np.array([0.6, 0.0, 0.8])
>>> wi, w = hemisphere_rule(0.8, 64, 64)             # the sheen lobe's albedo is R(0.8, 0.5)
>>> e = (m.eval(wi, wo)[:, 0] * wi[:, 2]) @ w
>>> bool(abs(e - dir_albedo(0.8, 0.5)) < 1e-4)
True
"""

from __future__ import annotations

import math

import numpy as np

from brdf.baselines.sheen import SheenModel
from brdf.frames import flat_pairs
from brdf.schema import ParamInfo

__all__ = ["Zeltner", "ROUGHNESS_ZELTNER", "dir_albedo", "ltc_ainv", "ltc_binv", "ltc_d"]

#: MaterialX's M_FLOAT_EPS: the least NdotV.
EPS = 1e-8

ROUGHNESS_ZELTNER = ParamInfo(
    "roughness", "scalar", "1", 0.01, 1.0, "r", "sheen roughness (MaterialX sheen_bsdf's "
    "roughness in zeltner mode)", typical=(0.1, 1.0), typical_value=0.5,
    note="MaterialX clamps it to [0.01, 1], the range of Zeltner et al.'s fits")


def dir_albedo(x, y):
    """MaterialX's mx_zeltner_sheen_dir_albedo: R(cos_o = x, roughness = y); broadcasts."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    s = y * (0.0206607 + 1.58491 * y) / (0.0379424 + y * (1.32227 + y))
    m = y * (-0.193854 + y * (-1.14885 + y * (1.7932 - 0.95943 * y * y))) / (0.046391 + y)
    o = y * (0.000654023 + (-0.0207818 + 0.119681 * y) * y) / (1.26264 + y * (-1.92021 + y))
    return np.exp(-0.5 * ((x - m) / s) ** 2) / (s * math.sqrt(2.0 * math.pi)) + o


def ltc_ainv(x, y):
    """MaterialX's mx_zeltner_sheen_ltc_aInv(x, y)."""
    return (2.58126 * x + 0.813703 * y) * y / (1.0 + 0.310327 * x * x + 2.60994 * x * y)


def ltc_binv(x, y):
    """MaterialX's mx_zeltner_sheen_ltc_bInv(x, y)."""
    return (np.sqrt(1.0 - x) * (y - 1.0) * y * y * y
            / (0.0000254053 + 1.71228 * x - 1.71506 * x * y + 1.34174 * y * y))


def _frame(wo):
    """The LTC frame's X and Y (n, 3) for viewers wo (n, 3) (MaterialX's
    mx_orthonormal_basis_ltc; for wo = n, mx_orthonormal_basis(+z) = (+x, +y))."""
    cos_o = np.clip(wo[:, 2], EPS, 1.0)
    x = wo - cos_o[:, None] * np.array([0.0, 0.0, 1.0])
    len2 = np.einsum("ij,ij->i", x, x)
    ok = len2 > 0.0
    x = np.where(ok[:, None], x / np.sqrt(np.where(ok, len2, 1.0))[:, None], [1.0, 0.0, 0.0])
    y = np.stack([-x[:, 1], x[:, 0], np.zeros(len(x))], axis=-1)            # n x X
    return x, y, cos_o


def ltc_d(wx, wy, wz, cos_o, roughness):
    """The LTC density D (1/sr) of directions with LTC-frame coordinates (wx, wy, wz) for
    the clamped cos_o and roughness; broadcasts."""
    a = ltc_ainv(cos_o, roughness)
    b = ltc_binv(cos_o, roughness)
    len2 = (a * wx + b * wz) ** 2 + (a * wy) ** 2 + wz * wz
    return np.maximum(wz, 0.0) / math.pi * (a / len2) ** 2


class Zeltner(SheenModel):
    """LTC sheen (MaterialX sheen_bsdf, zeltner mode) over a Lambertian base scaled by
    1 - R; see the module notes. Parameters: ``base`` and ``sheen`` (RGB in [0, 1]),
    ``roughness``."""

    name = "zeltner"
    ROUGHNESS = ROUGHNESS_ZELTNER
    reciprocal = False

    @classmethod
    def geometry(cls, wi, wo):
        x, y, cos_o = _frame(wo)
        return {"wx": np.einsum("ij,ij->i", wi, x), "wy": np.einsum("ij,ij->i", wi, y),
                "cos_i": wi[:, 2], "cos_o": cos_o}

    @classmethod
    def lobe(cls, geom, roughness):
        g = geom
        d = ltc_d(g["wx"], g["wy"], g["cos_i"], g["cos_o"], roughness)
        return np.maximum(dir_albedo(g["cos_o"], roughness), 0.0) * d / g["cos_i"]

    @classmethod
    def layer(cls, geom, roughness, sheen):
        return 1.0 - np.maximum(dir_albedo(geom["cos_o"], roughness), 0.0)

    # -- sampling: the cosine hemisphere or the LTC lobe ----------------------------------
    def sample_directions(self, wo, u):
        p = self.cosine_share()
        u0, u1 = u[:, 0], u[:, 1]
        cos_pick = u0 < p
        v = np.clip(np.where(cos_pick, u0 / p, (u0 - p) / max(1.0 - p, 1e-300)), 0.0,
                    1.0 - 1e-16)
        z = np.sqrt(1.0 - v)                         # cosine sample (both branches)
        r = np.sqrt(v)
        ph = 2.0 * np.pi * u1
        c = np.stack([r * np.cos(ph), r * np.sin(ph), z], axis=-1)
        x, y, cos_o = _frame(wo)
        a = ltc_ainv(cos_o, self.roughness)
        b = ltc_binv(cos_o, self.roughness)
        w = np.stack([(c[:, 0] - c[:, 2] * b) / a, c[:, 1] / a, c[:, 2]], axis=-1)
        w /= np.linalg.norm(w, axis=-1, keepdims=True)
        ltc = w[:, :1] * x + w[:, 1:2] * y + w[:, 2:3] * np.array([0.0, 0.0, 1.0])
        return np.where(cos_pick[:, None], c, ltc)

    def pdf(self, wo, wi):
        wi, wo, shape, bad, below = flat_pairs(wi, wo, names=("wi", "wo"))
        p = self.cosine_share()
        x, y, cos_o = _frame(wo)
        d = ltc_d(np.einsum("ij,ij->i", wi, x), np.einsum("ij,ij->i", wi, y), wi[:, 2], cos_o,
                  self.roughness)
        out = p * np.maximum(wi[:, 2], 0.0) / math.pi + (1.0 - p) * d
        out = np.where(below | (wi[:, 2] <= 0), 0.0, out)
        return np.where(bad, np.nan, out).reshape(shape)
