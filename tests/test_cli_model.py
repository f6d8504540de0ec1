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
    (["eval", "denim", "--wi", "30,0", "--wo", "30,180"], "unknown fabric 'denim'; valid presets"),
    (["eval", "velvet", "--wi", "30", "--wo", "30,180"], "expected THETA,PHI in degrees"),
    (["eval", "velvet", "--wi", "30,0", "--wo", "30,180", "--masking", "maybe"], "expected on or off"),
    (["eval", "velvet", "--wi", "30,0", "--wo", "30,180", "--tangent-samples", "0"],
     "--tangent-samples must be an integer in 1..4096; got 0"),
    (["eval", "velvet", "--wi", "30,0"], "the following arguments are required: --wo"),
    (["report", "--fabric", "denim"], "invalid choice: 'denim'"),
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
                 "--quality", "fast", "--quiet"]) == 0
    assert (out / "index.html").is_file() and (out / "velvet.html").is_file()
    data = json.loads((out / "summary.json").read_text())
    assert list(data["fabrics"]) == ["silk_shot", "velvet"]
    std = data["fabrics"]["velvet"]["standard_geometries"]
    wi = brdf.directions.from_angles(math.radians(30), 0.0)
    wo = brdf.directions.from_angles(math.radians(30), math.pi)
    np.testing.assert_allclose(std["specular 30 warp"], brdf.fabric("velvet").eval(wi, wo),
                               rtol=1e-12)
    assert data["fabrics"]["velvet"]["parameters"]["threads"][1]["offsets"] == [-90, -55, 55, 90]
    printed = capsys.readouterr().out
    assert "velvet" in printed and "index.html" in printed


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
