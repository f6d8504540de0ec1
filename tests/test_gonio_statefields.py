"""Tests of gonio.statefields (the checks of state files' fields) and, through it, of the JSON
and TOML readers: results.json, fit_config.json, a fit folder's medians, a fabric JSON, a fit
spec TOML. Damaged or hostile files are one ValueError line naming the file (and the field);
hypothesis fuzzes each reader with arbitrary JSON values put anywhere in a valid document."""

import json
import math

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from analysis.fit.checkpoint import FitFolder, read_config
from analysis.fit.medians import median_fabric
from analysis.fit.results import read_results
from analysis.params import ParamSpec
from gonio.statefields import MAX_DEPTH, FileFields, load_json, load_toml
from analysis.sources import resolve

FUZZ = settings(max_examples=60, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])


# ---------------------------------------------------------------------------- the helper
def test_each_check_names_file_field_value_and_what_is_allowed():
    f = FileFields("/x/results.json")
    doc = {"p": {"median": [1, 2], "n": 2.0, "s": 3, "b": 1, "a": [[1.0, np.nan]]}}
    cases = [
        (lambda: f.number(doc["p"], "median", "p"), "p.median must be a finite number; got [1, 2]"),
        (lambda: f.integer(doc["p"], "n", "p"), "p.n must be an integer; got 2.0"),
        (lambda: f.string(doc["p"], "s", "p"), "p.s must be a string; got 3"),
        (lambda: f.boolean(doc["p"], "b", "p"), "p.b must be true or false; got 1"),
        (lambda: f.number(doc["p"], "gone", "p"), "p.gone must be a finite number; it is missing"),
        (lambda: f.array(doc["p"], "a", "p", shape=(1, 2)),
         "p.a must be an array of finite numbers of shape (1, 2); got 1 non-finite value(s)"),
        (lambda: f.array(doc["p"], "a", "p", shape=(2,)),
         "p.a must be an array of finite numbers of shape (2,)"),
        (lambda: f.mapping({"q": []}, "q", "top"), "top.q must be an object; got []"),
    ]
    for fn, text in cases:
        with pytest.raises(ValueError) as exc:
            fn()
        assert str(exc.value).startswith("/x/results.json: " + text), str(exc.value)


def test_valid_fields_pass_through():
    f = FileFields("a.json")
    assert f.number({"x": 3}, "x") == 3.0 and isinstance(f.number({"x": 3}, "x"), float)
    assert f.number({"x": float("nan")}, "x", finite=False) != f.number({"x": 1}, "x")
    assert f.integer({"x": np.int64(4)}, "x", lo=0, hi=4) == 4
    assert f.number({}, "x", default=None) is None
    assert f.array({"x": [[1, 2]]}, "x", shape=(None, 2)).dtype == np.float64
    assert f.array({"x": np.arange(624, dtype=np.uint32)}, "x", shape=(624,),
                   integer=True)[-1] == 623
    with pytest.raises(ValueError, match=r"x must be a finite number in \[0, 1\]"):
        f.number({"x": 1.5}, "x", lo=0, hi=1)
    with pytest.raises(ValueError, match="x must be a finite number; got True"):
        f.number({"x": True}, "x")
    with pytest.raises(ValueError, match="too large for a float"):
        f.number({"x": 10 ** 400}, "x")


@pytest.mark.parametrize("text", ["[" * 100_000 + "]" * 100_000, '{"a":' * 50_000 + "1" +
                                  "}" * 50_000, "[" * (MAX_DEPTH + 2) + "]" * (MAX_DEPTH + 2)])
def test_deeply_nested_json_is_one_line_naming_the_file(tmp_path, text):
    path = tmp_path / "deep.json"
    path.write_text(text)
    with pytest.raises(ValueError) as exc:
        load_json(path)
    msg = str(exc.value)
    assert msg.startswith(f"{path}: ") and "\n" not in msg and "recursion" not in msg


def test_deeply_nested_toml_and_bad_text_name_the_file(tmp_path):
    deep = tmp_path / "deep.toml"
    deep.write_text("free = " + "[" * 5000 + "]" * 5000 + "\n")
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"free = \xff\n")
    for path in (deep, bad, tmp_path / "missing.toml"):
        with pytest.raises(ValueError) as exc:
            load_toml(path)
        assert str(exc.value).startswith(f"{path}: ") and "recursion" not in str(exc.value)
    with pytest.raises(ValueError, match=f"{deep}: "):          # and through the fit spec
        ParamSpec.from_toml(deep)


# ---------------------------------------------------------------------------- fuzz
def _json_values():
    leaves = (st.none() | st.booleans() | st.integers(-2**70, 2**70)
              | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=8))
    return st.recursive(leaves, lambda c: st.lists(c, max_size=3)
                        | st.dictionaries(st.text(max_size=6), c, max_size=3), max_leaves=8)


def _paths(doc, prefix=()):
    """Every place in a JSON document (dict keys and list indices), the root first."""
    yield prefix
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(
        doc, list) else ()
    for k, v in items:
        yield from _paths(v, prefix + (k,))


def _replaced(doc, path, value):
    if not path:
        return value
    doc = json.loads(json.dumps(doc))
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return doc


@st.composite
def _damaged(draw, doc):
    """``doc`` with one place (or, sometimes, a new key) holding an arbitrary JSON value."""
    paths = list(_paths(doc))
    path = paths[draw(st.integers(0, len(paths) - 1))]
    if draw(st.booleans()) and path and isinstance(doc, dict):
        path = path[:-1] + (draw(st.text(max_size=6)),)
        try:
            _replaced(doc, path, None)
        except (KeyError, IndexError, TypeError):
            path = paths[-1]
    return _replaced(doc, path, draw(_json_values()))


def _one_line_naming(exc, *names):
    msg = str(exc)
    assert isinstance(exc, (ValueError, OSError)), f"{type(exc).__name__} escaped: {msg}"
    assert "\n" not in msg.strip(), msg
    assert any(str(n) in msg for n in names), f"{msg!r} names none of {names}"


@pytest.fixture(scope="module")
def fit_dir(tmp_path_factory):
    """A real `microcyl fit` output folder (a short fit)."""
    from _fitmodels import fabric_table
    from analysis.fit.workflow import fit_fabric, fit_spec
    import brdf
    table, _ = fabric_table("silk_crepe_de_chine", n=60, seed=2)
    out = tmp_path_factory.mktemp("fit")
    fab = brdf.fabric("silk_crepe_de_chine")
    fit_fabric(table, fab, fit_spec(fab, "gamma_s1,kd1", ties=["none"]), out, max_steps=40,
               check_every=20, ensembles=2, progress=False,
               config_extra={"fabric": "silk_crepe_de_chine", "options": {}})
    return out


@FUZZ
@given(data=st.data())
def test_fuzz_results_json(fit_dir, tmp_path, data):
    doc = json.loads((fit_dir / "results.json").read_text())
    path = tmp_path / "results.json"
    path.write_text(json.dumps(data.draw(_damaged(doc))))
    try:
        out = read_results(path)
    except Exception as exc:  # noqa: BLE001 - the property is about what escapes
        _one_line_naming(exc, path)
        return
    for p in out["parameters"].values():          # what the readers then use is sound
        assert math.isfinite(p["median"]) and isinstance(p.get("unit", ""), str)


@FUZZ
@given(data=st.data(), which=st.sampled_from(["results.json", "fit_config.json"]))
def test_fuzz_fit_folder_medians(fit_dir, tmp_path_factory, data, which):
    folder = tmp_path_factory.mktemp("fz")
    for name in ("results.json", "fit_config.json"):
        (folder / name).write_bytes((fit_dir / name).read_bytes())
    doc = json.loads((fit_dir / which).read_text())
    (folder / which).write_text(json.dumps(data.draw(_damaged(doc))))
    try:
        med = median_fabric(folder)
    except Exception as exc:  # noqa: BLE001
        _one_line_naming(exc, folder)
        return
    assert np.all(np.isfinite(med.fabric.eval([0.0, 0.3, 0.95], [0.2, -0.1, 0.97])))


@FUZZ
@given(data=st.data())
def test_fuzz_fit_config_resume(fit_dir, tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("fc")
    doc = json.loads((fit_dir / "fit_config.json").read_text())
    (folder / "fit_config.json").write_text(json.dumps(data.draw(_damaged(doc))))
    try:
        read_config(folder / "fit_config.json")
        FitFolder(folder).read_start(doc["config"])
    except Exception as exc:  # noqa: BLE001
        _one_line_naming(exc, folder)       # the file, or the folder of another configuration


_PLUGIN = {"type": "microcylinder", "fabric": "velvet", "eta1": 1.5, "albedo1": [0.1, 0.2, 0.3],
           "kd2": 0.4, "gamma_s1": 8.0, "offsets2": "-20, 20", "lengths2": [1.0],
           "rotation": 30.0, "masking": True}


@FUZZ
@given(data=st.data())
def test_fuzz_fabric_json(tmp_path, data):
    path = tmp_path / "fabric.json"
    path.write_text(json.dumps(data.draw(_damaged(_PLUGIN))))
    try:
        fab = resolve(str(path)).brdf
    except Exception as exc:  # noqa: BLE001
        _one_line_naming(exc, path)
        return
    f = fab.eval([0.0, 0.3, 0.95], [0.2, -0.1, 0.97])
    assert np.all(np.isfinite(f)) and np.all(np.abs(f) < 1e30)


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) \
            else repr(v)
    if isinstance(v, (int, str)):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if v is None:
        return '""'
    return "{" + ", ".join(f"{json.dumps(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"


@FUZZ
@given(values=st.dictionaries(st.sampled_from(["free", "tie", "bounds", "prior", "start",
                                                "fabric", "kd1"]), _json_values(), max_size=4),
       raw=st.one_of(st.none(), st.text(max_size=40)))
def test_fuzz_fit_spec_toml(tmp_path, values, raw):
    path = tmp_path / "spec.toml"
    text = raw if raw is not None else "".join(f"{k} = {_toml_value(v)}\n"
                                               for k, v in values.items())
    path.write_text(text, encoding="utf-8")
    try:
        ParamSpec.from_toml(path, defaults={"kd1": 0.3, "gamma_s1": 5.0})
    except Exception as exc:  # noqa: BLE001
        _one_line_naming(exc, path)
