"""gonio.safenames: names from files refused or made safe, paths kept inside their folder."""

import os

import pytest

from gonio.safenames import (MAX_BYTES, MAX_CHARS, check_component, check_inside,
                             name_problem, safe_component)

HOSTILE = ["..", ".", "", "/etc/passwd", "../../escape_target", "a/b", "a\\b", ".bashrc",
           "x\x00y", "x\ny", "evil\u202egnp.exe", "C:evil", "a" * (MAX_CHARS + 1),
           "é" * (MAX_BYTES // 2 + 1), " lead", "trail ", "a|b", "\udcff"]
GOOD = ["t0", "curet_44_linen", "my table", "silk-2", "Æble_ø", "x.y", "a" * MAX_CHARS]


@pytest.mark.parametrize("name", HOSTILE)
def test_hostile_names_are_refused_in_one_line_naming_file_and_entry(name):
    assert name_problem(name) is not None
    with pytest.raises(ValueError) as err:
        check_component(name, source="DIR/measured.json", entry="datasets")
    msg = str(err.value)
    assert msg.startswith("DIR/measured.json: datasets: name ") and msg.endswith("; refused")
    assert "\n" not in msg


@pytest.mark.parametrize("name", [None, 3, ["a"]])
def test_a_name_that_is_not_a_string_is_refused(name):
    with pytest.raises(ValueError, match="not a string"):
        check_component(name, source="f.json", entry="tables[0].name")


@pytest.mark.parametrize("name", GOOD)
def test_safe_names_pass_unchanged(name):
    assert check_component(name, source="f", entry="e") == name
    assert safe_component(name) == name


@pytest.mark.parametrize("name", HOSTILE)
def test_sanitized_names_are_safe_single_components(name, tmp_path):
    out = safe_component(name)
    assert name_problem(out) is None
    assert os.sep not in out and out not in (".", "..") and not out.startswith(".")
    # and they really make one entry of the folder, inside it
    path = tmp_path / out
    path.mkdir()
    assert [p.name for p in tmp_path.iterdir()] == [out]
    assert check_inside(path, tmp_path) == path.resolve()


def test_distinct_names_stay_distinct_after_sanitizing():
    names = ["a/b", "a\\b", "a_b", "a|b", "..", "...", ".a_b", "a" * 200, "a" * 201]
    out = [safe_component(n) for n in names]
    assert len(set(out)) == len(names)
    assert safe_component("a/b") == safe_component("a/b")          # and stable


def test_check_inside_follows_links(tmp_path):
    root = tmp_path / "out"
    (root / "sub").mkdir(parents=True)
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (root / "link").symlink_to(outside, target_is_directory=True)
    (root / "file_link").symlink_to(tmp_path / "target.txt")
    assert check_inside(root / "sub" / "x.json", root) == (root / "sub" / "x.json").resolve()
    for bad in (root / "link" / "x.json", root / "file_link", root / ".." / "x",
                tmp_path / "x", "/etc/passwd"):
        with pytest.raises(ValueError, match="outside .*; refused"):
            check_inside(bad, root, source="summary.json", entry="tables[0].folder")
    with pytest.raises(ValueError, match=r"^summary\.json: tables\[0\]\.folder: "):
        check_inside(root / "link", root, source="summary.json", entry="tables[0].folder")
