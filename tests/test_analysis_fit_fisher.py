"""Which parameters a table can tell (analysis.fit.fisher): the Fisher information at the start
against an analytic toy, a parameter without effect, a confounded pair; ``microcyl fit
--suggest`` run as a user would."""

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.special import expit

import brdf
import gonio
from analysis.fit.fisher import (PRIOR_SD, candidate_spec, suggest_free,
                                 table_information)
from analysis.params import ParamSpec
from gonio.table import Table
from _fitmodels import fabric_table

REPO = Path(__file__).resolve().parents[1]


def _toy_table(n=60, kd=0.3, sigma=0.004, seed=0):
    """A grey Lambertian-like table f = kd / pi at random pairs, sigma known."""
    rng = np.random.default_rng(seed)
    wi = brdf.directions.from_angles(rng.uniform(0, 1.2, n), rng.uniform(-3, 3, n))
    wo = brdf.directions.from_angles(rng.uniform(0, 1.2, n), rng.uniform(-3, 3, n))
    return Table(wi, wo, np.full((n, 3), kd / math.pi), sigma=np.full((n, 3), sigma))


def _at_pairs(f, n):
    """f (B,) at n pairs, RGB: (B, n, 3)."""
    return np.broadcast_to(f[:, None, None], (f.shape[0], n, 3))


def lambert(n):
    """The model f_r = kd1 / pi at n pairs: eta and everything else without effect."""
    return lambda **kw: _at_pairs(kw["kd"][:, 0] / math.pi, n)


def product(n):
    """f_r = kd1 kd2 / pi: only the product is told."""
    return lambda **kw: _at_pairs(kw["kd"][:, 0] * kw["kd"][:, 1] / math.pi, n)


def test_cramer_rao_sd_matches_the_analytic_toy():
    """y = log(1 + f cos), s_y = cos sigma / (1 + f cos), f = kd / pi, kd = lo + (hi - lo)
    expit(u): dy/du / s_y = (hi - lo) q (1 - q) / (pi sigma) at every value, so
    I = n ((hi - lo) q (1 - q) / (pi sigma))^2 and sd = 1 / sqrt(I + 1/3) (the logistic
    prior's information). eta1, without effect, keeps the prior's: sqrt(3), ratio 0.95."""
    table, sigma, kd = _toy_table(), 0.004, 0.3
    spec = ParamSpec("kd1,eta1", defaults={"kd1": kd})
    r = table_information(table, spec, lambert(60))
    p = spec.params["kd1"]
    q = (kd - p.lo) / (p.hi - p.lo)
    info = len(table) * ((p.hi - p.lo) * q * (1 - q) / (math.pi * sigma)) ** 2
    assert r.information[0, 0] == pytest.approx(info, rel=1e-5)
    assert r.cr_sd[0] == pytest.approx(1 / math.sqrt(info + 1 / 3), rel=1e-5)
    assert r.natural_sd[0] == pytest.approx(r.cr_sd[0] * (p.hi - p.lo) * q * (1 - q),
                                            rel=1e-4)
    assert abs(r.information[1, 1]) < 1e-12
    assert r.cr_sd[1] == pytest.approx(math.sqrt(3.0), rel=1e-9)
    assert r.ratio[1] == pytest.approx(math.sqrt(3.0) / PRIOR_SD, rel=1e-9)
    assert r.verdict("eta1") == "not informed" and r.verdict("kd1") == "well informed"
    assert r.suggested == ("kd1",)


def test_sd_scales_with_the_noise_and_the_square_root_of_n():
    """Independent of the formula: four times the points, or half the noise, halve the
    table's part of the sd (the prior's 1/3 aside, negligible here)."""
    spec = ParamSpec("kd1", defaults={"kd1": 0.3})
    base = table_information(_toy_table(n=50), spec, lambert(50)).cr_sd[0]
    more = table_information(_toy_table(n=200), spec, lambert(200)).cr_sd[0]
    quieter = table_information(_toy_table(n=50, sigma=0.002), spec, lambert(50)).cr_sd[0]
    assert more == pytest.approx(base / 2, rel=1e-3)
    assert quieter == pytest.approx(base / 2, rel=1e-3)


def test_a_confounded_pair_is_named_and_one_of_it_suggested():
    spec = ParamSpec("kd1,kd2", defaults={"kd1": 0.3, "kd2": 0.4})
    r = table_information(_toy_table(), spec, product(60))
    (a, b, c), = r.confounded
    assert {a, b} == {"kd1", "kd2"} and c < -0.95
    assert len(r.suggested) == 1


def test_log_noise_is_a_candidate_without_sigma():
    """No sigma: log_noise is added (as the fit adds it) and starts at the rms residual."""
    t = _toy_table()
    t = t.replace(values=t.values * (1 + 0.05 * np.random.default_rng(1).normal(size=(60, 1))),
                  sigma=None)
    r = table_information(t, ParamSpec("kd1", defaults={"kd1": 0.3}), lambert(60))
    assert r.names == ("kd1", "log_noise")
    assert r.verdict("log_noise") != "not informed"


def test_candidates_of_an_rgb_table_include_the_albedos_and_a_grey_ones_not():
    fab = brdf.fabric("velvet")
    rgb, _ = fabric_table("velvet", n=30, seed=1)
    assert {"albedo1_r", "albedo2_b", "eta1", "area1"} <= set(candidate_spec(rgb, fab).free)
    grey = rgb.replace(values=np.repeat(rgb.values[:, :1], 3, 1),
                       sigma=np.repeat(rgb.sigma[:, :1], 3, 1))
    assert not any(n.startswith("albedo") for n in candidate_spec(grey, fab).free)


def test_suggest_on_the_model_keeps_ties_of_suggested_sources():
    from analysis.fit import FabricModel
    table, fab = fabric_table("silk_crepe_de_chine", n=200, seed=4)
    report, ties = suggest_free(table, fab, FabricModel(fab, table.wi, table.wo))
    assert "gamma_s1" in report.suggested and report.verdict("gamma_s1") == "well informed"
    assert set(ties) <= {"eta2", "area2"}
    assert all(src.lstrip("1-") in report.suggested for src in ties.values())


def test_microcyl_fit_suggest_prints_and_writes_nothing(tmp_path):
    table, _ = fabric_table("silk_crepe_de_chine", n=150, seed=9)
    path = tmp_path / "silk.csv"
    gonio.write(table, path)
    env = dict(os.environ, PYTHONPATH=str(REPO))
    r = subprocess.run([sys.executable, "-m", "reports", "fit", str(path), "--fabric",
                        "silk_crepe_de_chine", "--suggest"], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[1].split()[:2] == ["parameter", "start"]
    rows = {ln.split()[0]: ln for ln in lines[2:] if ln.split() and ln.split()[0] in
            {"eta1", "kd1", "gamma_s1", "albedo1_r", "albedo2_b"}}
    assert len(rows) == 5 and all(ln.rstrip().endswith("informed") for ln in rows.values())
    sugg = [ln for ln in lines if ln.startswith("suggested: --free ")]
    assert len(sugg) == 1
    free = sugg[0].split("--free ")[1].split()[0].split(",")
    assert "gamma_s1" in free
    assert sorted(p.name for p in tmp_path.iterdir()) == ["silk.csv"]     # nothing written
    r = subprocess.run([sys.executable, "-m", "reports", "fit", str(path), "--fabric",
                        "silk_crepe_de_chine"], cwd=tmp_path, env=env, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode != 0 and "-o/--output DIR is required" in r.stderr


def test_cramer_rao_sd_matches_the_posterior_of_a_fit(fit_folder):
    """The conftest's short fit of velvet (gamma_s1 and kd1 free, kd2 tied): the Fisher sd
    at the truth, in each parameter's unit, is the posterior's 68% half-width within 25%
    (a short fit: 100 steps of 2 ensembles; on the 3,721-pair silk table converged, the 14
    parameters' ratios were 0.97 to 1.19)."""
    from analysis.fit import FabricModel, fit_spec
    _, res = fit_folder
    fab = brdf.fabric("velvet", masking=False, rotation=0.25)
    rng = np.random.default_rng(2)                     # the conftest's table, rebuilt
    wi = brdf.directions.from_angles(rng.uniform(0, 1.3, 300), rng.uniform(-3, 3, 300))
    wo = brdf.directions.from_angles(rng.uniform(0, 1.3, 300), rng.uniform(-3, 3, 300))
    f = fab.eval(wi, wo)
    table = Table(wi, wo, f * (1 + 0.05 * rng.normal(size=f.shape)), sigma=0.05 * f + 1e-5)
    spec = fit_spec(fab, "gamma_s1,kd1", ["kd2=kd1"], None)
    r = table_information(table, spec, FabricModel(fab, table.wi, table.wo))
    for name, sd in zip(r.names, r.natural_sd):
        s = res.summary[name]
        assert (s["hi68"] - s["lo68"]) / 2 == pytest.approx(sd, rel=0.25), name
