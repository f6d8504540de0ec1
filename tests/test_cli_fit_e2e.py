"""``microcyl fit`` run as a user runs it: a subprocess, progress on (a line a check to a pipe), an
``-o`` folder, a table of thousands of pairs; killed with SIGKILL and resumed; Ctrl-C; and the
threading rule (no file opened by two threads) checked directly."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import brdf
import gonio
from analysis.fit import FabricModel, FitFolder, fit
from analysis.fit import progress as fit_progress
from analysis.params import ParamSpec, defaults_from_fabric
from _fitmodels import fabric_table
from _signals import default_sigint

REPO = Path(__file__).resolve().parents[1]


def _cli(*args, **kw):
    """Popen of ``python -m reports ...`` in the repository, stdout and stderr piped."""
    env = dict(os.environ, PYTHONPATH=str(REPO), PYTHONUNBUFFERED="1")
    return subprocess.Popen([sys.executable, "-m", "reports", *map(str, args)], cwd=REPO,
                            preexec_fn=default_sigint,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, **kw)


@pytest.fixture(scope="module")
def silk_csv(tmp_path_factory):
    """A simulated gonioreflectometer table of silk: 3,721 direction pairs (``full:15:30``),
    SNR 20 with a 1e-4 1/sr floor, written as a CSV file the way a user would have it."""
    fab = brdf.fabric("silk_crepe_de_chine")
    table = gonio.measure(fab, "full:15:30", gonio.Instrument(snr=20, floor=1e-4), seed=3,
                          progress=False)
    path = tmp_path_factory.mktemp("table") / "silk.csv"
    gonio.write(table, path)
    return path, table


def test_fit_with_progress_bar_to_convergence(silk_csv, tmp_path):
    """The command of the bug report: it died after 4 to 183 steps with 'file is already open
    for read-only' while the progress bar read the checkpoints."""
    path, table = silk_csv
    assert len(table) > 3000
    out = tmp_path / "fit"
    free = "kd1,gamma_s1,gamma_v1,albedo1_r,albedo1_g,albedo1_b"
    p = _cli("fit", path, "--fabric", "silk_crepe_de_chine", "--free", free, "-o", out)
    stdout, stderr = p.communicate(timeout=900)
    assert p.returncode == 0, stderr[-2000:]
    assert "emcee: step" in stderr and "\r" not in stderr  # one line a check on the pipe
    assert "error" not in stderr.lower()
    doc = json.loads((out / "results.json").read_text())
    assert doc["converged"] is True, doc["reason"]
    truth = defaults_from_fabric(brdf.fabric("silk_crepe_de_chine"))
    par = doc["parameters"]
    # the simulation's truth within 4 posterior standard deviations of each median
    for name in free.split(","):
        sd = (par[name]["hi95"] - par[name]["lo95"]) / 3.92
        assert abs(par[name]["median"] - truth[name]) < 4 * sd, (name, par[name])
    assert set(doc["plots"]) == {"corner", "traces", "lobes", "residuals", "adequacy", "pit"}
    assert all((out / f"{k}.png").stat().st_size > 1000 for k in doc["plots"])
    assert "CONVERGED" in stdout and f"results: {out / 'results.json'}" in stdout
    # no temporary; the marker listing what the fit wrote (issue 35: a resume's own files)
    assert sorted(q.name for q in out.iterdir() if q.name.startswith(".")) == [".microcyl-fit"]
    listed = json.loads((out / ".microcyl-fit").read_text())["files"]
    assert {q.name for q in out.iterdir()} - {".microcyl-fit"} <= set(listed)


def test_only_the_calling_thread_opens_files(monkeypatch, tmp_path):
    """The threading rule, provoked deterministically: a slow model keeps the ensemble threads
    stepping while the progress bar polls (every 0.25 s), and every h5py.File opened during the
    fit is recorded with its thread. Today's rule: one thread, the caller's, opens them all
    (before, the progress bar opened the checkpoints that the ensemble threads were writing)."""
    import h5py
    opened = []
    real = h5py.File

    class Recording(real):
        def __init__(self, name, *a, **kw):
            opened.append((str(getattr(name, "name", name)), threading.get_ident()))
            super().__init__(name, *a, **kw)

    monkeypatch.setattr(h5py, "File", Recording)
    table, fab = fabric_table("velvet", n=80, seed=2)
    spec = ParamSpec("gamma_s1", defaults=defaults_from_fabric(fab))
    inner = FabricModel(fab, table.wi, table.wo)
    polls = []

    def slow(**kw):
        time.sleep(0.01)
        return inner(**kw)

    import tqdm.auto
    real_tqdm = tqdm.auto.tqdm

    class CountingBar(real_tqdm):
        def refresh(self, *a, **kw):
            polls.append(threading.get_ident())
            return super().refresh(*a, **kw)

    monkeypatch.setattr(tqdm.auto, "tqdm", CountingBar)
    monkeypatch.setattr(fit_progress, "interactive", lambda: True)     # the bar, not lines
    r = fit(table, spec, slow, max_steps=60, check_every=20, min_ratio=1e9, threads=2,
            out_dir=tmp_path, progress=True, seed=1)
    assert r.steps == 60
    assert len(polls) >= 3                       # the bar polled while the ensembles stepped
    assert opened, "the checkpoint was written through h5py"
    assert {t for _, t in opened} == {threading.get_ident()}


def _checkpoint_step(folder: Path) -> int:
    """Steps of every ensemble in the checkpoint, 0 while there is none."""
    if not (folder / "checkpoint.h5").exists():
        return 0
    ck = FitFolder(folder).read_checkpoint()
    return min(e["chain"].shape[0] for e in ck["ensembles"])


def _wait_for_checkpoint(p, folder, step, timeout=300):
    t0 = time.monotonic()
    while _checkpoint_step(folder) < step:
        assert p.poll() is None, p.communicate()
        assert time.monotonic() - t0 < timeout, "no checkpoint in time"
        time.sleep(0.05)
    return _checkpoint_step(folder)


@pytest.fixture(scope="module")
def small_csv(tmp_path_factory):
    table, _ = fabric_table("silk_crepe_de_chine", n=300, seed=9)
    path = tmp_path_factory.mktemp("small") / "silk.csv"
    gonio.write(table, path)
    return path


def _fit_args(path, out):
    return ["fit", path, "--fabric", "silk_crepe_de_chine", "--free", "gamma_s1,kd1",
            "--check-every", "20", "--max-steps", "240", "--no-plots", "-o", out]


def test_sigkill_then_resume_loses_at_most_one_check(small_csv, tmp_path):
    args = _fit_args(small_csv, tmp_path / "a")
    p = _cli(*args)
    seen = _wait_for_checkpoint(p, tmp_path / "a", 60)
    p.send_signal(signal.SIGKILL)
    p.communicate()
    assert p.returncode == -signal.SIGKILL
    kept = _checkpoint_step(tmp_path / "a")
    assert kept >= seen                          # the checkpoint survived the kill whole
    p = _cli(*args)
    stdout, stderr = p.communicate(timeout=600)
    assert p.returncode in (0,), stderr
    assert f"resumed from the checkpoint at step {kept}" in stdout
    straight = _cli(*_fit_args(small_csv, tmp_path / "b"))
    s_out, s_err = straight.communicate(timeout=600)
    assert straight.returncode == 0, s_err
    a = json.loads((tmp_path / "a" / "results.json").read_text())
    b = json.loads((tmp_path / "b" / "results.json").read_text())
    assert a["parameters"] == b["parameters"] and a["reason"] == b["reason"]


def test_ctrl_c_prints_one_line_and_resumes(silk_csv, tmp_path):
    """On the default fit's table (8 free parameters converge near step 350, seconds after
    the first checkpoint, so that Ctrl-C finds the fit running)."""
    args = ["fit", silk_csv[0], "--fabric", "silk_crepe_de_chine", "--check-every", "20",
            "--no-plots", "--no-progress", "-o", tmp_path / "c"]
    p = _cli(*args)
    _wait_for_checkpoint(p, tmp_path / "c", 40)
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == 130
    # the estimate of the fit's time (it may take over 10 s), then the one line of Ctrl-C
    lines = [x for x in stderr.strip().splitlines() if not x.startswith("fit: 11163 values")]
    assert len(lines) == 1 and lines[0].startswith("microcyl fit: interrupted at step"), stderr
    assert f"the checkpoint in {tmp_path / 'c'} resumes" in lines[0]
    step = int(lines[0].split("step ")[1].split(";")[0])
    assert _checkpoint_step(tmp_path / "c") == step
    p = _cli(*args)
    stdout, stderr = p.communicate(timeout=600)
    assert p.returncode == 0, stderr
    assert f"resumed from the checkpoint at step {step}" in stdout


def test_fit_measured_with_progress_killed_and_resumed(tmp_path, shared_data):
    """``microcyl fit-measured`` as a user runs it (progress bar on, a real folder), killed
    with SIGKILL in the middle of its fit and run again: it resumes and finishes."""
    out = tmp_path / "fits"
    args = ["fit-measured", "curet_07_velvet", "--data", shared_data, "--max-steps", "250",
            "-o", out]
    p = _cli(*args)
    seen = _wait_for_checkpoint(p, out / "curet_07_velvet", 100)
    p.send_signal(signal.SIGKILL)
    p.communicate()
    p = _cli(*args)
    stdout, stderr = p.communicate(timeout=600)
    assert p.returncode == 1, stderr            # 250 steps: not converged, and it says so
    assert "fits:" in stderr                     # the batch's bar was drawn on the pipe
    kept = int(stdout.split("resumed from step ")[1].split()[0])
    assert kept >= seen
    doc = json.loads((out / "measured.json").read_text())
    e = doc["datasets"]["curet_07_velvet"]
    assert e["steps"] == 250 and not e["converged"] and "step limit 250" in e["reason"]
    res = json.loads((out / "curet_07_velvet" / "results.json").read_text())
    assert res["quality"]["albedo_delta_e2000"] == e["albedo_delta_e2000"]
    assert (out / "curet_07_velvet" / "lobes.png").stat().st_size > 1000


def test_fit_takes_a_curet_dataset_name_for_sample(tmp_path, shared_data):
    """``fit abrdf.dat --sample curet_07_velvet`` (the name fit-measured prints) fits sample
    7, as ``--sample 7`` would: fit_config.json records the number; a name that is no CUReT
    dataset is refused in one line naming --sample."""
    table = shared_data / "curet" / "abrdf.dat"
    out = tmp_path / "fit"
    p = subprocess.run([sys.executable, "-m", "reports", "fit", str(table), "--sample",
                        "curet_07_velvet", "--fabric", "velvet", "--free", "gamma_s1",
                        "--tie", "none", "--max-steps", "20", "--check-every", "10",
                        "--ensembles", "2", "--no-plots", "--quiet", "-o", str(out)],
                       cwd=REPO, env=dict(os.environ, PYTHONPATH=str(REPO)),
                       capture_output=True, timeout=600)
    assert p.returncode == 0, p.stderr.decode()[-2000:]
    assert (out / "results.json").is_file()
    config = json.loads((out / "fit_config.json").read_text())["config"]
    assert config["extra"]["sample"] == 7
    bad = subprocess.run([sys.executable, "-m", "reports", "fit", str(table), "--sample",
                          "curet_07_felt", "--fabric", "velvet", "-o", str(tmp_path / "b")],
                         cwd=REPO, env=dict(os.environ, PYTHONPATH=str(REPO)),
                         capture_output=True, timeout=600)
    err = bad.stderr.decode().strip().splitlines()
    assert bad.returncode == 2 and "--sample" in err[-1] and "curet_07_velvet" in err[-1]
