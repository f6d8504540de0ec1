"""Colour from the data: a warm cotton simulated from linen's preset with a changed albedo,
fitted from linen's blue albedo. ``--suggest`` must not keep the contradicted albedo fixed,
and a fit that holds it fixed is warned (``colour_fixed``) with the channels to free."""

from __future__ import annotations

import numpy as np
import pytest

import brdf
import gonio
from analysis.fit import FabricModel
from analysis.fit.fisher import candidate_spec, start_colour_difference, suggest_free
from analysis.fit.workflow import fit_fabric, fit_spec

WARM = (0.8, 0.45, 0.2)          # a warm cotton (linen's preset albedo is blue-grey)
ALBEDOS = [f"albedo{j}_{c}" for j in (1, 2) for c in "rgb"]


@pytest.fixture(scope="module")
def warm_table():
    linen = brdf.fabric("linen_plain")
    warm = linen.with_values({f"albedo{j}_{c}": a for j in (1, 2) for c, a in zip("rgb", WARM)})
    return gonio.measure(warm, "full:30:60", gonio.Instrument(snr=50), seed=3, progress=False)


def test_suggest_frees_the_albedo_the_table_contradicts(warm_table):
    linen = brdf.fabric("linen_plain")
    model = FabricModel(linen, warm_table.wi, warm_table.wo)
    spec = candidate_spec(warm_table, linen)
    assert "rotation" in spec.free
    assert start_colour_difference(warm_table, spec, model) > 10
    report, _ = suggest_free(warm_table, linen, model)
    assert set(ALBEDOS) <= set(report.suggested), report.suggested
    # the same table in linen's own colour: no colour contradiction at the start
    own = gonio.measure(linen, "full:30:60", gonio.Instrument(snr=50), seed=3, progress=False)
    assert start_colour_difference(own, spec, FabricModel(linen, own.wi, own.wo)) < 1


@pytest.mark.slow
def test_a_fit_holding_the_wrong_albedo_is_warned(warm_table, tmp_path):
    linen = brdf.fabric("linen_plain")
    spec = fit_spec(linen, "kd1,kd2", table=warm_table)        # albedo held fixed
    r = fit_fabric(warm_table, linen, spec, tmp_path, max_steps=60, n_starts=1, seed=1,
                   progress=False)
    assert r.quality["albedo_delta_e2000"] > 5
    kinds = {w["kind"]: w for w in r.warnings}
    assert set(kinds["colour_fixed"]["parameters"]) == set(ALBEDOS)
    assert "albedo1" in kinds["colour_fixed"]["message"]


def test_the_default_free_set_frees_the_albedo_on_a_table_of_another_colour(warm_table):
    linen = brdf.fabric("linen_plain")
    spec = fit_spec(linen, table=warm_table)
    assert set(ALBEDOS) <= set(spec.free)
    assert any("CIEDE2000" in n and "albedo1, albedo2 freed" in n for n in spec.notes)
    # linen's own colour: the default free set is the microcylinder's, albedo fixed
    own = gonio.measure(linen, "full:30:60", gonio.Instrument(snr=50), seed=3, progress=False)
    assert not set(ALBEDOS) & set(fit_spec(linen, table=own).free)
