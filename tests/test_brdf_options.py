"""brdf.options: the typed options of a fabric, validated once; Fabric.options derived from them."""

import json

import numpy as np
import pytest

import brdf
from brdf.options import FabricOptions, Gap, TangentSampling, Transmission, validate_method


@pytest.mark.parametrize("enum, good", [(Transmission, "longitudinal"), (Gap, "outgoing"),
                                        (TangentSampling, "control_points")])
def test_validate_method_takes_members_and_their_strings(enum, good):
    member = validate_method("x", good, enum)
    assert member is enum(good) and validate_method("x", member, enum) is member


@pytest.mark.parametrize("value", ["Half_Angle", "half-angle", "", None, 1, ("half_angle",)])
def test_validate_method_names_option_value_and_allowed(value):
    with pytest.raises(ValueError) as err:
        validate_method("transmission", value, Transmission)
    assert str(err.value) == (f"transmission must be one of 'half_angle', 'longitudinal'; got "
                              f"{value!r}")


def test_a_member_of_another_enum_is_refused():
    with pytest.raises(ValueError, match="gap must be one of 'incident', 'outgoing'"):
        validate_method("gap", Transmission.HALF_ANGLE, Gap)


def test_defaults_are_the_options_table():
    assert FabricOptions().as_dict() == brdf.OPTIONS
    assert list(brdf.OPTIONS) == ["masking", "reweighting", "tangent_samples",
                                  "tangent_sampling", "transmission", "gap", "rotation"]
    assert brdf.TRANSMISSION_METHODS == ("half_angle", "longitudinal")
    assert brdf.GAP_METHODS == ("incident", "outgoing")
    assert brdf.SAMPLING_METHODS == ("midpoint", "control_points")


def test_typed_inside_plain_outside():
    fab = brdf.fabric("velvet", gap=Gap.OUTGOING, transmission="longitudinal",
                      masking="off", tangent_samples=np.int64(8))
    opts = fab.plan.options
    assert opts.gap is Gap.OUTGOING and opts.transmission is Transmission.LONGITUDINAL
    assert opts.masking is False and opts.tangent_samples == 8
    plain = fab.options
    assert {k: type(v) for k, v in plain.items()} == {
        "masking": bool, "reweighting": bool, "tangent_samples": int,
        "tangent_sampling": str, "transmission": str, "gap": str, "rotation": float}
    assert plain["gap"] == "outgoing" and plain["transmission"] == "longitudinal"
    again = brdf.Fabric(fab.threads, **json.loads(json.dumps(fab.as_dict()))["options"])
    assert again.plan.options == opts


def test_options_are_frozen():
    opts = brdf.fabric("linen_plain").plan.options
    with pytest.raises(AttributeError):
        opts.gap = Gap.OUTGOING


def test_unknown_option_named():
    with pytest.raises(ValueError, match="unknown option\\(s\\) 'colour'; valid options are "
                                         "masking, reweighting"):
        FabricOptions.from_mapping({"colour": 1})
