"""`microcyl export` of a fit to a relative table (CUReT-like): the absolute level is an
assumption, said on the terminal and in the fidelity file, never silently; `--albedo-scale K`
multiplies f_r by K. Run as a user runs it (the CLI in a subprocess)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
#: The table's values: velvet's f_r times this (relative units): the fit's scale.
UNITS = 0.02


def microcyl(*args, cwd):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          cwd=cwd, capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def relative_fit(tmp_path_factory):
    """A short real fit of velvet's f_r x 0.02 in a table whose meta says "relative" (kd1
    free; the fit adds scale), velvet's albedos held at the preset's."""
    import brdf
    from analysis.fit import fit_fabric, fit_spec
    from gonio.table import Table
    tmp = tmp_path_factory.mktemp("relfit")
    fab = brdf.fabric("velvet")
    rng = np.random.default_rng(5)
    wi = brdf.directions.from_angles(rng.uniform(0, 1.3, 200), rng.uniform(-3, 3, 200))
    wo = brdf.directions.from_angles(rng.uniform(0, 1.3, 200), rng.uniform(-3, 3, 200))
    f = UNITS * fab.eval(wi, wo)
    table = Table(wi, wo, f * (1 + 0.02 * rng.normal(size=f.shape)), sigma=0.02 * f + 1e-7,
                  meta={"units": "relative"})
    spec = fit_spec(fab, "kd1", [], None)
    fit_fabric(table, fab, spec, tmp / "fit", max_steps=60, ensembles=2, progress=False,
               config_extra={"fabric": "velvet", "options": fab.options})
    return tmp


def _albedo_normal(fab, n=400):
    """Directional albedo at normal incidence (luminance), by a midpoint rule in (cos theta,
    phi) written here: integral of f_r cos theta_o d omega."""
    mu = (np.arange(n) + 0.5) / n
    phi = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * np.pi
    m, p = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - m ** 2)
    wo = np.stack([s * np.cos(p), s * np.sin(p), m], -1).reshape(-1, 3)
    wi = np.broadcast_to([0.0, 0.0, 1.0], wo.shape)
    f = np.asarray(fab.eval(wi, wo)) @ [0.2126, 0.7152, 0.0722]
    return float(np.sum(f * wo[:, 2]) * (1.0 / n) * (2 * np.pi / (2 * n)))


def test_relative_fit_export_says_what_it_assumed(relative_fit):
    import brdf
    r = microcyl("export", "fit", "-o", "v.glb", "--grid", "3x6", "--draws", "0",
                 cwd=relative_fit)
    assert r.returncode == 0, r.stderr
    assert "relative scale: the fit 'fit' was made to relative values" in r.stdout
    assert "fixed at velvet's values" in r.stdout and "--albedo-scale K" in r.stdout
    doc = json.loads((relative_fit / "v.glb.fidelity.json").read_text())
    sc = doc["scale"]
    assert sc["absolute"] is False and sc["albedo_scale"] is None and sc["level_free"] == []
    assert sc["fit_scale"] == pytest.approx(UNITS, rel=0.1)
    a0 = _albedo_normal(brdf.fabric("velvet"))       # kd1 at its median, near velvet's
    assert sc["source_albedo_normal_luminance"] == pytest.approx(a0, rel=0.05)
    assert f"{sc['source_albedo_normal_luminance']:.3g}" in r.stdout
    assert any(n.startswith("relative scale:") for n in doc["notes"])


def test_albedo_scale_multiplies_the_source(relative_fit):
    """OpenPBR's fuzz (microcyl's Zeltner: linear in its colours at a given roughness, the
    base's throughput colourless): least squares on K f_r gives the same roughness and K
    times the colours, while they stay within [0, 1] (velvet's sheen is about 0.35)."""
    base = microcyl("export", "fit", "-o", "a.mtlx", "--grid", "3x6", "--draws", "0",
                    cwd=relative_fit)
    k = microcyl("export", "fit", "-o", "b.mtlx", "--grid", "3x6", "--draws", "0",
                 "--albedo-scale", "2", cwd=relative_fit)
    assert base.returncode == 0 and k.returncode == 0, (base.stderr, k.stderr)
    assert "f_r multiplied by 2 (--albedo-scale)" in k.stdout
    a, b = (json.loads((relative_fit / f"{n}.mtlx.fidelity.json").read_text())
            for n in ("a", "b"))
    assert b["scale"]["albedo_scale"] == 2.0
    assert b["scale"]["source_albedo_normal_luminance"] == pytest.approx(
        2 * a["scale"]["source_albedo_normal_luminance"], rel=1e-9)
    va, vb = a["projection"]["values"], b["projection"]["values"]
    assert vb["roughness"] == pytest.approx(va["roughness"], abs=2e-3)
    assert np.allclose(vb["sheen"], 2 * np.asarray(va["sheen"]), rtol=0.02, atol=1e-6)
    assert b["fidelity"]["relative_l2"]["luminance"] == pytest.approx(
        a["fidelity"]["relative_l2"]["luminance"], abs=2e-3)       # unitless: unchanged


def test_absolute_sources_say_nothing_and_bad_scales_are_one_line(tmp_path):
    r = microcyl("export", "velvet", "-o", "v.glb", "--grid", "3x6", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "relative scale" not in r.stdout and "albedo-scale" not in r.stdout
    doc = json.loads((tmp_path / "v.glb.fidelity.json").read_text())
    assert doc["scale"]["absolute"] is True and doc["scale"]["albedo_scale"] is None
    for args, words in ((("--albedo-scale", "0"), "--albedo-scale 0.0: must be a finite"),
                        (("--albedo-scale", "nan"), "must be a finite number > 0"),
                        (("--to", "mitsuba", "-o", "m.json", "--albedo-scale", "2"),
                         "writes the fabric itself")):
        bad = microcyl("export", "velvet", "-o", "w.glb", *args, cwd=tmp_path)
        assert bad.returncode != 0 and words in bad.stderr, bad.stderr
        assert len(bad.stderr.strip().splitlines()) == 1, bad.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.glb", "v.glb.fidelity.json"]
