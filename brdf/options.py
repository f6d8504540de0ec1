"""A fabric's options (MODEL.md's toggles and variants), typed and validated once.

The variants are string enums (:class:`enum.StrEnum`): a member equals its string
(``Transmission.HALF_ANGLE == "half_angle"``) and is written as it in JSON, so that options read
from files and command lines are accepted as strings; inside the model they are compared as
members (``options.transmission is Transmission.HALF_ANGLE``), never as free strings.
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Mapping

from brdf import schema, validate

__all__ = ["Transmission", "Gap", "TangentSampling", "FabricOptions", "OPTIONS",
           "TRANSMISSION_METHODS", "GAP_METHODS", "SAMPLING_METHODS", "validate_method",
           "MAX_TANGENT_SAMPLES"]


class Transmission(enum.StrEnum):
    """F_T of MODEL.md: ``half_angle`` (1 - F_r(cos g))^2, ``longitudinal`` (1 - F_r(cos
    theta_i))(1 - F_r(cos theta_r))."""

    HALF_ANGLE = "half_angle"
    LONGITUDINAL = "longitudinal"


class Gap(enum.StrEnum):
    """c_gap of Q: ``incident`` n . wi, ``outgoing`` n . wo."""

    INCIDENT = "incident"
    OUTGOING = "outgoing"


class TangentSampling(enum.StrEnum):
    """Samples of a tangent curve: arc-length ``midpoint`` s or the ``control_points``."""

    MIDPOINT = "midpoint"
    CONTROL_POINTS = "control_points"


#: The values of each variant, in order (the first is the default).
TRANSMISSION_METHODS = tuple(m.value for m in Transmission)
GAP_METHODS = tuple(m.value for m in Gap)
SAMPLING_METHODS = tuple(m.value for m in TangentSampling)
#: The most tangent samples a curve takes (the default is 32), and the most control points
#: (offsets) a tangent curve lists: a fixed cap on the work and memory of each direction
#: pair, whoever asks (a preset's options, a fabric JSON or TOML, the command line's
#: --tangent-samples, the API).
MAX_TANGENT_SAMPLES = 4096


def validate_method(name: str, value, methods: type[enum.StrEnum]) -> enum.StrEnum:
    """``value`` (a member or its string) as a member of ``methods``, or a ValueError naming
    the option, the value and the allowed values (as colour-science's ``validate_method``;
    case matters here).

    Examples
    --------
    >>> validate_method("gap", "outgoing", Gap) is Gap.OUTGOING
    True
    >>> validate_method("gap", "none", Gap)
    Traceback (most recent call last):
    ...
    ValueError: gap must be one of 'incident', 'outgoing'; got 'none'
    """
    if isinstance(value, methods):
        return value
    return methods(validate.choice(name, value, tuple(m.value for m in methods)))


@dataclasses.dataclass(frozen=True)
class FabricOptions:
    """MODEL.md's toggles and variants of a fabric, validated (:meth:`from_mapping`).

    Attributes
    ----------
    masking, reweighting : bool
        Shadowing and masking M; reweighting P and Q (off: M = 1; P = Q = 1).
    tangent_samples : int
        Samples N per tangent curve (>= 1).
    tangent_sampling : TangentSampling
    transmission : Transmission
    gap : Gap
    rotation : float
        Rotation of both threads about n, radians.

    Examples
    --------
    >>> opts = FabricOptions.from_mapping({"gap": "outgoing"})
    >>> opts.gap is Gap.OUTGOING, opts.as_dict()["gap"]
    (True, 'outgoing')
    """

    masking: bool = True
    reweighting: bool = True
    tangent_samples: int = 32
    tangent_sampling: TangentSampling = TangentSampling.MIDPOINT
    transmission: Transmission = Transmission.HALF_ANGLE
    gap: Gap = Gap.INCIDENT
    rotation: float = 0.0

    @classmethod
    def from_mapping(cls, options: Mapping) -> "FabricOptions":
        """Options from a mapping of names to values (strings for the variants), each
        checked: a ValueError names an unknown option, or an option, its value and what is
        allowed."""
        unknown = set(options) - set(OPTIONS)
        if unknown:
            raise ValueError(f"unknown option(s) {', '.join(sorted(map(repr, unknown)))}; "
                             f"valid options are {', '.join(OPTIONS)}")
        opts = dict(OPTIONS, **options)
        return cls(
            masking=validate.flag("masking", opts["masking"]),
            reweighting=validate.flag("reweighting", opts["reweighting"]),
            tangent_samples=validate.integer("tangent_samples", opts["tangent_samples"], lo=1,
                                             hi=MAX_TANGENT_SAMPLES),
            tangent_sampling=validate_method("tangent_sampling", opts["tangent_sampling"],
                                             TangentSampling),
            transmission=validate_method("transmission", opts["transmission"], Transmission),
            gap=validate_method("gap", opts["gap"], Gap),
            rotation=schema.FABRIC["rotation"].check(opts["rotation"]))

    def as_dict(self) -> dict:
        """The options as plain values (variants as their strings), in :data:`OPTIONS`'
        order: what ``Fabric.options`` and the JSON of a fabric hold."""
        return {f.name: (v.value if isinstance(v := getattr(self, f.name), enum.Enum) else v)
                for f in dataclasses.fields(self)}


#: Option names and defaults of a Fabric (MODEL.md's toggles and variants), plain values.
OPTIONS = {f.name: (f.default.value if isinstance(f.default, enum.Enum) else f.default)
           for f in dataclasses.fields(FabricOptions)}
