"""analysis.budget: pair counts of geometry specs without building them, the memory limit,
and the refusals of work too large for it (measure, info --step, fit --walkers)."""

import pytest

from analysis.budget import check_memory, memory_limit, spec_pairs
from gonio.geomspec import from_spec
from reports.cli import main


@pytest.mark.parametrize("spec", ["full:30", "full:45:90", "full:20:40:30:60", "rus:30",
                                  "rus:30:90:45:120", "merl:9", "merl:30"])
def test_spec_pairs_counts_what_from_spec_builds(spec):
    g = from_spec(spec)
    assert spec_pairs(spec) == len(g) + g.info.get("dropped_below_horizon", 0)


def test_spec_pairs_of_other_or_malformed_specs_is_none():
    for spec in ("plane:warp:5", "pairs:x.csv", "full:x", "full:-1", "full:nan", "sphere:3"):
        assert spec_pairs(spec) is None
    assert spec_pairs("full:1e-300") == float("inf")


def test_memory_limit_from_the_environment(monkeypatch):
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "2G")
    assert memory_limit() == (2 << 30, "MICROCYL_MEMORY_LIMIT")
    with pytest.raises(ValueError, match=r"^work would take about 3.0 GB of memory; the limit "
                                         r"is 2.0 GB \(MICROCYL_MEMORY_LIMIT\); do less$"):
        check_memory("work", 3 << 30, "do less")
    check_memory("work", 1 << 30, "do less")
    monkeypatch.delenv("MICROCYL_MEMORY_LIMIT")
    assert memory_limit()[0] > 0


@pytest.mark.parametrize("argv, start", [
    (["measure", "velvet", "--geometry", "full:0.5", "-o", "x.exr"],
     "microcyl measure: error: --geometry full:0.5 (1.66e+10 pairs) would take about 6.0 TB"),
    (["fit", "t.csv", "--fabric", "velvet", "--ensembles", "100000", "-o", "f"],
     "microcyl fit: error: --ensembles must be an integer in 2..64"),
])
def test_too_large_work_is_refused_before_it_starts(argv, start, tmp_path, monkeypatch,
                                                    capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "4G")
    assert main(argv) == 1
    assert capsys.readouterr().err.startswith(start)
    assert list(tmp_path.iterdir()) == []
