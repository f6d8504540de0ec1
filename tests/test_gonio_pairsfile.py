"""Tests of the plan file (gonio/pairsfile.py) and its arm-travel order (gonio/travel.py): the writer, the header
reader, and the file read back by gonio.geomspec.read_pairs_csv (``pairs:FILE``)."""

import math

import numpy as np
import pytest

from gonio import FormatError, measure
from gonio.geomspec import read_pairs_csv
from gonio.pairsfile import (MAX_HEADER_BYTES, order_for_travel, read_pairs_header, travel,
                             write_pairs_csv)


def _uniform(n, seed):
    """n pairs uniform in solid angle over the hemisphere, degrees."""
    rng = np.random.default_rng(seed)
    t = np.degrees(np.arccos(1 - rng.random((n, 2))))
    p = rng.uniform(0, 360, (n, 2))
    return np.stack([t[:, 0], p[:, 0], t[:, 1], p[:, 1]], axis=1)


def _arc(t1, p1, t2, p2):
    """Great-circle angle in degrees, by the spherical law of cosines (written out)."""
    t1, p1, t2, p2 = map(math.radians, (t1, p1, t2, p2))
    c = math.cos(t1) * math.cos(t2) + math.sin(t1) * math.sin(t2) * math.cos(p1 - p2)
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def test_travel_is_the_sum_of_both_arms_great_circle_moves():
    a = np.array([[30, 0, 30, 180], [30, 0, 60, 180], [40, 90, 60, 0], [0, 0, 10, 45]], float)
    ref = sum(_arc(*a[k, :2], *a[k + 1, :2]) + _arc(*a[k, 2:], *a[k + 1, 2:])
              for k in range(3))
    assert math.isclose(travel(a), ref, rel_tol=1e-9)
    assert math.isclose(travel(a, [3, 2, 1, 0]), ref, rel_tol=1e-9)
    assert travel(a[:1]) == 0.0


def test_order_beats_the_input_order_and_random_orders_on_a_uniform_set():
    a = _uniform(150, seed=5)
    order = order_for_travel(a)
    assert sorted(order.tolist()) == list(range(150))
    assert np.array_equal(order, order_for_travel(a))             # deterministic
    rng = np.random.default_rng(0)
    best_random = min(travel(a, rng.permutation(150)) for _ in range(20))
    assert travel(a, order) < 0.5 * travel(a)
    assert travel(a, order) < 0.5 * best_random


def test_order_groups_sources_and_sweeps_each_plane_back_and_forth():
    """An in-plane geometry shuffled: each source position once, its detectors swept
    monotonically along the plane, consecutive sweeps in opposite directions."""
    a = np.array([[ti, 0.0, to, po] for ti in (0.0, 20.0, 40.0, 60.0)
                  for to in np.arange(0.0, 90.0, 10.0) for po in (0.0, 180.0)
                  if to > 0 or po == 0])
    a = a[np.random.default_rng(1).permutation(len(a))]
    o = order_for_travel(a)
    b = a[o]
    src = [tuple(r) for r in np.round(b[:, :2], 9)]
    blocks = [k for k in range(len(src)) if k == 0 or src[k] != src[k - 1]]
    assert len(blocks) == 4 == len(set(src))                     # each source once
    # signed in-plane angle of the detector: + toward phi_i, - opposite
    signed = np.where(np.isclose(np.cos(np.radians(b[:, 3] - b[:, 1])), 1.0), b[:, 2], -b[:, 2])
    directions = []
    for s, e in zip(blocks, blocks[1:] + [len(b)]):
        d = np.diff(signed[s:e])
        assert (d > 0).all() or (d < 0).all()
        directions.append(np.sign(d[0]))
    assert all(x != y for x, y in zip(directions, directions[1:]))   # boustrophedon
    assert travel(b) < travel(a)


def test_write_then_read_pairs_csv_round_trips_the_angles(tmp_path):
    a = _uniform(40, seed=2)
    a[0] = [0, 0, 0, 0]
    a[1] = [89.9999, -359.5, 89.999999, 359.999999999]
    path = write_pairs_csv(tmp_path / "plan.csv", a, {"fabric": "velvet", "free": "gamma1,kd1"},
                           columns={"sd_gamma1": np.linspace(0, 1, 40), "note": ["x"] * 40})
    assert path == tmp_path / "plan.csv"
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# microcyl measurement plan.")
    assert lines[1:3] == ["# fabric: velvet", "# free: gamma1,kd1"]
    assert lines[3] == "index,theta_i,phi_i,theta_o,phi_o,sd_gamma1,note"
    rows = [r.split(",") for r in lines[4:]]
    assert [int(r[0]) for r in rows] == list(range(1, 41))
    perm = order_for_travel(a)
    back = np.array([[float(x) for x in r[1:5]] for r in rows])
    assert np.array_equal(back, a[perm])                         # exact
    assert np.allclose([float(r[5]) for r in rows], np.linspace(0, 1, 40)[perm], atol=0)
    g = read_pairs_csv(path)                                     # the pairs: reader
    got = np.degrees(np.stack([g.coords[k] for k in ("theta_i", "phi_i", "theta_o", "phi_o")],
                              axis=1))
    assert len(g) == 40 and np.abs(got - a[perm]).max() < 1e-9
    assert read_pairs_header(path) == {"fabric": "velvet", "free": "gamma1,kd1"}


def test_write_in_the_given_order_and_measure_reads_it(tmp_path):
    a = np.array([[30, 0, 60, 180], [30, 0, 30, 180], [0, 0, 45, 90]], float)
    path = write_pairs_csv(tmp_path / "p.csv", a, order=False)

    class Grey:
        def eval(self, wi, wo):
            return np.full(wi.shape[:-1] + (3,), 0.2)
    t = measure(Grey(), f"pairs:{path}")
    assert len(t) == 3 and np.allclose(np.degrees(t.angles[:, 2]), [60, 30, 45])


def test_header_values_stay_one_line(tmp_path):
    path = write_pairs_csv(tmp_path / "p.csv", [[30, 0, 30, 180]],
                           {"fabric": "evil\nindex,theta_i\r\x00\u2028", "n": 3})
    text = path.read_text()
    assert text.count("\n") == 5 and "\r" not in text and "\u2028" not in text
    h = read_pairs_header(path)
    assert h["n"] == "3" and "\n" not in h["fabric"] and h["fabric"].startswith("evil\\n")
    assert len(read_pairs_csv(path)) == 1


@pytest.mark.parametrize("kwargs, match", [
    ({"angles_deg": [[30, 0, 95, 0]]}, r"^angles_deg row 1: theta_o 95.0 outside \[0, 90\)"),
    ({"angles_deg": [[90, 0, 30, 0]]}, r"^angles_deg row 1: theta_i 90.0 outside \[0, 90\) "
                                       r"\(above the horizon"),
    ({"angles_deg": [[30, 400, 30, 0]]}, r"^angles_deg row 1: phi_i 400.0 outside \[-360, 360\]"),
    ({"angles_deg": [[30, 0, 30]]}, r"^angles_deg must be an \(n, 4\) array"),
    ({"angles_deg": np.zeros((0, 4))}, "no pairs"),
    ({"angles_deg": [[30, 0, math.nan, 0]]}, "row 1 is not finite"),
    ({"header": {"bad key": "x"}}, "^header key 'bad key' must be a name"),
    ({"columns": {"theta_i": [1.0]}}, "^column name 'theta_i' must be"),
    ({"columns": {"sd": [1.0, 2.0]}}, r"^column 'sd' must have one value a pair \(1\)"),
    ({"columns": {"note": ["a,b"]}}, r"^column 'note', pair 1: 'a,b' must be printable"),
])
def test_bad_input_is_refused_before_anything_is_written(tmp_path, kwargs, match):
    args = {"angles_deg": [[30, 0, 30, 180]], **kwargs}
    with pytest.raises(ValueError, match=match):
        write_pairs_csv(tmp_path / "p.csv", **args)
    assert list(tmp_path.iterdir()) == []


def test_read_pairs_header_is_bounded_and_says_what_is_wrong(tmp_path):
    big = tmp_path / "big.csv"
    big.write_text("# a: 1\n" + ("# pad: " + "x" * 1000 + "\n") * (MAX_HEADER_BYTES // 1000))
    with pytest.raises(FormatError, match=r"big.csv: comment lines longer than"):
        read_pairs_header(big)
    long_rows = tmp_path / "rows.csv"
    long_rows.write_text("# a: 1\nindex,theta_i\n" + "1,2\n" * 400_000)
    assert read_pairs_header(long_rows) == {"a": "1"}
    bad = tmp_path / "bad.csv"
    bad.write_bytes(b"# a: \xff\n")
    with pytest.raises(FormatError, match=r"bad.csv: line 1: not UTF-8"):
        read_pairs_header(bad)
    with pytest.raises(OSError, match="cannot read plan file"):
        read_pairs_header(tmp_path)
    with pytest.raises(OSError, match="cannot read plan file"):
        read_pairs_header(tmp_path / "missing.csv")


def test_large_sets_fall_back_to_nearest_neighbour_then_serpentine(monkeypatch):
    """Beyond MAX_TOUR nodes no 2-opt (still far better than random on a uniform set),
    beyond MAX_GREEDY a serpentine over the sources (still a permutation, sources grouped)."""
    import gonio.travel
    monkeypatch.setattr(gonio.travel, "MAX_TOUR", 10)
    monkeypatch.setattr(gonio.travel, "MAX_GREEDY", 100)
    a = _uniform(90, seed=7)
    o = order_for_travel(a)
    rng = np.random.default_rng(1)
    assert sorted(o.tolist()) == list(range(90))
    assert travel(a, o) < 0.5 * min(travel(a, rng.permutation(90)) for _ in range(10))
    b = np.repeat(_uniform(150, seed=8)[:, :2], 2, axis=0)            # 150 sources, 2 each
    b = np.column_stack([b, _uniform(300, seed=9)[:, 2:]])
    o = order_for_travel(b)
    assert sorted(o.tolist()) == list(range(300))
    src = [tuple(r) for r in b[o, :2]]
    assert sum(src[k] != src[k - 1] for k in range(1, 300)) == 149   # each source once
