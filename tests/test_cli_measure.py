"""Tests of the ``microcyl measure`` verb (reports/cli/measure.py)."""

import math
import re

import numpy as np
import pytest

import brdf
import gonio
from reports.cli import main


@pytest.fixture
def written(monkeypatch):
    """Replace gonio.write by a recorder, to check what would be written without writing."""
    calls = []
    monkeypatch.setattr(gonio, "write", lambda table, path: calls.append((table, path)),
                        raising=False)
    return calls


@pytest.fixture
def made(monkeypatch):
    """Record the keyword arguments brdf.fabric receives."""
    calls = []
    real = brdf.fabric

    def fabric(name, **kw):
        calls.append((name, kw))
        return real(name, **kw)

    monkeypatch.setattr(brdf, "fabric", fabric)
    return calls


def test_measure_good(tmp_path, written, made, capsys):
    out = tmp_path / "t.exr"
    status = main(["measure", "velvet", "--geometry", "plane:warp:30", "--snr", "50",
                   "--floor", "0.001", "--cone-source", "1", "--cone-detector", "2",
                   "--seed", "1", "--tangent-samples", "4", "--masking", "off",
                   "--reweighting", "on", "--tangent-sampling", "control_points",
                   "--transmission", "longitudinal", "--gap", "outgoing",
                   "--rotation", "30", "-o", str(out)])
    assert status == 0
    assert made == [("velvet", {"masking": False, "reweighting": True, "tangent_samples": 4,
                                "tangent_sampling": "control_points",
                                "transmission": "longitudinal", "gap": "outgoing"})]
    (table, path), = written
    assert path == out and len(table) == 6 * 5
    m = table.meta
    assert m["seed"] == 1 and m["units"] == "1/sr" and m["source"]["name"] == "velvet"
    assert m["instrument"]["snr"] == 50 and m["instrument"]["cone_detector"] == 2
    assert m["geometry"]["kind"] == "plane" and math.isclose(m["geometry"]["rotation_deg"], 30)
    assert table.sigma is not None
    # the rotation turns the sample: the table's directions are in the sample frame
    assert math.isclose(math.degrees(table.angles[5, 1]), -30, abs_tol=1e-9)  # theta_i 15
    # same as the Python API with the same settings
    fab = brdf.fabric("velvet", masking=False, tangent_samples=4,
                      tangent_sampling="control_points", transmission="longitudinal",
                      gap="outgoing")
    ref = gonio.measure(fab, gonio.from_spec("plane:warp:30",
                                                      rotation=math.radians(30)),
                        gonio.Instrument(cone_source=1, cone_detector=2, snr=50, floor=0.001),
                        seed=1)
    assert np.array_equal(ref.values, table.values)
    assert "velvet: 30 pairs" in capsys.readouterr().out


def test_measure_defaults_pass_no_options(tmp_path, written, made):
    assert main(["measure", "linen_plain", "--geometry", "plane:weft:45:0",
                 "-o", str(tmp_path / "a.csv")]) == 0
    assert made == [("linen_plain", {})]
    (table, _), = written
    assert table.sigma is None and table.meta["seed"] is None


def test_unknown_fabric(tmp_path, written, capsys):
    status = main(["measure", "tweed", "-o", str(tmp_path / "t.exr")])
    err = capsys.readouterr().err.strip()
    assert status == 1 and "\n" not in err
    assert "FABRIC 'tweed': not a preset" in err
    for name in brdf.PRESETS:
        assert name in err
    assert not written


@pytest.mark.parametrize("args, match", [
    (["--geometry", "sphere:3"], "unknown kind 'sphere'"),
    (["--geometry", "full:0"], "theta_step"),
    (["--snr", "-5"], "snr"),
    (["--floor", "-1"], "floor"),
    (["--cone-detector", "95"], "--cone-detector"),
    (["--seed", "-3"], "--seed"),
    (["--tangent-samples", "0"], "--tangent-samples"),
    (["--rotation", "nan"], "--rotation"),
])
def test_bad_values_exit_1(tmp_path, written, capsys, args, match):
    status = main(["measure", "velvet", *args, "-o", str(tmp_path / "t.exr")])
    err = capsys.readouterr().err.strip()
    assert status == 1 and match in err and "\n" not in err
    assert err.startswith("microcyl measure: error:")
    assert not written


@pytest.mark.parametrize("args", [
    ["--masking", "maybe"],
    ["--gap", "sideways"],
    ["--snr", "lots"],
    [],                                    # no -o
])
def test_usage_errors_exit_2(capsys, args):
    with pytest.raises(SystemExit) as exc:
        main(["measure", "velvet", *args])
    assert exc.value.code == 2
    assert "\n" not in capsys.readouterr().err.strip()


def test_missing_output_folder(tmp_path, written, capsys):
    status = main(["measure", "velvet", "-o", str(tmp_path / "nope" / "t.exr")])
    assert status == 1 and "does not exist" in capsys.readouterr().err
    assert not written


def test_measure_writes_a_readable_table(tmp_path):
    out = tmp_path / "t.exr"
    assert main(["measure", "silk_shot", "--geometry", "plane:warp:30", "--snr", "40",
                 "--seed", "2", "--tangent-samples", "4", "-o", str(out)]) == 0
    table = gonio.read(out)
    fab = brdf.fabric("silk_shot", tangent_samples=4)
    ref = gonio.measure(fab, "plane:warp:30", gonio.Instrument(snr=40), seed=2)
    assert len(table) == len(ref)
    assert np.allclose(table.values, ref.values, rtol=1e-6, atol=1e-7)   # float32 on disk


def test_progress_shows_on_a_pipe_unless_turned_off(tmp_path):
    """As a user runs it, stderr a pipe (not a terminal): tqdm's bar over the pairs, as
    `microcyl fit` shows its own; --no-progress draws none."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    runs = {}
    for flag in ([], ["--no-progress"]):
        out = tmp_path / f"t{len(flag)}.exr"
        r = subprocess.run([sys.executable, "-m", "reports", "measure", "velvet", "--geometry",
                            "full:30", "--tangent-samples", "4", *flag, "-o", str(out)],
                           env=env, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        assert len(gonio.read(out)) == 625                 # full:30: 625 pairs
        runs[bool(flag)] = r.stderr
    assert "measure:" in runs[False] and "625" in runs[False] and "pair" in runs[False]
    # on a pipe the bar is whole lines (no carriage returns), the last one at 100%
    bar = [line for line in runs[False].splitlines() if line.startswith("measure:")]
    assert "\r" not in runs[False] and bar[-1].startswith("measure: 100%")
    assert "measure:" not in runs[True] and "%|" not in runs[True]


def _run_measure(*args):
    """``microcyl measure ...`` as a user runs it: a subprocess, progress on."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    return subprocess.run([sys.executable, "-m", "reports", "measure", *map(str, args)],
                          env=env, capture_output=True, text=True, timeout=300)


def test_measure_refuses_a_plan_with_a_pair_out_of_reach(tmp_path):
    """A plan file (gonio.write_pairs_csv) with a retro-reflection pair: with
    --min-separation 5 the verb fails in one line naming the pair, and writes nothing;
    without the pair it measures the plan, the limits in the table's metadata."""
    angles = [[30, 0, 30, 180], [40, 90, 40, 90], [20, 0, 60, 180]]   # row 2: retro
    plan = gonio.write_pairs_csv(tmp_path / "plan.csv", angles, {"fabric": "velvet"})
    out = tmp_path / "t.csv"
    r = _run_measure("velvet", "--geometry", f"pairs:{plan}", "--min-separation", "5",
                     "--tangent-samples", "4", "-o", out)
    err = r.stderr.strip()
    assert r.returncode == 1 and "\n" not in err, err
    assert err.startswith(f"microcyl measure: error: geometry pairs:{plan}: 1 of 3 pairs out "
                          f"of the instrument's reach (1 closer than min_separation)")
    assert "theta_i 40, phi_i 90, theta_o 40, phi_o 90 deg" in err
    assert err.endswith("limits: min_separation 5 deg")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.csv"]
    gonio.write_pairs_csv(plan, [angles[0], angles[2]])
    r = _run_measure("velvet", "--geometry", f"pairs:{plan}", "--min-separation", "5",
                     "--max-theta", "80", "--in-plane", "--cone-detector", "1",
                     "--tangent-samples", "4", "-o", out)
    assert r.returncode == 0, r.stderr
    t = gonio.read(out)
    assert len(t) == 2 and np.allclose(np.degrees(t.angles[:, 0]), [20, 30])  # travel order
    ins = t.meta["instrument"]
    assert (ins["min_separation"], ins["max_theta"], ins["in_plane"]) == (5, 80, True)


@pytest.mark.parametrize("args, match", [
    (["--max-theta", "0"], r"--max-theta must be an angle in \(0, 90\] degrees; got 0.0"),
    (["--max-theta", "nan"], r"--max-theta must be an angle in \(0, 90\]"),
    (["--min-separation", "180"], r"--min-separation must be an angle in \[0, 180\) degrees"),
    (["--in-plane", "--geometry", "full:30"], r"505 of 625 pairs out of the instrument's reach"
                                              r" \(25 closer than min_separation, 480 out of "
                                              r"the plane of incidence\)"),
])
def test_bad_limits_are_refused_naming_the_option(tmp_path, written, capsys, args, match):
    status = main(["measure", "velvet", "--min-separation", "1", *args,
                   "-o", str(tmp_path / "t.exr")])
    err = capsys.readouterr().err.strip()
    assert status == 1 and "\n" not in err and re.search(match, err), err
    assert not written
