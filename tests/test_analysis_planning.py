"""analysis.planning: the information of a design, the greedy D-optimal choice, the start
from measured pairs, the instrument's limits, the posterior of a fit folder, and a Laplace
validation that a planned design tells more than a uniform one of the same size."""

import numpy as np
import pytest

import brdf
from analysis.fit.fisher import PRIOR_INFORMATION, table_information
from analysis.fit.posterior import FabricModel
from analysis.fit.workflow import fit_spec
from analysis.planning import plan, uniform_pairs
from analysis.planning.information import information, whitened_jacobians
from gonio import Instrument, measure
from gonio.layouts import pairs_from_angles
from gonio.table import Table

FREE = "kd1,gamma_s1,gamma_v1"
SMALL = "full:15:30"       # 1 + 5 * 12 = 61 directions a side: 3721 candidates


def _truth_table(fab, wi, wo, instrument, seed=None):
    """The fabric measured at the pairs: true values with the instrument's sigma (no noise),
    or a noisy measurement with ``seed``."""
    geo = pairs_from_angles(*_angles(wi, wo).T, degrees=True)
    if seed is None:
        t = measure(fab, geo, Instrument(), progress=False)
        return Table(t.wi, t.wo, t.values, sigma=instrument.sigma(t.values))
    return measure(fab, geo, instrument, seed=seed, progress=False)


def _angles(wi, wo):
    ti, pi_ = brdf.frames.to_angles(wi)
    to, po = brdf.frames.to_angles(wo)
    return np.degrees(np.stack([ti, pi_, to, po], -1))


def test_design_information_is_the_fisher_information_of_its_table():
    """Independent path: analysis.fit.fisher.table_information on a table of the same pairs
    (true values, the instrument's sigma) gives the same matrix."""
    fab = brdf.fabric("silk_crepe_de_chine")
    ins = Instrument(snr=25)
    spec = fit_spec(fab, FREE, None)
    wi, wo = uniform_pairs(50, ins, seed=3)
    jac = whitened_jacobians(fab, spec, spec.start()[None], wi, wo, ins)
    mine = information(jac)[0]
    table = _truth_table(fab, wi, wo, ins)
    ref = table_information(table, spec, FabricModel(fab, table.wi, table.wo)).information
    assert np.allclose(mine, ref, rtol=1e-5, atol=1e-8 * np.abs(ref).max())


def test_greedy_beats_uniform_and_its_criterion_is_the_tables():
    fab = brdf.fabric("silk_crepe_de_chine")
    ins = Instrument(snr=25)
    p = plan(fab, FREE, 15, instrument=ins, candidates=SMALL, draws=1)
    q = plan(fab, FREE, 15, instrument=ins, candidates=SMALL, draws=1, exchange_pass=False)
    c = p.criterion
    assert c["plan"] > c["uniform"] and c["plan"] >= q.criterion["plan"] - 1e-9
    assert np.all(p.sd <= p.uniform_sd)
    assert p.budget == 15 and len({tuple(a) for a in p.angles.round(6)}) == 15
    assert sorted(p.rank.tolist()) == list(range(1, 16))
    # the criterion recomputed from the plan's table by analysis.fit.fisher
    spec = fit_spec(fab, FREE, None)
    table = _truth_table(fab, p.wi, p.wo, ins)
    info = table_information(table, spec, FabricModel(fab, table.wi, table.wo)).information
    logdet = np.linalg.slogdet(info + PRIOR_INFORMATION * np.eye(3))[1]
    assert abs(logdet - c["plan"]) < 1e-4 * abs(logdet)


def test_measured_pairs_are_the_start_and_the_sd_shrinks():
    fab = brdf.fabric("velvet")
    ins = Instrument(snr=20)
    wi, wo = uniform_pairs(30, ins, seed=7)
    seed_table = _truth_table(fab, wi, wo, ins, seed=1)
    alone = plan(fab, FREE, 10, instrument=ins, candidates=SMALL, draws=2)
    after = plan(fab, FREE, 10, instrument=ins, candidates=SMALL, draws=2,
                 measured=seed_table)
    assert after.n_measured == 30
    assert np.all(after.sd < alone.sd)
    assert after.criterion["start"] > alone.criterion["start"]


def test_the_instruments_limits_are_respected():
    fab = brdf.fabric("linen_plain")
    ins = Instrument(snr=20, max_theta=60, min_separation=20)
    p = plan(fab, FREE, 12, instrument=ins, candidates=SMALL, draws=1)
    assert ins.reachable(p.wi, p.wo).all() and ins.reachable(p.uniform_wi, p.uniform_wo).all()
    assert p.angles[:, [0, 2]].max() <= 60 + 1e-9
    flat = Instrument(snr=20, in_plane=True)
    q = plan(fab, FREE, 8, instrument=flat, candidates="full:10:10", draws=1)
    assert flat.reachable(q.wi, q.wo).all()
    phi = q.angles[:, [1, 3]]
    normal = q.angles[:, [0, 2]].min(axis=1) < 1e-9
    assert np.all(normal | np.isclose(np.mod(phi[:, 1] - phi[:, 0], 360), 180)
                  | np.isclose(np.mod(phi[:, 1] - phi[:, 0], 360), 0))


def test_bad_input_is_refused_before_work():
    fab = brdf.fabric("velvet")
    with pytest.raises(ValueError, match="noiseless"):
        plan(fab, FREE, 5, instrument=Instrument())
    with pytest.raises(ValueError, match="budget"):
        plan(fab, FREE, 0, instrument=Instrument(snr=5))
    with pytest.raises(ValueError, match="exceeds the 25 candidate"):
        plan(fab, FREE, 26, instrument=Instrument(snr=5), candidates="full:45:90")
    with pytest.raises(ValueError, match="kdd1"):
        plan(fab, "kdd1", 5, instrument=Instrument(snr=5))
    with pytest.raises(ValueError, match="at most"):
        plan(fab, FREE, 5, instrument=Instrument(snr=5), candidates="full:1")


def test_a_fit_folder_plans_over_its_posterior(fit_folder):
    out, res = fit_folder
    ins = Instrument(snr=20)
    p = plan(out, "gamma_s1,kd1", 6, instrument=ins, candidates=SMALL, draws=4, seed=2)
    assert p.source == "posterior" and p.fabric == "fit" and p.budget == 6
    again = plan(out, "gamma_s1,kd1", 6, instrument=ins, candidates=SMALL, draws=4, seed=2)
    assert np.array_equal(p.angles, again.angles)
    own = plan(out, None, 4, instrument=ins, candidates=SMALL, draws=2)   # the fit's free set
    assert own.free == ("gamma_s1", "kd1")


def test_a_grey_instrument_counts_one_reading_a_pair():
    """Grey: the information of a grey table (R = G = B, the channels' mean) by
    analysis.fit.fisher, one row a pair."""
    fab = brdf.fabric("velvet")
    ins = Instrument(snr=25)
    spec = fit_spec(fab, FREE, None)
    wi, wo = uniform_pairs(40, ins, seed=4)
    jac = whitened_jacobians(fab, spec, spec.start()[None], wi, wo, ins, grey=True)
    assert jac.shape == (1, 40, 1, 3)
    t = _truth_table(fab, wi, wo, Instrument())
    grey = np.repeat(t.values.mean(axis=1, keepdims=True), 3, axis=1)
    table = Table(t.wi, t.wo, grey, sigma=ins.sigma(grey))
    ref = table_information(table, spec, FabricModel(fab, table.wi, table.wo)).information
    assert np.allclose(information(jac)[0], ref, rtol=1e-5, atol=1e-8 * np.abs(ref).max())


def test_laplace_validation_planned_beats_uniform():
    """Noisy tables measured at the planned and at uniform pairs: the Cramér-Rao sds of
    analysis.fit.fisher at the truth (the Laplace posterior of a fit) are smaller for the
    plan, in geometric mean."""
    fab = brdf.fabric("polyester_satin_charmeuse")
    ins = Instrument(snr=20)
    spec = fit_spec(fab, FREE, None)
    p = plan(fab, FREE, 20, instrument=ins, candidates=SMALL, draws=2)

    def sd(wi, wo):
        t = _truth_table(fab, wi, wo, ins, seed=5)
        return table_information(t, spec, FabricModel(fab, t.wi, t.wo)).cr_sd

    ratio = np.exp(np.mean(np.log(sd(p.wi, p.wo) / sd(p.uniform_wi, p.uniform_wo))))
    assert ratio < 0.9


def test_plan_file_reads_back_and_its_figure_shows_every_pair(tmp_path):
    """analysis.planning.workflow.plan_file writes a file gonio reads back pair for pair, with
    the header naming the fabric, the free parameters and one expected sd each;
    reports.plots.plan.draw_plan writes a PNG."""
    import matplotlib.image

    from analysis.planning.workflow import plan_file
    from gonio.geomspec import read_pairs_csv
    from gonio.pairsfile import read_pairs_header
    from reports.plots.plan import draw_plan

    fab = brdf.fabric("velvet")
    p, path = plan_file(fab, FREE, 12, tmp_path / "plan.csv", instrument=Instrument(snr=25),
                        candidates=SMALL, draws=1, seed=1)
    geo = read_pairs_csv(path)
    assert np.allclose(geo.wi, p.wi, atol=1e-12) and np.allclose(geo.wo, p.wo, atol=1e-12)
    head = read_pairs_header(path)
    assert head["free"] == "kd1,gamma_s1,gamma_v1" and head["budget"] == "12"
    assert [s.split("=")[0] for s in head["expected_sd"].split(", ")] == FREE.split(",")
    fig, (ax1, ax2) = draw_plan(p, filename=tmp_path / "plan.png")
    assert len(ax1.texts) >= p.budget            # each chosen pair numbered in its order
    img = matplotlib.image.imread(tmp_path / "plan.png")
    assert img.shape[0] > 200 and img.shape[1] > 400
