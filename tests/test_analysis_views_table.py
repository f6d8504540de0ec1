"""Table views: each model evaluated once per panel at the measured points and once along the
plane, and what ``plot table --data`` writes is what the figure draws."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

import brdf  # noqa: E402
from analysis.views import compute_table_panel  # noqa: E402
from gonio import Table  # noqa: E402
from reports.plots import views as plot_views  # noqa: E402

W = np.array([0.2126, 0.7152, 0.0722])


def _in_plane_table(fab, theta_i_deg, light_phi):
    """A noiseless table of ``fab`` in the plane phi = 0 / 180: the light at azimuth
    ``light_phi`` (radians), the viewer every 10 degrees from -80 to 80 (signed)."""
    ti, to = np.meshgrid(np.radians(theta_i_deg), np.radians(np.arange(-80.0, 81.0, 10.0)),
                         indexing="ij")
    ti, to = ti.ravel(), to.ravel()
    wi = brdf.directions.from_angles(ti, np.full(ti.shape, light_phi))
    wo = brdf.directions.from_angles(np.abs(to), np.where(to >= 0, 0.0, np.pi))
    return Table(wi, wo, fab.eval(wi, wo), sigma=0.01 * fab.eval(wi, wo) + 1e-6)


class Counted:
    """A fabric whose evaluations are counted (pairs)."""

    def __init__(self, fab):
        self.fab, self.pairs = fab, 0

    def eval(self, wi, wo):
        self.pairs += wi.shape[0]
        return self.fab.eval(wi, wo)


def test_panel_is_the_models_at_the_points_each_evaluated_once():
    velvet, linen = brdf.fabric("velvet"), brdf.fabric("linen_plain")
    table = _in_plane_table(velvet, [20.0, 50.0], np.pi)
    models = {"velvet": Counted(velvet), "linen": Counted(linen)}
    panel = compute_table_panel(table, models, 50.0, 0.0, quantity="luminance", resolution=25)
    rows = panel.points["rows"]
    assert len(rows) == 17 and np.allclose(np.degrees(table.angles[rows, 0]), 50.0)
    assert all(m.pairs == 17 + 25 for m in models.values())    # points, curve: once each
    for name, fab in (("velvet", velvet), ("linen", linen)):
        at = fab.eval(table.wi[rows], table.wo[rows]) @ W
        assert np.allclose(panel.points["models"][name], at, rtol=1e-4)
    # noiseless: velvet at the points is the measured value
    assert np.allclose(panel.points["measured"], panel.points["models"]["velvet"], rtol=1e-12)


def test_data_csv_rows_are_the_drawn_points():
    velvet, linen = brdf.fabric("velvet"), brdf.fabric("linen_plain")
    table = _in_plane_table(velvet, [20.0, 50.0], np.pi)
    models = {"velvet": Counted(velvet), "linen": Counted(linen)}
    panels = plot_views.table_view_panels(table, models, resolution=31)
    counts = [m.pairs for m in models.values()]
    fig = plot_views.table_view(table, models, panels=panels, resolution=31)
    rows = plot_views.table_view_data(table, models, panels=panels)
    assert [m.pairs for m in models.values()] == counts          # drawn and written: no eval
    assert counts == [2 * (17 + 31)] * 2
    for ax, ti in zip(fig.axes, (20.0, 50.0)):
        lines = {line.get_gid(): line for line in ax.get_lines() if line.get_gid()}
        for name in ("measured", "velvet", "linen"):
            line = lines["data" if name == "measured" else f"model points {name}"]
            mine = [r for r in rows if r[0] == name and abs(r[1] - ti) < 1e-9]
            order = np.argsort([r[3] * (1 if abs(r[4]) < 90 else -1) for r in mine])
            assert np.array_equal(line.get_ydata(), np.array([mine[k][5] for k in order]))
            signed = [mine[k][3] * (1 if abs(mine[k][4]) < 90 else -1) for k in order]
            assert np.allclose(line.get_xdata(), signed)
