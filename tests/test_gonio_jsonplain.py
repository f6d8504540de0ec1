"""Tests of gonio.jsonplain: the project's one conversion to plain JSON data."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from gonio.jsonplain import plain


@dataclasses.dataclass
class _Inst:
    snr: float
    cone: tuple


def test_every_kind_becomes_plain_json():
    doc = {"i": np.int32(3), "b": np.bool_(True), "a": np.eye(2, dtype=np.float32),
           "d": _Inst(np.float64(20.0), (1, 2)), "p": Path("/x/y"), 5: None, "o": object}
    out = plain(doc)
    assert out["i"] == 3 and type(out["i"]) is int and out["b"] is True
    assert out["a"] == [[1.0, 0.0], [0.0, 1.0]] and out["d"] == {"snr": 20.0, "cone": [1, 2]}
    assert out["p"] == "/x/y" and out["5"] is None and out["o"] == str(object)
    assert json.loads(json.dumps(out)) == out


def test_nonfinite_policies():
    v = [float("nan"), np.float64(np.inf), 1.0]
    assert json.dumps(plain(v, nonfinite="null"), allow_nan=False) == "[null, null, 1.0]"
    assert plain(v, nonfinite="repr") == ["nan", "inf", 1.0]
    kept = plain(v)
    assert np.isnan(kept[0]) and kept[1] == np.inf
    with pytest.raises(ValueError, match="nonfinite must be"):
        plain(v, nonfinite="drop")
