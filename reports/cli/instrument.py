"""The instrument's options, shared by the verbs that simulate a gonioreflectometer
(``measure``, ``plan``): noise, cones and limits (:class:`gonio.Instrument`).

Angles are in degrees on the command line (cone half-angles and limits).
"""

from __future__ import annotations

import argparse
import math

from gonio import Instrument
from gonio.instrument import NOISE_MODELS

__all__ = ["add_instrument_options", "instrument_from_args"]


def add_instrument_options(parser: argparse.ArgumentParser):
    """Add the ``instrument`` option group (noise, cones, limits) to a verb's parser; returns
    the group (a verb may add its own options to it, such as ``--seed``)."""
    i = parser.add_argument_group("instrument")
    i.add_argument("--snr", type=float, default=None,
                   help="signal-to-noise ratio of the signal-dependent noise (default none)")
    i.add_argument("--noise", choices=NOISE_MODELS, default="multiplicative",
                   help="noise model (default multiplicative; shot = Poisson)")
    i.add_argument("--snr-reference", type=float, default=1.0, metavar="FR",
                   help="for --noise shot: the f_r (1/sr) at which the SNR is --snr")
    i.add_argument("--floor", type=float, default=0.0,
                   help="std of the additive Gaussian noise floor, 1/sr (default 0)")
    i.add_argument("--cone-source", type=float, default=0.0, metavar="DEG",
                   help="source cone half-angle, degrees (default 0: a point)")
    i.add_argument("--cone-detector", type=float, default=0.0, metavar="DEG",
                   help="detector cone half-angle, degrees (default 0: a point)")
    i.add_argument("--cone-rings", type=int, default=2, metavar="N",
                   help="cone quadrature rings (default 2)")
    i.add_argument("--cone-azimuths", type=int, default=6, metavar="N",
                   help="cone quadrature azimuths per ring (default 6)")
    i.add_argument("--max-theta", type=float, default=None, metavar="DEG",
                   help="largest polar angle of the source and the detector, degrees in "
                        "(0, 90] (default: no limit)")
    i.add_argument("--min-separation", type=float, default=None, metavar="DEG",
                   help="smallest angle between the source and detector cones, edge to "
                        "edge, degrees in [0, 180): the detector must not shadow the source "
                        "(default: no limit; any value > 0 excludes retro-reflection)")
    i.add_argument("--in-plane", action="store_true",
                   help="the instrument measures in the plane of incidence only")
    return i


#: The instrument's parameters and their options, longest name first (messages name them).
_OPTIONS = (("rings x azimuths", "--cone-rings x --cone-azimuths"),
            ("snr_reference", "--snr-reference"), ("cone_detector", "--cone-detector"),
            ("cone_source", "--cone-source"), ("azimuths", "--cone-azimuths"),
            ("rings", "--cone-rings"), ("floor", "--floor"), ("noise", "--noise"),
            ("snr", "--snr"))


def _check_angles(args: argparse.Namespace) -> None:
    """The options in degrees, each refused by name (in the command line's words)."""
    checks = (("--cone-source", args.cone_source, 0 <= args.cone_source < 90, "[0, 90)"),
              ("--cone-detector", args.cone_detector, 0 <= args.cone_detector < 90,
               "[0, 90)"),
              ("--max-theta", args.max_theta,
               args.max_theta is None or 0 < args.max_theta <= 90, "(0, 90]"),
              ("--min-separation", args.min_separation,
               args.min_separation is None or 0 <= args.min_separation < 180, "[0, 180)"))
    for option, value, ok, allowed in checks:
        if not ok or (value is not None and not math.isfinite(value)):
            what = "a half-angle" if option.startswith("--cone") else "an angle"
            raise ValueError(f"{option} must be {what} in {allowed} degrees; got {value}")


def instrument_from_args(args: argparse.Namespace) -> Instrument:
    """The :class:`gonio.Instrument` of :func:`add_instrument_options`'s options; a bad
    value is refused naming its option, before any work."""
    _check_angles(args)
    try:
        return Instrument(cone_source=args.cone_source, cone_detector=args.cone_detector,
                          snr=args.snr, floor=args.floor, noise=args.noise,
                          snr_reference=args.snr_reference, rings=args.cone_rings,
                          azimuths=args.cone_azimuths, max_theta=args.max_theta,
                          min_separation=args.min_separation, in_plane=bool(args.in_plane))
    except ValueError as exc:
        msg = str(exc)
        for name, option in _OPTIONS:
            if name in msg:
                raise ValueError(f"{option}: {msg}") from None
        raise ValueError(f"instrument options (--snr, --floor, --cone-*): {msg}") from None
