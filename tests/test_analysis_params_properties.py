"""Property tests (hypothesis) of the fit's parameter specs: parse_free, parse_ties,
ParamSpec and ParamSpec.from_toml on random valid and invalid inputs. The rule: a spec is
either built, consistent (every free parameter free once, every tie onto a free source), or
refused with a ValueError/TypeError whose message names something of the input; no other
exception escapes."""

import string

import hypothesis.strategies as st
import numpy as np
from hypothesis import HealthCheck, given, settings

from analysis.paramnames import ALIASES, PARAM_NAMES
from analysis.params import ParamSpec, parse_free, parse_ties

SETTINGS = settings(max_examples=600, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])
NAMES = st.sampled_from(PARAM_NAMES + tuple(ALIASES))
JUNK = st.text(alphabet=string.ascii_lowercase + string.digits + "_=-, 1", max_size=12)
NAME_OR_JUNK = st.one_of(NAMES, NAMES, JUNK)
SCALARS = st.one_of(st.integers(-5, 5), st.floats(allow_nan=True, allow_infinity=True),
                    st.booleans(), st.text(max_size=5), st.none())
TIE = st.one_of(
    st.builds(lambda a, c, b: f"{a}={c}{b}", NAMES, st.sampled_from(["", "1-"]), NAMES),
    JUNK)
ALLOWED = (ValueError, TypeError)


def _names_something(message: str, pieces) -> bool:
    return any(p and str(p).strip() and str(p).strip()[:8] in message for p in pieces) or any(
        w in message for w in ("free", "tie", "bound", "prior", "start", "parameter"))


@SETTINGS
@given(st.one_of(st.lists(NAME_OR_JUNK, max_size=6), NAME_OR_JUNK,
                 st.lists(SCALARS, max_size=3), SCALARS))
def test_parse_free_builds_known_names_or_says_why(free):
    try:
        out = parse_free(free)
    except ALLOWED as exc:
        assert str(exc) and ("free" in str(exc) or "parameter" in str(exc))
        return
    assert out and len(set(out)) == len(out) and set(out) <= set(PARAM_NAMES)


@SETTINGS
@given(st.one_of(st.lists(TIE, max_size=4), TIE, st.lists(SCALARS, max_size=3), SCALARS))
def test_parse_ties_builds_ties_or_says_why(ties):
    try:
        out = parse_ties(ties)
    except ALLOWED as exc:
        assert "tie" in str(exc)
        return
    for target, (source, kind) in out.items():
        assert target in PARAM_NAMES and source in PARAM_NAMES and target != source
        assert kind in ("equal", "complement")


@SETTINGS
@given(free=st.lists(NAMES, min_size=0, max_size=5), ties=st.lists(TIE, max_size=3),
       bounds=st.dictionaries(NAMES, st.one_of(
           st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)), SCALARS), max_size=2),
       start=st.dictionaries(NAMES, st.one_of(st.floats(-10, 100), SCALARS), max_size=2))
def test_param_spec_is_consistent_or_refused(free, ties, bounds, start):
    try:
        spec = ParamSpec(free, defaults=start, ties=ties, bounds=bounds)
    except ALLOWED as exc:
        assert _names_something(str(exc), free + ties + list(bounds) + list(start))
        return
    assert len(set(spec.free)) == spec.ndim >= 1
    for target, (source, _) in spec.ties.items():
        assert source in spec.free and target not in spec.free
    u = spec.start()
    assert u.shape == (spec.ndim,) and np.all(np.isfinite(u))
    v = spec.values(u[None])
    for target, (source, kind) in spec.ties.items():
        want = v[source] if kind == "equal" else 1.0 - v[source]
        assert np.allclose(v[target], want)


def _toml_value(x):
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        return repr(x) if np.isfinite(x) else ("nan" if np.isnan(x) else
                                                ("inf" if x > 0 else "-inf"))
    if isinstance(x, str):
        return '"' + x.replace("\\", "").replace('"', "") + '"'
    if isinstance(x, list):
        return "[" + ", ".join(_toml_value(i) for i in x) + "]"
    return "{a = 1}"


TOML_VALUES = st.one_of(SCALARS.filter(lambda x: x is not None),
                        st.lists(st.one_of(NAMES, TIE, st.integers(0, 3)), max_size=3),
                        st.just({"a": 1}))


@SETTINGS
@given(st.dictionaries(st.sampled_from(["free", "tie", "bounds", "prior", "start", "fabric",
                                        "other"]), TOML_VALUES, max_size=4),
       st.dictionaries(st.sampled_from(["bounds", "prior", "start"]),
                       st.dictionaries(NAMES, TOML_VALUES, max_size=2), max_size=2))
def test_from_toml_reads_a_spec_or_names_the_file_and_key(tmp_path_factory, top, tables):
    lines = [f"{k} = {_toml_value(v)}" for k, v in top.items()]
    for t, entries in tables.items():
        if t in top:
            continue
        lines.append(f"[{t}]")
        lines += [f"{k} = {_toml_value(v)}" for k, v in entries.items()]
    text = "\n".join(lines) + "\n"
    path = tmp_path_factory.mktemp("toml") / "spec.toml"
    path.write_text(text)
    try:
        spec = ParamSpec.from_toml(path)
    except ALLOWED as exc:
        assert str(exc).startswith(str(path))
        return
    assert spec.ndim >= 1
