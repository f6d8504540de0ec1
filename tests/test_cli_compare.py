"""`microcyl compare` as a user runs it: short fits of a simulated silk table by the fabric that
made it and by a wrong preset, ranked by PSIS-LOO; fits of another table refused."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

import gonio
from _fitmodels import fabric_table

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
FIT = ["--free", "gamma_s1,kd1", "--tie", "none", "--max-steps", "60", "--check-every", "30",
       "--no-plots"]


def microcyl(*args, env=None):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)],
                          env=dict(ENV, **(env or {})), capture_output=True, text=True,
                          timeout=600)


@pytest.fixture(scope="module")
def fits(tmp_path_factory):
    """Fits of silk.csv (150 pairs of silk_crepe_de_chine, 5% noise) by silk_crepe_de_chine
    and silk_shot, and of other.csv (another draw of the same fabric) by silk_crepe_de_chine."""
    d = tmp_path_factory.mktemp("compare")
    for name, seed in (("silk", 9), ("other", 10)):
        table, _ = fabric_table("silk_crepe_de_chine", n=150, seed=seed)
        gonio.write(table, d / f"{name}.csv")
    out = {}
    for key, table, preset in (("right", "silk", "silk_crepe_de_chine"),
                               ("wrong", "silk", "silk_shot"),
                               ("other", "other", "silk_crepe_de_chine")):
        r = microcyl("fit", d / f"{table}.csv", "--fabric", preset, *FIT, "-o", d / key)
        assert r.returncode == 0, r.stderr
        assert "PSIS-LOO: elpd" in r.stdout
        out[key] = d / key
    return out


def test_compare_ranks_the_generating_fabric_first_by_more_than_4_se(fits, tmp_path):
    r = microcyl("compare", fits["wrong"], fits["right"], "--json")
    assert r.returncode == 0, r.stderr
    rows = json.loads(r.stdout)
    assert [row["fit"] for row in rows] == [str(fits["right"]), str(fits["wrong"])]
    assert all(set(row) == {"fit", "model", "elpd", "se", "d_elpd", "d_se", "d_se_block",
                            "d_lag1", "adequate", "n_high_k", "k_threshold"} for row in rows)
    # each fit's adequacy is its results.json's; the threshold arviz's for 400 draws
    for row, key in zip(rows, ("right", "wrong")):
        doc = json.loads((fits[key] / "results.json").read_text())
        assert row["adequate"] == doc["adequate"]
        assert row["k_threshold"] == pytest.approx(1 - 1 / math.log10(400))
    assert all(row["model"] == "microcylinder" for row in rows)
    best, wrong = rows
    assert best["d_elpd"] == 0 and best["d_se"] == 0
    assert wrong["d_elpd"] == pytest.approx(best["elpd"] - wrong["elpd"])
    assert wrong["d_elpd"] > 4 * wrong["d_se"] > 0
    # the numbers are those each fit wrote into its results.json
    for row, key in ((best, "right"), (wrong, "wrong")):
        loo = json.loads((fits[key] / "results.json").read_text())["loo"]
        assert row["elpd"] == pytest.approx(loo["elpd"]) and row["se"] == pytest.approx(
            loo["se"])
    # a fresh cache: arviz's once-a-day FutureWarning would be due, and is not shown
    text = microcyl("compare", fits["right"], fits["wrong"],
                    env={"XDG_CACHE_HOME": str(tmp_path / "cache")})
    assert text.returncode == 0 and "ArviZ" not in text.stderr and "Warning" not in text.stderr
    lines = text.stdout.splitlines()
    assert lines[0].split()[:4] == ["rank", "fit", "model", "elpd"]
    assert lines[1].split()[:3] == ["1", str(fits["right"]), "microcylinder"]
    assert lines[0].split()[-1] == "adequate"
    assert (f"{fits['right']} (microcylinder) is preferred over {fits['wrong']} "
            f"(microcylinder) by" in text.stdout)


def test_compare_refuses_fits_of_different_tables_in_one_line(fits):
    r = microcyl("compare", fits["right"], fits["other"])
    assert r.returncode == 1 and r.stdout == ""
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and "is a fit of another table" in err[0]
    assert err[0].startswith("microcyl compare: error:") and str(fits["other"]) in err[0]


def test_compare_refuses_a_folder_that_is_no_fit_and_a_single_fit(fits, tmp_path):
    r = microcyl("compare", fits["right"], tmp_path)
    assert r.returncode == 1 and len(r.stderr.strip().splitlines()) == 1
    assert "results.json: not found" in r.stderr
    r = microcyl("compare", fits["right"])
    assert r.returncode == 1 and "two or more fit folders" in r.stderr
