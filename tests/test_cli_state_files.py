"""Damaged or hostile state files, as a user meets them: a colleague's fit folder
(results.json, fit_config.json, checkpoint.h5) or fabric JSON read by `export`, `plot table
--fit`, `render`, `report --fit` and a resumed `fit`. Each is refused with one line naming the
file and the field, exit status 1, no traceback (issue 24, problem 8)."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from _fitmodels import fabric_table
from test_cli_fit import _write_csv

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
FIT = ["--fabric", "silk_crepe_de_chine", "--free", "gamma_s1,kd1", "--tie", "none",
       "--check-every", "20", "--ensembles", "2"]


def microcyl(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          capture_output=True, text=True, timeout=300, cwd=cwd)


def refused(p, *names):
    """Exit 1, one line on stderr naming each of ``names``, no traceback."""
    err = p.stderr.strip()
    assert p.returncode == 1, (p.returncode, p.stdout[-500:], err[-2000:])
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for n in names:
        assert str(n) in err, f"{n!r} not in {err!r}"
    assert "recursion" not in err and "could not convert" not in err, err
    return err


@pytest.fixture(scope="module")
def fit(tmp_path_factory):
    """A table and a finished short fit of it (fit, 40 steps; resumable to 60)."""
    d = tmp_path_factory.mktemp("state")
    table, _ = fabric_table("silk_crepe_de_chine", n=60, seed=4)
    _write_csv(table, d / "silk.csv")
    p = microcyl("fit", d / "silk.csv", *FIT, "--max-steps", "40", "--no-plots", "-o",
                 d / "fit")
    assert p.returncode == 0, p.stderr
    return d


def _copy(fit, tmp_path, name="damaged"):
    out = tmp_path / name
    shutil.copytree(fit / "fit", out)
    return out


def _edit_json(path, change):
    doc = json.loads(path.read_text())
    change(doc)
    path.write_text(json.dumps(doc))


def test_a_median_that_is_a_list_is_named_by_every_reader(fit, tmp_path):
    bad = _copy(fit, tmp_path)
    _edit_json(bad / "results.json",
               lambda d: d["parameters"]["kd1"].__setitem__("median", [1, 2]))
    res = bad / "results.json"
    refused(microcyl("export", bad, "-o", tmp_path / "x.json"), res, "parameters.kd1.median")
    refused(microcyl("plot", "table", fit / "silk.csv", "--fit", bad, "-o", tmp_path / "p.png"),
            res, "parameters.kd1.median")
    refused(microcyl("render", "patch", bad, "-o", tmp_path / "r.png", "--width", 8,
                     "--height", 8, "--spp", 1, "--quiet"), res, "parameters.kd1.median")
    refused(microcyl("report", "--fabric", "silk_crepe_de_chine", "--fit",
                     f"silk_crepe_de_chine={res}", "-o", tmp_path / "rep", "--quiet"),
            res, "parameters.kd1.median")
    assert not (tmp_path / "rep").exists() and not (tmp_path / "x.json").exists()


def test_text_where_a_number_belongs_names_file_and_field(fit, tmp_path):
    bad = _copy(fit, tmp_path)
    _edit_json(bad / "fit_config.json", lambda d: d["config"]["spec"]["params"]["kd1"]
               .__setitem__("default", "abc"))
    refused(microcyl("export", bad, "-o", tmp_path / "x.json"), bad / "fit_config.json",
            "config.spec.params.kd1.default")
    bad2 = _copy(fit, tmp_path, "bad2")
    _edit_json(bad2 / "fit_config.json", lambda d: d.__setitem__("best", ["abc", 1.0]))
    refused(microcyl("fit", fit / "silk.csv", *FIT, "--max-steps", "60", "--no-progress",
                     "--no-plots", "-o", bad2), bad2 / "fit_config.json", "best")


def test_a_nested_fit_config_is_one_line_naming_it(fit, tmp_path):
    bad = _copy(fit, tmp_path)
    (bad / "fit_config.json").write_text('{"config": ' * 100_000)
    err = refused(microcyl("fit", fit / "silk.csv", *FIT, "--max-steps", "60",
                           "--no-progress", "--no-plots", "-o", bad), bad / "fit_config.json")
    assert "nested" in err


def _edit_h5(path, change):
    with h5py.File(path, "r+") as f:
        change(f)


def _short_keys(f):
    keys = f["ensemble_1/rng/keys"][:10]
    del f["ensemble_1/rng/keys"]
    f["ensemble_1/rng/keys"] = keys


def _nan_in_chain(f):
    c = f["ensemble_0/chain"][...]
    c[5, 1, 0] = np.nan
    f["ensemble_0/chain"][...] = c


def _nested_progress(f):
    f.attrs["progress"] = "[" * 100_000 + "]" * 100_000


@pytest.mark.parametrize("change, field", [(_short_keys, "ensemble_1.rng.keys"),
                                           (_nan_in_chain, "ensemble_0.chain"),
                                           (_nested_progress, "nested")])
def test_a_damaged_checkpoint_is_one_line_naming_the_field(fit, tmp_path, change, field):
    bad = _copy(fit, tmp_path)
    _edit_h5(bad / "checkpoint.h5", change)
    refused(microcyl("fit", fit / "silk.csv", *FIT, "--max-steps", "60", "--no-progress",
                     "--no-plots", "-o", bad), bad / "checkpoint.h5", field)


_FABRIC = '{"type": "microcylinder", "fabric": "velvet", '


@pytest.mark.parametrize("text, key", [(_FABRIC + '"albedo1": 1e308}', "albedo1"),
                                       ("[" * 100_000 + "]" * 100_000, "nested")])
def test_a_fabric_json_that_would_render_inf_is_refused_by_key(tmp_path, text, key):
    path = tmp_path / "fabric.json"
    path.write_text(text)
    refused(microcyl("render", "patch", path, "-o", tmp_path / "r.png", "--width", 8,
                     "--height", 8, "--spp", 1, "--quiet"), path, key)
    assert not (tmp_path / "r.png").exists()


@pytest.mark.parametrize("text, key", [
    (_FABRIC + '"kd2": NaN}', "kd2"), (_FABRIC + '"gamma_s2": Infinity}', "gamma_s2"),
    (_FABRIC + '"albedo2": [0.1, "nan", 0.2]}', "albedo2"),
    (_FABRIC + '"eta1": true}', "eta1"), (_FABRIC + '"rotation": "abc"}', "rotation")])
def test_non_finite_fabric_values_are_refused_like_range_errors(tmp_path, capsys, text, key):
    from reports.cli import main
    path = tmp_path / "fabric.json"
    path.write_text(text)
    assert main(["render", "patch", str(path), "-o", str(tmp_path / "r.png"), "--width", "8",
                 "--height", "8", "--spp", "1", "--quiet"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(path) in err and key in err, err
    assert not (tmp_path / "r.png").exists()
