"""The model's command-line verbs: fabrics, eval, report (good and bad input)."""

import json
import math

import numpy as np
import pytest

import brdf
from reports.cli import main


def test_fabrics_lists_every_preset_with_parameters(capsys):
    assert main(["fabrics"]) == 0
    out = capsys.readouterr().out
    for name in brdf.PRESETS:
        assert name in out
    assert "[-32, -32, -18, 0, 0, 18, 32, 32]" in out     # charmeuse warp offsets
    assert "1.539" in out and "2.5" in out


def test_eval_prints_fr(capsys):
    assert main(["eval", "velvet", "--wi", "30,0", "--wo", "40,180", "--masking", "off",
                 "--gap", "outgoing"]) == 0
    out = capsys.readouterr().out
    vals = [float(x) for x in out.split()[3::2]]
    fab = brdf.fabric("velvet", masking=False, gap="outgoing")
    expect = fab.eval(brdf.directions.from_angles(math.radians(30), 0.0),
                      brdf.directions.from_angles(math.radians(40), math.pi))
    np.testing.assert_allclose(vals, expect, rtol=1e-8)


@pytest.mark.parametrize("argv, message", [
    (["eval", "denim", "--wi", "30,0", "--wo", "30,180"], "FABRIC 'denim': not a preset (linen"),
    (["eval", "velvet", "--wi", "30", "--wo", "30,180"], "expected THETA,PHI in degrees"),
    (["eval", "velvet", "--wi", "30,0", "--wo", "30,180", "--masking", "maybe"], "expected on or off"),
    (["eval", "velvet", "--wi", "30,0", "--wo", "30,180", "--tangent-samples", "0"],
     "--tangent-samples must be an integer in 1..4096; got 0"),
    (["eval", "velvet", "--wi", "30,0"], "the following arguments are required: --wo"),
    (["report", "--fabric", "denim"], "--fabric 'denim': not a preset (linen"),
])
def test_bad_input_is_one_line_and_nonzero(argv, message, capsys):
    try:
        status = main(argv)
    except SystemExit as exc:
        status = exc.code
    assert status != 0
    err = capsys.readouterr().err.strip()
    assert message in err
    assert "Traceback" not in err
    assert len(err.splitlines()) <= 2   # argparse may print its usage line first


def test_report_writes_html_and_summary(tmp_path, capsys):
    out = tmp_path / "rep"
    assert main(["report", "--fabric", "silk_shot", "--fabric", "velvet", "-o", str(out),
                 "--quality", "fast", "--no-progress"]) == 0
    assert (out / "index.html").is_file() and (out / "velvet.html").is_file()
    data = json.loads((out / "summary.json").read_text())
    assert list(data["fabrics"]) == ["silk_shot", "velvet"]
    std = data["fabrics"]["velvet"]["standard_geometries"]
    wi = brdf.directions.from_angles(math.radians(30), 0.0)
    wo = brdf.directions.from_angles(math.radians(30), math.pi)
    np.testing.assert_allclose(std["specular 30 warp"], brdf.fabric("velvet").eval(wi, wo),
                               rtol=1e-12)
    assert data["fabrics"]["velvet"]["parameters"]["threads"][1]["offsets"] == [-90, -55, 55, 90]
    printed = capsys.readouterr()
    assert "velvet" in printed.out and "index.html" in printed.err   # "wrote": a diagnostic


def test_report_bad_fit_argument(tmp_path, capsys):
    assert main(["report", "-o", str(tmp_path / "r"), "--fit", "velvet=/nonexistent.json"]) == 1
    assert "no such file" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()


def test_report_unwritable_folder(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["report", "-o", str(blocker / "sub")]) == 1
    assert "cannot create output folder" in capsys.readouterr().err


def test_help_everywhere(capsys):
    for argv in (["--help"], ["fabrics", "--help"], ["eval", "--help"], ["report", "--help"]):
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 0
    assert "--tangent-samples" in capsys.readouterr().out


def test_version_and_a_closed_pipe(tmp_path):
    """`microcyl --version`, and `microcyl fabrics | head` (the reader gone) without a
    broken-pipe error."""
    import os
    import subprocess
    import sys
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, PYTHONPATH=root)
    v = subprocess.run([sys.executable, "-m", "reports", "--version"], env=env,
                       capture_output=True, text=True, timeout=120)
    assert v.returncode == 0 and v.stdout.startswith("microcyl ")
    r, w = os.pipe()
    os.close(r)                                     # the reader has already left
    p = subprocess.run([sys.executable, "-m", "reports", "fabrics"], stdout=w, env=env,
                       stderr=subprocess.PIPE, text=True, timeout=120)
    os.close(w)
    assert p.returncode == 0 and "BrokenPipe" not in p.stderr and p.stderr == ""


def test_json_of_fabrics_and_eval(capsys):
    assert main(["fabrics", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc["fabrics"]) == set(brdf.PRESETS) and doc["units"]["gamma_s"] == "deg"
    warp = doc["fabrics"]["polyester_satin_charmeuse"][0]
    assert warp["eta"] == 1.539 and warp["gamma_s"] == 2.5          # Table II
    assert warp["offsets"] == [-32, -32, -18, 0, 0, 18, 32, 32]
    assert main(["eval", "silk_shot", "--wi", "20,10", "--wo", "50,200", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    expect = brdf.fabric("silk_shot").eval(
        brdf.directions.from_angles(math.radians(20), math.radians(10)),
        brdf.directions.from_angles(math.radians(50), math.radians(200)))
    np.testing.assert_allclose(out["f_r"], expect, rtol=1e-15)
    assert out["unit"] == "1/sr" and out["wi_deg"] == [20.0, 10.0]


def test_diagnostics_through_logging(tmp_path):
    """'wrote ...' lines are diagnostics on stderr: shown by default, gone with -q; the
    result itself (here, none) stays on stdout."""
    import os
    import subprocess
    import sys
    from tests._gonio_helpers import random_table
    import gonio
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, PYTHONPATH=root)
    src, out = tmp_path / "t.csv", tmp_path / "t.exr"
    gonio.write(random_table(0), src)

    def run(*flags):
        return subprocess.run([sys.executable, "-m", "reports", *flags, "convert", str(src),
                               str(out)], env=env, capture_output=True, text=True, timeout=300)
    loud, quiet = run(), run("-q")
    assert loud.returncode == quiet.returncode == 0, loud.stderr
    assert f"wrote 50 rows to {out}" in loud.stderr and quiet.stderr == ""
    assert loud.stdout == quiet.stdout == ""
