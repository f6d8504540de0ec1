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
