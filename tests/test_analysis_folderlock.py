"""Tests of analysis.folderlock: one lock per output whatever the kind of run, never opened
through a link, and a clean-up that removes microcyl's temporaries and nothing else."""

import os
from pathlib import Path

import pytest

import analysis.batch
import analysis.measured as measured
from analysis.folderlock import (LOCK_NAME, REPORT_MARKER, FolderBusy, lock_name, output_lock,
                                 remove_stale_temporaries)
from gonio.atomic import make_temporary_folder, open_temporary


def _temp_file(folder: Path, name: str) -> Path:
    fd, path = open_temporary(folder, name)
    os.write(fd, b"half")
    os.close(fd)
    return path


def test_every_kind_of_run_takes_the_same_lock_and_names_the_holder(tmp_path):
    for holder, other in [("report", "fit"), ("fit", "report"), ("batch", "fit-measured")]:
        with output_lock(tmp_path, holder):
            assert (tmp_path / LOCK_NAME).read_text() == f"{os.getpid()} {holder}\n"
            with pytest.raises(FolderBusy, match=f"^another {holder} is running in "
                                                 f"{tmp_path} \\(pid {os.getpid()}\\)"):
                with output_lock(tmp_path, other):
                    pass
        assert not (tmp_path / LOCK_NAME).exists()


@pytest.mark.parametrize("inside", [True, False])
def test_a_lock_that_is_a_link_is_refused_and_its_target_untouched(tmp_path, inside):
    target = tmp_path / "victim"
    target.write_text("precious")
    out = tmp_path / "out"
    if inside:
        out.mkdir()
        lock = out / LOCK_NAME
    else:
        lock = tmp_path / lock_name("out")
    lock.symlink_to(target)
    with pytest.raises(OSError, match=f"^lock file {lock} is a symbolic link"):
        with output_lock(out, "fit", inside=inside):
            pass
    assert target.read_text() == "precious" and lock.is_symlink()
    lock.unlink()
    lock.symlink_to(tmp_path / "nothing")                 # a dangling link: not created
    with pytest.raises(OSError, match="is a symbolic link"):
        with output_lock(out, "fit", inside=inside):
            pass
    assert not (tmp_path / "nothing").exists()


def test_a_hard_linked_lock_is_refused_and_its_target_untouched(tmp_path):
    target = tmp_path / "victim"
    target.write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    os.link(target, out / LOCK_NAME)
    with pytest.raises(OSError, match="is not a plain file of its own"):
        with output_lock(out, "fit"):
            pass
    assert target.read_text() == "precious"


def test_an_output_folder_that_is_a_link_is_refused(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "out").symlink_to(elsewhere)
    (tmp_path / "dangling").symlink_to(tmp_path / "missing")
    for out in (tmp_path / "out", tmp_path / "dangling"):
        with pytest.raises(OSError, match=f"^output folder {out} is a symbolic link"):
            with output_lock(out, "batch"):
                pass
    assert list(elsewhere.iterdir()) == [] and not (tmp_path / "missing").exists()


def test_a_fit_or_a_batch_refuses_a_report_folder_a_report_does_not(tmp_path):
    (tmp_path / REPORT_MARKER).write_text("{}")
    for what in ("fit", "batch"):
        with pytest.raises(ValueError, match=f"holds a microcyl report .* a {what} would be "
                                             f"deleted by the next report"):
            with output_lock(tmp_path, what):
                pass
    with output_lock(tmp_path, "report"):
        pass
    assert sorted(p.name for p in tmp_path.iterdir()) == [REPORT_MARKER]


def test_only_microcyl_temporaries_are_removed(tmp_path):
    mine = tmp_path / ".mydata.tmp"
    mine.mkdir()
    (mine / "a.csv").write_text("1")
    (tmp_path / ".notes.tmp").write_text("notes")
    (tmp_path / ".results.json.abcdefgh.tmp").write_text("an old-style name: not ours")
    (tmp_path / ".microcyl-x.0123456789ab.tmp.keep").write_text("not the pattern")
    stale = _temp_file(tmp_path, "results.json")
    folder = make_temporary_folder(tmp_path, "rep")       # a folder temporary: kept inside
    assert remove_stale_temporaries(tmp_path) == [stale]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [".mydata.tmp", ".notes.tmp", ".results.json.abcdefgh.tmp",
         ".microcyl-x.0123456789ab.tmp.keep", folder.name])


def test_a_named_clean_up_leaves_another_outputs_temporaries(tmp_path):
    """``rep``'s clean-up must not take the temporaries of ``rep.v2`` (another report)."""
    own, other = make_temporary_folder(tmp_path, "rep"), make_temporary_folder(tmp_path, "rep.v2")
    (own / "index.html").write_text("half")
    assert remove_stale_temporaries(tmp_path, "rep") == [own]
    assert other.is_dir()


def test_a_link_named_like_a_temporary_is_not_followed(tmp_path):
    target = tmp_path / "target"
    target.mkdir()
    (target / "precious").write_text("x")
    out = tmp_path / "out"
    out.mkdir()
    link = out / ".microcyl-x.0123456789ab.tmp"
    link.symlink_to(target)
    beside = tmp_path / ".microcyl-out.0123456789ab.tmp"
    beside.symlink_to(target)
    with output_lock(out, "fit"):
        pass
    assert (target / "precious").read_text() == "x"
    assert link.is_symlink() and beside.is_symlink()       # not microcyl's: left alone


def test_a_new_holder_keeps_its_lock_when_the_old_one_ends(tmp_path):
    """A report renames its old folder away while it holds the lock inside it: ending, it
    must not remove the lock a new run took in the new folder."""
    out = tmp_path / "R"
    first = output_lock(out, "report")
    first.__enter__()
    os.replace(out, tmp_path / "old")
    out.mkdir()
    second = output_lock(out, "fit")
    second.__enter__()
    first.__exit__(None, None, None)                      # the old holder ends
    assert (out / LOCK_NAME).read_text() == f"{os.getpid()} fit\n"
    with pytest.raises(FolderBusy, match="another fit is running"):
        with output_lock(out, "batch"):
            pass
    second.__exit__(None, None, None)
    assert not (out / LOCK_NAME).exists()


def test_fit_measured_takes_the_lock_through_measured_json(tmp_path, monkeypatch):
    seen = []

    def fake_run_batch(jobs, out, *, locked, **kw):
        seen.append((locked, (Path(out) / LOCK_NAME).read_text().split()[1]))
        raise KeyboardInterrupt                          # stop here: no fit, no json

    monkeypatch.setattr(measured, "load_measured", lambda n, root, rgl_step: None)
    monkeypatch.setattr(analysis.batch, "run_batch", fake_run_batch)
    name = next(iter(measured.MEASURED))
    with output_lock(tmp_path, "report"):
        with pytest.raises(FolderBusy, match="another report is running"):
            measured.fit_measured([name], tmp_path, data_dir=tmp_path)
    assert seen == []
    with pytest.raises(KeyboardInterrupt):
        measured.fit_measured([name], tmp_path, data_dir=tmp_path)
    assert seen == [(True, "fit-measured")]
