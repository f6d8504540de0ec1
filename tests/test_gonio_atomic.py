"""Atomic writes leave nothing behind when the writer fails midway, even on Ctrl-C."""

import numpy as np
import pytest

import gonio
from gonio.atomic import atomic_write, is_temporary
from tests._gonio_helpers import random_table


@pytest.mark.parametrize("exc", [RuntimeError, KeyboardInterrupt])
def test_nothing_left_behind(tmp_path, exc):
    with pytest.raises(exc):
        with atomic_write(tmp_path / "x.bin") as f:
            f.write(b"half of it")
            raise exc()
    assert list(tmp_path.iterdir()) == []


def test_old_file_kept_when_writer_fails(tmp_path, monkeypatch):
    p = tmp_path / "t.csv"
    gonio.write(random_table(0), p)
    before = p.read_bytes()

    calls = {"n": 0}
    real = gonio.csvwrite.format_numbers

    def boom(x, *a, **k):  # fails after some rows were written (100 rows, 10 columns a time)
        calls["n"] += 1
        if calls["n"] > 20:
            raise KeyboardInterrupt
        return real(x, *a, **k)

    monkeypatch.setattr("gonio.csvwrite.format_numbers", boom)
    monkeypatch.setattr("gonio.csvwrite._WRITE_ROWS", 100)
    with pytest.raises(KeyboardInterrupt):
        gonio.write(random_table(1, n=500), p)
    monkeypatch.undo()
    assert p.read_bytes() == before
    assert sorted(x.name for x in tmp_path.iterdir()) == ["t.csv"]


def test_exr_and_merl_writers_clean_up(tmp_path, monkeypatch):
    class Broken:
        def __init__(self):
            self.n = 0

        def eval(self, wi, wo):
            self.n += 1
            if self.n > 3:
                raise RuntimeError("model failed midway")
            return np.full(np.shape(wi), 0.1)

    with pytest.raises(RuntimeError, match="midway"):
        gonio.write(Broken(), tmp_path / "m.binary", rotations=1)
    import OpenEXR

    def failing_write(self, name):
        open(name, "wb").write(b"partial")
        raise RuntimeError("disk full")

    monkeypatch.setattr(OpenEXR.File, "write", failing_write)
    with pytest.raises(RuntimeError, match="disk full"):
        gonio.write(random_table(2), tmp_path / "t.exr")
    assert list(tmp_path.iterdir()) == []


def test_errors_name_the_users_path_not_the_temporary_file(tmp_path, monkeypatch):
    """A missing folder, a folder in the file's place, a failing rename or an OSError about
    the temporary file inside the writer: the error names the destination."""
    (tmp_path / "d.csv").mkdir()
    for target in (tmp_path / "missing" / "t.csv", tmp_path / "d.csv"):
        with pytest.raises(OSError) as info:
            gonio.write(random_table(0), target)
        assert info.value.filename == str(target) and ".tmp" not in str(info.value)
    dest = tmp_path / "t.csv"

    def fail(src, dst):
        raise PermissionError(13, "Permission denied", str(src), None, str(dst))

    monkeypatch.setattr("gonio.atomic.os.replace", fail)
    with pytest.raises(PermissionError, match="cannot write: Permission denied") as info:
        gonio.write(random_table(0), dest)
    assert info.value.filename == str(dest) and ".tmp" not in str(info.value)
    monkeypatch.undo()
    with pytest.raises(OSError) as info:
        with atomic_write(dest) as f:
            raise OSError(28, "No space left on device", str(f.tmp_path))
    assert info.value.filename == str(dest)
    with pytest.raises(FileNotFoundError) as info:      # the writer's own errors pass as they are
        with atomic_write(dest):
            open(tmp_path / "other.bin", "rb")
    assert info.value.filename == str(tmp_path / "other.bin")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.csv"]


def test_temporaries_are_microcyl_named_and_never_open_an_existing_name(tmp_path, monkeypatch):
    """A planted link at the next temporary's name is skipped, not written through; the
    temporary that is used carries the microcyl prefix and is gone after the rename."""
    victim = tmp_path / "victim"
    victim.write_text("precious")
    tokens = iter(["0123456789ab", "0123456789ab", "ba9876543210"])
    monkeypatch.setattr("gonio.atomic.secrets.token_hex", lambda n: next(tokens))
    planted = tmp_path / ".microcyl-t.bin.0123456789ab.tmp"
    planted.symlink_to(victim)
    seen = []
    with atomic_write(tmp_path / "t.bin") as f:
        seen.append(f.tmp_path.name)
        f.write(b"data")
    assert seen == [".microcyl-t.bin.ba9876543210.tmp"]
    assert victim.read_text() == "precious" and planted.is_symlink()
    assert (tmp_path / "t.bin").read_bytes() == b"data"
    assert is_temporary(seen[0], "t.bin") and is_temporary(seen[0])
    assert not is_temporary(".t.bin.abcdefgh.tmp") and not is_temporary(".notes.tmp")
