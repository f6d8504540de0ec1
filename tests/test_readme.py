"""The README's Python examples run as written (from a scratch folder, the data path pointed at
../shared/data) and give what they say."""

import contextlib
import io
import re
import textwrap
from pathlib import Path

import numpy as np
import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def _blocks():
    """The ```python blocks, dedented (some sit inside list items)."""
    return [textwrap.dedent(b) for b in
            re.findall(r"^[ \t]*```python\n(.*?)^[ \t]*```", README.read_text(), flags=re.S | re.M)]


def test_readme_has_python_examples():
    assert len(_blocks()) >= 3


def test_readme_starts_with_the_set_up_commands_and_stays_short():
    lines = README.read_text().splitlines()
    assert lines[0] == "```" and lines[1].startswith("make report") \
        and lines[2].startswith("make test")
    assert len(lines) <= 200


def test_readme_links_point_at_files():
    root = README.parent
    for target in re.findall(r"\]\(([^)#\s]+)\)", README.read_text()):
        if not target.startswith("http"):
            assert (root / target).exists(), target


@pytest.mark.parametrize("k", range(len(_blocks())))
def test_readme_example_runs(k, tmp_path, monkeypatch, shared_data):
    code = _blocks()[k].replace("../shared/data", str(shared_data))
    monkeypatch.chdir(tmp_path)
    out = io.StringIO()
    ns = {}
    with contextlib.redirect_stdout(out):
        exec(compile(code, f"README block {k}", "exec"), ns)
    if "f = fab.eval(wi, wo)" in code:        # the quickstart: f_r of velvet at one pair
        import brdf
        t_i, t_o = np.radians(30), np.radians(45)
        wi = np.array([np.sin(t_i), 0.0, np.cos(t_i)])       # phi_i = 0
        wo = np.array([-np.sin(t_o), 0.0, np.cos(t_o)])      # phi_o = 180 degrees
        expected = brdf.fabric("velvet").eval(wi, wo)
        assert expected.shape == (3,) and np.all(expected > 0)
        np.testing.assert_allclose(ns["f"], expected, rtol=1e-12)
        assert "velvet" in out.getvalue()
    if "gonio.write" in code:                 # the table written is the table read
        assert (tmp_path / "velvet.exr").exists()
        np.testing.assert_allclose(ns["same"].values, ns["table"].values, rtol=1e-6)
        np.testing.assert_allclose(ns["same"].wi, ns["table"].wi, atol=1e-6)
        assert len(ns["curet"]) == 205
    if "analysis.albedo" in code:             # the reflectance is physical and bounded
        assert np.all((ns["r"].value > 0) & (ns["r"].value < 1))
        assert np.all(ns["r"].error < 1e-3)
    if "fit_fabric" in code:                  # the fit wrote its results; velvet's gamma_s
        import json                            # (6 deg in Table II) inside its 95% interval
        doc = json.loads((tmp_path / "velvet_fit" / "results.json").read_text())
        g = doc["parameters"]["gamma_s1"]
        assert g["lo95"] < 6.0 < g["hi95"] and ns["result"].names == ("gamma_s1", "kd1")
        assert "gamma_s1" in out.getvalue()
    if "plot_polar_lobe" in code:
        assert (tmp_path / "lobe.png").stat().st_size > 1000
