"""Tests of reports.prose: the findings of the energy and reciprocity reports in words."""

import math

from analysis import energy_report, reciprocity_report
from reports.prose import energy_statements, reciprocity_statements


def test_energy_statements_of_a_small_report():
    rep = energy_report(["silk_shot"], ["default", "gap_outgoing"], theta_deg=(0.0, 60.0),
                        phi_deg=(0.0, 90.0), hemispherical=False, furnace=False, workers=1)
    lines = energy_statements(rep)
    assert any("furnace" in s for s in lines)
    # one line of maxima per mode, naming the number of curves of that mode
    for mode in ("furnace", "reflectance"):
        top = [s for s in lines if s.startswith(f"{mode}: ")]
        assert len(top) == 1 and "of 2 (preset, variant) curves exceed 1" in top[0]
    assert not any(s.startswith("white furnace") for s in lines)   # furnace=False


def _max(value, exceeds):
    return {"value": value, "error": 1e-3, "theta_deg": 60.0, "phi_deg": 90.0, "channel": 1,
            "exceeds_one": exceeds, "possibly_exceeds_one": exceeds}


def test_energy_statements_count_what_exceeds_one():
    """Hand-made curves and furnace rows: the counts and the worst case are the ones given."""
    class Rep:
        settings = {"modes": ["furnace"]}
        curves = [{"preset": p, "variant": "default", "mode": "furnace", "max": _max(v, v > 1),
                   "first_theta_above_one": None} for p, v in (("a", 0.9), ("b", 1.25))]
        furnace = [{"curves": "a", "parameter": "kd", "value": k, "variant": "default",
                    "furnace": _max(v, v > 1)} for k, v in ((0.0, 0.95), (1.0, 1.5))]

    lines = energy_statements(Rep())
    assert lines[0].startswith("furnace: with the presets' own colours, 1 of 2 ")
    assert "(b/default)" in lines[0] and "Largest: b/default 1.2500 +- 1.0e-03" in lines[0]
    assert lines[1] == "  furnace by variant: default: 1/2 presets above 1."
    assert "white furnace (furnace, A = 1): 1 of 2 configurations exceed 1." in lines
    assert any(s.startswith("  largest furnace albedo in the scan: 1.500 (+0.500 above 1)")
               for s in lines)


def test_reciprocity_statements_compare_variants():
    rep = reciprocity_report(["linen_plain"], ["default", "gap_outgoing"], n=500)
    lines = reciprocity_statements(rep)
    assert len(lines) == 1 and lines[0].startswith("linen_plain: median ")
    d = {r["variant"]: r["random"]["median"] for r in rep.rows}
    word = "lower" if d["gap_outgoing"] < d["default"] else "not lower"
    assert f"gap_outgoing median {d['gap_outgoing']:.3f} ({word})" in lines[0]
    assert math.isfinite(d["default"])


# -- the report's sentences: each kind on a case where it holds and one where it does not ------

import numpy as np  # noqa: E402

from analysis import albedo_curve  # noqa: E402
import brdf  # noqa: E402
from reports.prose import (albedo_exceeds, albedo_sentence, energy_summary,  # noqa: E402
                           energy_verdict, overview_sentence)

_T = [0.0, 60.0, 89.0]


def _grazing_reflectance(name):
    """The default variant's directional reflectance at theta_i = 0, 60, 89 deg, phi = 0."""
    c = albedo_curve(brdf.fabric(name), _T, 0.0, swap=True, workers=1)
    return np.asarray(c.value).reshape(3, -1), np.asarray(c.error).reshape(3, -1)


def test_the_reflectance_sentence_on_velvet_says_where_and_how_much_it_exceeds_one():
    """velvet's reflectance grows like 1/cos(theta_i) toward the horizon (prose._energy_grazing)
    and exceeds 1 at 89 deg; the sentence names that angle and the value computed here."""
    v, e = _grazing_reflectance("velvet")
    assert v[2].max() - e[2].max() > 1.0 > v[:2].max()     # independent of the sentence
    s = albedo_sentence("reflectance", _T, v, e)
    assert s.startswith("The directional reflectance ρ'(wi) exceeds 1 from θi = 89°, up to ")
    assert f"{v.max():.3f} at θi = 89°" in s
    assert "at or below" not in s


def test_the_reflectance_sentence_on_a_lambertian_half_albedo_says_at_or_below_one():
    """A Lambertian surface of albedo 0.5 reflects 0.5 from every direction."""
    v = np.full((3, 3), 0.5)
    s = albedo_sentence("reflectance", _T, v, np.full_like(v, 1e-4))
    assert "stays at or below 1" in s and "at most 0.500" in s and "exceeds" not in s


def test_the_furnace_sentence_both_ways_and_within_the_error():
    th = [0.0, 30.0, 60.0, 85.0]
    over = np.array([[0.9], [0.95], [1.2], [1.1]])
    s = albedo_sentence("furnace", th, over, np.full_like(over, 0.01))
    # 60 exceeds, 85 exceeds too: "from"; the maximum 1.2 is at 60
    assert "The furnace albedo ρ(wo) exceeds 1 from θo = 60°, up to 1.200 at θo = 60°." == s
    gap = np.array([[0.9], [1.2], [0.8], [1.1]])
    s = albedo_sentence("furnace", th, gap, np.full_like(gap, 0.01))
    assert "at 2 of the 4 angles θo on the grid, the first 30°" in s
    near = np.array([[0.9], [0.995], [0.9], [0.9]])
    s = albedo_sentence("furnace", th, near, np.full_like(near, 0.01))
    assert "within its error bound of 1" in s and "exceeds 1 " not in s


def test_verdicts_and_the_overview_sentence_count_what_exceeds():
    over = albedo_exceeds([0, 89], [[0.5], [4.6]], [[1e-3], [1e-3]])
    ok = albedo_exceeds([0, 89], [[0.5], [0.6]], [[1e-3], [1e-3]])
    assert energy_verdict(ok, over) == "reflectance exceeds 1 (up to 4.60 at θi = 89°)"
    assert energy_verdict(ok, ok) == "both albedos at or below 1"
    s = overview_sentence({"velvet": {"furnace": ok, "reflectance": over},
                           "linen": {"furnace": ok, "reflectance": ok}, "x": {}})
    assert "exceeds 1 for 1 of 2 fabrics (velvet up to 4.6 at θi = 89°)" in s
    assert "stays at or below 1 for all 2" in s
    s = overview_sentence({"linen": {"furnace": ok, "reflectance": ok}})
    assert "exceeds" not in s


def test_energy_summary_names_the_largest_reflectance_and_the_verdict():
    def curve(p, mode, top, variant="default"):
        v = np.full((2, 1, 3), 0.4)
        v[1, 0, 0] = top
        return {"preset": p, "variant": variant, "mode": mode, "theta_deg": [0.0, 89.0],
                "value": v.tolist(), "error": np.full_like(v, 1e-3).tolist(),
                "exceeds_one": top - 1e-3 > 1, "possibly_exceeds_one": top + 1e-3 > 1,
                "max": {"value": top, "error": 1e-3, "theta_deg": 89.0, "phi_deg": 0.0,
                        "channel": 0}}
    doc = {"settings": {"modes": ["furnace", "reflectance"]}, "furnace": [],
           "curves": [curve("velvet", "furnace", 0.85), curve("velvet", "reflectance", 4.6),
                      curve("linen", "furnace", 0.7), curve("linen", "reflectance", 0.8),
                      curve("linen", "reflectance", 1.3, "masking_off")]}
    lines = energy_summary(doc)
    assert lines[0] == ("velvet (default): ENERGY CREATED: reflectance exceeds 1 from "
                        "theta_i = 89 deg, up to 4.600")
    assert "largest 4.600 +- 1e-03 at theta_i = 89, phi = 0 (R)" in lines[1]
    assert "furnace albedo rho(wo) 0.400 - 0.850" in lines[2]
    assert lines[3] == "linen (default): ok: both albedos at or below 1"
    assert lines[-1] == "other variants: 1 of 1 curves exceed 1 (linen/masking_off/reflectance)."


def test_a_close_call_is_worded_as_one_and_alike_in_compare_and_the_measured_page():
    """Gaps of elpd in the words of reports.fitwords, used by `compare` and the measured
    page alike: within 2 se not separated; 2-2.7 se (naive or block) a close call that says
    why; past both, preferred."""
    from reports.cli.compare import format_table
    from reports.fitwords import gap_sentence
    from reports.report_measured import models_verdict
    cases = {  # d_elpd, d_se, block_se, lag1 -> words expected
        "apart": (1.2, 1.0, 1.1, 0.0, "The data cannot separate"),
        "close": (2.4, 1.0, 1.1, 0.05, "a close call"),
        "streaky": (5.0, 1.0, 3.0, 0.7, "a close call"),
        "firm": (8.0, 1.0, 1.2, 0.1, "is preferred over"),
    }
    for key, (d, se, block, lag, words) in cases.items():
        text = gap_sentence("A", "B", d, se, block_se=block, lag1=lag)
        assert words in text, (key, text)
        z, zb = d / se, d / block
        if words == "a close call":
            assert f"({z:.1f} se)" in text and f"the gap is {zb:.1f} se" in text
            assert f"lag-1 autocorrelation {lag:.2f}" in text
        rows = [dict(fit="A", model="m", elpd=10.0, se=2.0, d_elpd=0.0, d_se=0.0,
                     d_se_block=0.0, d_lag1=None, p_loo=1.0, n_high_k=0, k_threshold=0.62,
                     converged=True, adequate=True, values=50, table="t"),
                dict(fit="B", model="m", elpd=10.0 - d, se=2.0, d_elpd=d, d_se=se,
                     d_se_block=block, d_lag1=lag, p_loo=1.0, n_high_k=0, k_threshold=0.62,
                     converged=True, adequate=False, values=50, table="t")]
        assert gap_sentence("A (m)", "B (m)", d, se, block_se=block, lag1=lag) \
            in format_table(rows)
        page = models_verdict({"A": {"rank": 1, "d_elpd": 0.0, "d_se": 0.0},
                               "B": {"rank": 2, "d_elpd": d, "d_se": se,
                                     "d_se_block": block, "d_lag1": lag}})
        assert page == text + "."
    # a file without the block se (written before it was kept) still words a close call
    assert "treats the values as independent" in gap_sentence("A", "B", 2.4, 1.0)
