"""The paper's Table II: six fabrics' threads, by the names of MODEL.md (the data of
:mod:`brdf.presets`, kept apart from :class:`brdf.Fabric` so that the fabric itself can start
from a preset: :meth:`brdf.Fabric.start`)."""

from __future__ import annotations

from brdf.thread import Thread

__all__ = ["PRESETS", "DEFAULT_PRESET", "preset_threads", "check_preset"]


def _scaled(scale, rgb):
    return tuple(scale * c for c in rgb)


# name: (thread 1 (warp), thread 2 (weft)); A written as scale x (R, G, B) in MODEL.md.
_TABLE = {
    "linen_plain": (
        Thread(1.46, _scaled(0.3, (0.2, 0.8, 1.0)), 0.3, 12, 24, 0.33, (-25, 25), (1,)),
        Thread(1.46, _scaled(0.3, (0.2, 0.8, 1.0)), 0.3, 12, 24, 0.33, (-25, 25), (1,)),
    ),
    "silk_crepe_de_chine": (
        Thread(1.345, _scaled(0.12, (1.0, 0.95, 0.05)), 0.2, 5, 10, 0.75,
               (-35, -35, 35, 35), (1, 1, 1)),
        Thread(1.345, _scaled(0.16, (1.0, 0.95, 0.05)), 0.3, 18, 32, 0.25, (0, 0), (1,)),
    ),
    "polyester_satin_charmeuse": (
        Thread(1.539, _scaled(0.035, (1.0, 0.37, 0.3)), 0.1, 2.5, 5, 0.9,
               (-32, -32, -18, 0, 0, 18, 32, 32), (1.33, 0.66, 2, 2, 2, 0.66, 1.33)),
        Thread(1.539, _scaled(0.2, (1.0, 0.37, 0.3)), 0.7, 30, 60, 0.1, (0, 0), (1,)),
    ),
    "polyester_satin_charmeuse_back": (
        Thread(1.539, _scaled(0.035, (1.0, 0.37, 0.3)), 0.1, 2.5, 5, 0.67,
               (-30, -30, 30, 30, -5, -5, 5, 5), (1.33, 1.33, 1.33, 0, 0.67, 0.67, 0.67)),
        Thread(1.539, _scaled(0.2, (1.0, 0.37, 0.3)), 0.7, 30, 60, 0.33, (0, 0), (1,)),
    ),
    "silk_shot": (
        Thread(1.345, _scaled(0.2, (0.1, 1.0, 0.4)), 0.1, 4, 8, 0.86,
               (-25, -25, 25, 25), (1.33, 2.67, 1.33)),
        Thread(1.345, _scaled(0.6, (1.0, 0.0, 0.1)), 0.1, 5, 10, 0.14, (0, 0), (1,)),
    ),
    "velvet": (
        Thread(1.46, _scaled(0.3, (0.05, 0.02, 0.0)), 0.1, 6, 12, 0.5, (-90, -50), (1,)),
        Thread(1.46, _scaled(0.3, (0.05, 0.02, 0.0)), 0.1, 6, 12, 0.5,
               (-90, -55, 55, 90), (0.5, 0, 0.5)),
    ),
}

#: Names of the paper's fabrics (Table II), in the order of MODEL.md.
PRESETS = tuple(_TABLE)
#: The preset a microcylinder fit starts from when none is named.
DEFAULT_PRESET = "linen_plain"


def check_preset(name) -> str:
    """``name`` when it names a preset of :data:`PRESETS`: the one check of a preset's name.

    Raises
    ------
    ValueError
        Unknown name; the message lists the valid ones.

    Examples
    --------
    >>> check_preset("velvet")
    'velvet'
    >>> check_preset("denim")
    Traceback (most recent call last):
    ...
    ValueError: unknown fabric 'denim'; valid presets are linen_plain, silk_crepe_de_chine, polyester_satin_charmeuse, polyester_satin_charmeuse_back, silk_shot, velvet
    """
    if not isinstance(name, str) or name not in _TABLE:
        raise ValueError(f"unknown fabric {name!r}; valid presets are {', '.join(PRESETS)}")
    return name


def preset_threads(name: str) -> tuple[Thread, Thread]:
    """The two threads (warp, weft) of a preset.

    Raises
    ------
    ValueError
        Unknown name; the message lists the valid ones (:func:`check_preset`).
    """
    return _TABLE[check_preset(name)]
