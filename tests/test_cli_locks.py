"""One lock per output, no link followed, nothing removed that microcyl did not write: fit,
report and convert as a user runs them (subprocesses, real folders), against folders that hold
another kind of output, a planted symbolic link, or a user's own ``.tmp`` files."""

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

import brdf
import gonio
from analysis.folderlock import output_lock
from reports import report as rep
from reports_standin import Phongish

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(REPO), PYTHONUNBUFFERED="1")
FIT = ("--fabric", "silk_crepe_de_chine", "--free", "kd1,gamma_s1", "--max-steps", "300",
       "--no-plots", "--no-progress")


def microcyl(*args):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], cwd=REPO,
                          env=ENV, capture_output=True, text=True, timeout=600)


def listing(folder: Path) -> dict:
    """Every entry under ``folder`` (links not followed) -> its bytes, or None for a folder."""
    out = {}
    for p in sorted(folder.rglob("*")):
        rel = str(p.relative_to(folder))
        out[rel] = None if p.is_dir() and not p.is_symlink() else (
            os.readlink(p) if p.is_symlink() else p.read_bytes())
    return out


def last_line(r) -> str:
    lines = r.stderr.strip().splitlines()
    return lines[-1] if lines else ""


@pytest.fixture(scope="module")
def table_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("locks") / "silk.csv"
    table = gonio.measure(brdf.fabric("silk_crepe_de_chine"), "full:30:60",
                          gonio.Instrument(snr=20, floor=1e-4), seed=3, progress=False)
    gonio.write(table, path)
    return path


@pytest.fixture(scope="module")
def fit_dir(table_csv, tmp_path_factory):
    """A finished short fit, as `microcyl fit -o DIR` writes it."""
    out = tmp_path_factory.mktemp("fitted") / "fit"
    r = microcyl("fit", table_csv, *FIT, "-o", out)
    assert r.returncode == 0, r.stderr
    return out


def small_report(out: Path) -> Path:
    """A report folder as `microcyl report` writes it (one stand-in fabric, one section)."""
    rep.build_report({"a": Phongish()}, out, quality="fast", progress=False,
                     sections=["parameters"])
    return out


def test_a_fit_into_a_report_folder_is_refused_and_the_report_kept(table_csv, tmp_path):
    """Problem 5 of issue 24: a report, then a fit into the same folder."""
    out = small_report(tmp_path / "R")
    before = listing(out)
    r = microcyl("fit", table_csv, *FIT, "-o", out)
    assert r.returncode == 1, r.stdout
    assert last_line(r) == (f"microcyl fit: error: output folder {out} holds a microcyl "
                            f"report (.microcyl-report); a fit would be deleted by the next "
                            f"report there; choose another folder")
    assert len(r.stderr.strip().splitlines()) == 1
    assert listing(out) == before


def test_a_report_refuses_a_folder_holding_a_fit_naming_its_files(fit_dir, tmp_path):
    before = listing(fit_dir)
    r = microcyl("report", "--fabric", "velvet", "--quality", "fast", "--quiet", "-o", fit_dir)
    assert r.returncode == 1
    assert last_line(r) == (
        f"microcyl report: error: output folder {fit_dir} holds a fit (checkpoint.h5, "
        f"fit_config.json, results.csv, results.json), not a microcyl report; a report "
        f"replaces its folder whole: remove it or choose another")
    assert listing(fit_dir) == before


def test_a_report_refuses_a_report_folder_a_fit_was_written_into(tmp_path):
    """Today's main let a fit into a report folder; the next report must not sweep it away."""
    out = small_report(tmp_path / "R")
    (out / "fit_config.json").write_text("{}")
    (out / "checkpoint.h5").write_bytes(b"x")
    before = listing(out)
    with pytest.raises(ValueError, match=r"holds a fit \(checkpoint.h5, fit_config.json\)"):
        small_report(out)
    assert listing(out) == before
    marker = json.loads((out / ".microcyl-report").read_text())    # a marker that lies
    marker["files"] += ["fit_config.json", "checkpoint.h5"]
    (out / ".microcyl-report").write_text(json.dumps(marker))
    with pytest.raises(ValueError, match=r"holds a fit \(checkpoint.h5, fit_config.json\)"):
        small_report(out)


def test_a_report_refuses_a_batch_and_unknown_files(tmp_path):
    batch = tmp_path / "B"
    batch.mkdir()
    (batch / "summary.json").write_text('{"tables": []}')
    (batch / "summary.csv").write_text("name\n")
    with pytest.raises(ValueError, match=r"holds a batch \(summary.csv, summary.json\)"):
        small_report(batch)
    out = small_report(tmp_path / "R")
    (out / "notes.txt").write_text("mine")
    (out / "a" / "mine.png").write_bytes(b"mine")
    with pytest.raises(ValueError, match=r"holds files a report did not write \(a/mine.png, "
                                         r"notes.txt\)"):
        small_report(out)
    assert (out / "notes.txt").read_text() == "mine"


def test_a_report_replaces_its_own_previous_report(tmp_path):
    out = small_report(tmp_path / "R")
    rep.build_report({"b": Phongish()}, out, quality="fast", progress=False,
                     sections=["parameters"])
    assert (out / "b.html").is_file() and not (out / "a.html").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["R"]      # no temporaries left


def test_a_report_and_a_fit_take_the_same_lock(tmp_path):
    out = tmp_path / "F"
    with output_lock(out, "fit"):
        r = microcyl("report", "--fabric", "velvet", "--quality", "fast", "--quiet", "-o", out)
    assert r.returncode == 1
    assert last_line(r) == (f"microcyl report: error: another fit is running in {out} "
                            f"(pid {os.getpid()}); wait for it to end or use another output")
    out = tmp_path / "R"
    with output_lock(out, "report"):
        with pytest.raises(Exception, match=f"another report is running in {out}"):
            with output_lock(out, "batch"):
                pass


def test_a_planted_lock_link_is_refused_and_its_target_untouched(table_csv, tmp_path):
    """Problem 2 of issue 24: `.microcyl.lock` a symbolic link to a file outside."""
    target = tmp_path / "authorized_keys"
    target.write_text("ssh-ed25519 AAAA precious\n")
    out = tmp_path / "F"
    out.mkdir()
    (out / ".microcyl.lock").symlink_to(target)
    r = microcyl("fit", table_csv, *FIT, "-o", out)
    assert r.returncode == 1
    assert last_line(r) == (f"microcyl fit: error: lock file {out / '.microcyl.lock'} is a "
                            f"symbolic link; microcyl never opens one: remove it")
    assert target.read_text() == "ssh-ed25519 AAAA precious\n"
    out = small_report(tmp_path / "R")
    (out / ".microcyl.lock").symlink_to(target)
    r = microcyl("report", "--fabric", "velvet", "--quality", "fast", "--quiet", "-o", out)
    assert r.returncode == 1 and "is a symbolic link" in last_line(r)
    assert target.read_text() == "ssh-ed25519 AAAA precious\n"


def test_a_planted_file_lock_link_is_refused(table_csv, tmp_path):
    target = tmp_path / "victim.txt"
    target.write_text("precious")
    out = tmp_path / "o.exr"
    (tmp_path / ".microcyl-o.exr.lock").symlink_to(target)
    r = microcyl("convert", table_csv, out)
    assert r.returncode == 1 and "is a symbolic link" in last_line(r)
    assert target.read_text() == "precious" and not out.exists()


def test_an_output_folder_that_is_a_link_is_refused(table_csv, tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "F").symlink_to(elsewhere, target_is_directory=True)
    r = microcyl("fit", table_csv, *FIT, "-o", tmp_path / "F")
    assert r.returncode == 1
    assert last_line(r) == (f"microcyl fit: error: output folder {tmp_path / 'F'} is a "
                            f"symbolic link; give the folder itself or another")
    assert list(elsewhere.iterdir()) == []


def test_a_fit_keeps_a_users_tmp_files_and_removes_its_own(table_csv, tmp_path):
    """Problem 6 of issue 24: `.mydata.tmp/` and `.notes.tmp` are the user's."""
    out = tmp_path / "F"
    (out / ".mydata.tmp").mkdir(parents=True)
    (out / ".mydata.tmp" / "run1.csv").write_text("1,2,3\n")
    (out / ".notes.tmp").write_text("notes")
    (out / ".checkpoint.h5.abcdefgh.tmp").write_text("looks like the old pattern: not ours")
    code = ("import os, signal, sys; from gonio import atomic_write\n"
            "with atomic_write(sys.argv[1]) as f:\n"
            "    f.write(b'half'); f.flush(); os.kill(os.getpid(), signal.SIGKILL)\n")
    subprocess.run([sys.executable, "-c", code, str(out / "checkpoint.h5")], env=ENV, cwd=REPO)
    stale = [p for p in out.iterdir() if p.name.startswith(".microcyl-checkpoint.h5.")]
    assert len(stale) == 1                      # a killed fit's temporary
    stale = stale[0]
    r = microcyl("fit", table_csv, *FIT, "-o", out)
    # the user's files: a fit does not write where they are (issue 35), and keeps them
    assert r.returncode == 1 and last_line(r).endswith(
        "holds files a fit did not write (.checkpoint.h5.abcdefgh.tmp, .mydata.tmp, "
        ".notes.tmp); a fit replaces its files there: move them away or choose another "
        "folder"), r.stderr
    assert (out / ".mydata.tmp" / "run1.csv").read_text() == "1,2,3\n"
    assert (out / ".notes.tmp").read_text() == "notes"
    assert (out / ".checkpoint.h5.abcdefgh.tmp").exists()
    for mine in (".mydata.tmp", ".notes.tmp", ".checkpoint.h5.abcdefgh.tmp"):
        shutil.move(out / mine, tmp_path / mine)
    r = microcyl("fit", table_csv, *FIT, "-o", out)
    assert r.returncode == 0, r.stderr
    assert not stale.exists()                   # the killed fit's temporary: removed
    assert (out / "results.json").is_file()
    assert (tmp_path / ".mydata.tmp" / "run1.csv").read_text() == "1,2,3\n"


def test_the_batch_page_takes_the_batch_folders_lock(tmp_path):
    out = tmp_path / "B"
    with output_lock(out, "batch"):
        r = microcyl("report", "--batch", out)
    assert r.returncode == 1
    assert last_line(r) == (f"microcyl report: error: another batch is running in {out} "
                            f"(pid {os.getpid()}); wait for it to end or use another output")
    assert list(out.iterdir()) == []


def test_a_killed_report_leaves_what_the_next_report_removes(tmp_path):
    """SIGKILL mid-build: the lock and the build folder stay behind; the next report takes
    the lock over, removes the build folder and writes its own."""
    out = tmp_path / "R"
    proc = subprocess.Popen([sys.executable, "-m", "reports", "report", "--fabric", "velvet",
                             "--quality", "fast", "--engine", "builtin", "--quiet",
                             "-o", str(out)], cwd=REPO, env=ENV, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not any(
                p.name.startswith(".microcyl-R.") and any(p.iterdir())
                for p in tmp_path.iterdir() if p.is_dir()):
            time.sleep(0.05)
    finally:
        proc.kill()
        proc.wait(timeout=60)
    left = sorted(p.name for p in tmp_path.iterdir())
    assert len(left) == 2 and left[0].startswith(".microcyl-R.") and left[1] == "R"
    assert [p.name for p in out.iterdir()] == [".microcyl.lock"]
    small_report(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["R"]
    assert (out / "a.html").is_file() and not (out / ".microcyl.lock").exists()
