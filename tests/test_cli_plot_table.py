"""`microcyl plot table` shows all of a table, as a user runs it: CUReT velvet (real cloth,
points at many azimuths) drawn at every incidence of the warp plane with a line of what was
left out, and a `microcyl plan` design measured (scattered pairs) drawn at every point, its
`--data` CSV holding every point."""

import csv
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import brdf
import gonio
from analysis.measured import load_measured
from analysis.views import TableCoverage, is_scattered, table_coverage

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
#: Rec. 709 luminance weights (CIE Y of linear sRGB primaries), typed here.
Y709 = np.array([0.2126, 0.7152, 0.0722])


def microcyl(*args):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          capture_output=True, text=True, timeout=600)


def _read_data(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["curve", "theta_i", "phi_i", "theta_o", "phi_o", "f_r"]
    return [(r[0], *map(float, r[1:])) for r in rows[1:]]


def _in_plane(phi_deg, theta_deg, tol=2.0):
    """Directions within tol of the plane phi = 0 (either half), or of the pole."""
    d = np.abs((np.asarray(phi_deg) + 180.0) % 180.0)
    return (np.minimum(d, 180.0 - d) <= tol) | (np.asarray(theta_deg) <= tol)


def test_velvet_is_drawn_at_every_incidence_with_what_was_left_out(tmp_path, shared_data):
    table = load_measured("curet_07_velvet", shared_data)
    gonio.write(table, tmp_path / "velvet.csv")
    r = microcyl("plot", "table", tmp_path / "velvet.csv", "velvet", "-o", tmp_path / "v.png",
                 "--data", tmp_path / "v.csv")
    assert r.returncode == 0, r.stderr
    a = np.degrees(table.angles)
    valid = np.asarray(table.valid).all(axis=1)
    plane = _in_plane(a[:, 1], a[:, 0]) & _in_plane(a[:, 3], a[:, 2]) & valid
    assert 0 < plane.sum() < valid.sum()             # velvet has points off the warp plane
    # every incidence of the plane, grazing ones included; a panel per incidence and side
    ti = np.round(a[plane, 0] * 2) / 2
    light_at_0 = (a[plane, 0] > 2.0) & (np.cos(np.radians(a[plane, 1])) > 0)
    panels = {(t, s) for t, s in zip(ti, light_at_0)}
    assert f"(table, {len(panels)} axes)" in r.stdout
    assert ti.max() > 75                           # velvet's grazing incidence is there
    drawn = [row for row in _read_data(tmp_path / "v.csv") if row[0] == "measured"]
    assert len(drawn) == plane.sum()
    assert {round(row[1] * 2) / 2 for row in drawn} == set(ti)
    # the line saying what was left out, on the terminal (and the figure's title)
    off = int(valid.sum() - plane.sum())
    assert (f"drew {plane.sum()} of {len(table)} points; left out: {off} off the plane "
            f"φ = 0° (±2°)") in r.stdout
    # --theta-i selects; the others are counted as left out
    r = microcyl("plot", "table", tmp_path / "velvet.csv", "velvet", "--theta-i", "79",
                 "-o", tmp_path / "v79.png")
    assert r.returncode == 0, r.stderr
    n79 = int((ti == 79.0).sum())
    others = sorted(set(ti) - {79.0})
    assert (f"drew {n79} of {len(table)} points; left out: {off} off the plane φ = 0° (±2°), "
            f"{int(plane.sum()) - n79} at the incidences not asked for (θi = "
            + ", ".join(f"{t:g}" for t in others) + "°)") in r.stdout


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    """A D-optimal plan of 12 pairs for velvet's kd1 and gamma_s1, measured (SNR 25)."""
    d = tmp_path_factory.mktemp("plan")
    r = microcyl("plan", "velvet", "--free", "kd1,gamma_s1", "--budget", 12, "--snr", 25,
                 "--candidates", "full:15:30", "--seed", 3, "-q", "-o", d / "plan.csv")
    assert r.returncode == 0, r.stderr
    r = microcyl("measure", "velvet", "--geometry", f"pairs:{d / 'plan.csv'}", "--snr", 25,
                 "-q", "-o", d / "planned.csv")
    assert r.returncode == 0, r.stderr
    return d / "planned.csv"


def test_a_plan_design_gets_a_view_of_every_point(planned, tmp_path):
    table = gonio.read(planned)
    assert is_scattered(table)
    r = microcyl("plot", "table", planned, "velvet", "silk_shot", "-o", tmp_path / "p.png",
                 "--data", tmp_path / "p.csv")
    assert r.returncode == 0, r.stderr
    assert "no valid points" not in r.stderr
    # the measured-vs-model panel, and a residual map (with its colour bar) per model
    assert "(table, 5 axes)" in r.stdout
    rows = _read_data(tmp_path / "p.csv")
    n = len(table)
    assert [sum(1 for x in rows if x[0] == c) for c in ("measured", "velvet", "silk_shot")] \
        == [n, n, n]
    # each model's value is its luminance at the point's own angles
    for name in ("velvet", "silk_shot"):
        mine = np.array([x[1:] for x in rows if x[0] == name])
        t = np.radians(mine[:, :4])
        wi = np.stack([np.sin(t[:, 0]) * np.cos(t[:, 1]), np.sin(t[:, 0]) * np.sin(t[:, 1]),
                       np.cos(t[:, 0])], axis=1)
        wo = np.stack([np.sin(t[:, 2]) * np.cos(t[:, 3]), np.sin(t[:, 2]) * np.sin(t[:, 3]),
                       np.cos(t[:, 2])], axis=1)
        want = brdf.fabric(name).eval(wi, wo) @ Y709
        np.testing.assert_allclose(mine[:, 4], want, rtol=1e-6)
    measured = np.array([x[5] for x in rows if x[0] == "measured"])
    np.testing.assert_allclose(measured, np.asarray(table.values) @ Y709, rtol=1e-9)
    assert "left out" not in r.stdout                  # every point drawn
    # --theta-i has nothing to select among scattered pairs: one line
    r = microcyl("plot", "table", planned, "velvet", "--theta-i", "45", "-o", tmp_path / "q.png")
    assert r.returncode != 0 and len(r.stderr.strip().splitlines()) == 1
    assert "pairs are scattered" in r.stderr and not (tmp_path / "q.png").exists()


def test_coverage_counts_partition_the_table(shared_data):
    table = load_measured("curet_07_velvet", shared_data)
    cov = table_coverage(table, [], 0.0)
    assert isinstance(cov, TableCoverage) and cov.drawn == 0 and not cov.complete
    assert cov.off_plane + cov.at_other_incidences + cov.invalid == len(table)
    assert table_coverage(table, np.arange(len(table))).complete
