"""Tests of reports.fitplots' adequacy figure: residuals against angle, the optional PIT
histogram, and the verdict and warnings as text."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

import brdf  # noqa: E402
from analysis.fit import FabricModel, fit  # noqa: E402
from analysis.params import ParamSpec, defaults_from_fabric  # noqa: E402
from reports.fitplots import adequacy_plot  # noqa: E402
from _fitmodels import fabric_table  # noqa: E402


def test_adequacy_figure_shows_residuals_pit_and_warnings(tmp_path):
    silk = brdf.fabric("silk_crepe_de_chine")
    t1, t2 = silk.threads
    fab = silk.replace(threads=(t1, t2.replace(area=0.0)))    # kd2 has no effect
    table, _ = fabric_table("silk", n=120, seed=3, fab=fab)
    spec = ParamSpec("gamma_s1,kd2", defaults=defaults_from_fabric(fab))
    r = fit(table, spec, FabricModel(fab, table.wi, table.wo), max_steps=100, progress=False,
            threads=1)
    assert any(w["kind"] == "not_informed" for w in r.warnings)
    pit = np.random.default_rng(0).uniform(size=r.counts["used"])
    fig, axes = adequacy_plot(r, table, pit=pit, filename=tmp_path / "a.png")
    assert len(axes) == 4 and (tmp_path / "a.png").stat().st_size > 1000
    # every point of the table is drawn once in the first panel, against its theta_i
    xs = np.concatenate([line.get_xdata() for line in axes[0].lines if line.get_marker() == "."])
    assert np.allclose(np.sort(xs), np.sort(np.degrees(table.angles[:, 0])))
    assert sum(p.get_height() for p in axes[3].patches) == pit.size
    text = "\n".join(t.get_text() for a in fig.axes for t in a.texts)
    assert "warning (not_informed): kd2" in text.replace("\n    ", " ")
    fig, axes = adequacy_plot(r, table)
    assert len(axes) == 3
