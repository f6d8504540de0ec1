"""`microcyl fit-batch` as a user runs it: a subprocess with the progress bar on, a real output
folder, a local cluster; against `dask scheduler` and two `dask worker` processes; Ctrl-C and
the same command again."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import brdf
import gonio
from _signals import default_sigint

pytest.importorskip("distributed")
ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
FIT = ["--fabric", "silk_crepe_de_chine", "--free", "kd1,gamma_s1", "--tie", "none"]


def microcyl(*args, **kw):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          capture_output=True, text=True, timeout=600, **kw)


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    d = tmp_path_factory.mktemp("tables")
    fab = brdf.fabric("silk_crepe_de_chine")
    for k, spec in enumerate(["full:20:45", "full:30"]):      # 1,089 and 625 pairs
        t = gonio.measure(fab, spec, gonio.Instrument(snr=20, floor=1e-4), seed=k,
                          progress=False)
        gonio.write(t, d / f"silk{k}.csv")
    return d


def test_fit_batch_with_progress_a_corrupt_table_and_the_page(tables, tmp_path):
    src = tmp_path / "in"
    shutil.copytree(tables, src)
    (src / "broken.exr").write_bytes(b"not an exr file")
    out = tmp_path / "out"
    r = microcyl("fit-batch", src, *FIT, "--workers", "2", "-o", out)
    assert r.returncode == 1, r.stderr                 # one table failed
    assert "fits:" in r.stderr and "table" in r.stderr     # tqdm's bar over tables
    # the estimate, once, before the batch: 3 tables, the corrupt one skipped for timing
    est = [x for x in r.stderr.splitlines() if x.startswith("fit-batch: 3 tables to fit")]
    assert len(est) == 1 and "(estimated on silk0)" in est[0] and "on 2 workers" in est[0]
    assert r.stderr.index(est[0]) < r.stderr.index("fits:")
    assert "broken: error" in r.stdout and "broken.exr" in r.stdout
    assert "2 converged, 0 not converged, 1 errors" in r.stdout
    rows = {x["name"]: x for x in json.loads((out / "summary.json").read_text())["tables"]}
    assert rows["silk0"]["status"] == rows["silk1"]["status"] == "converged"
    page = (out / "index.html").read_text()
    for name in ("silk0", "silk1"):
        doc = json.loads((out / name / "results.json").read_text())
        for plot in doc["plots"].values():
            assert f'{name}/{plot}' in page and (out / name / plot).exists()
        # each fit's verdict: its adequacy, and a line as it ended that says it
        head = {True: "adequate", False: "NOT adequate"}.get(doc["adequate"],
                                                              "adequacy unknown")
        assert f"<p><b>{head}</b>: " in page
        line = next(x for x in r.stdout.splitlines() if x.startswith(f"{name}: converged"))
        assert ("NOT ADEQUATE" in line) == (doc["adequate"] is False)
    again = microcyl("fit-batch", src, *FIT, "--workers", "1", "--no-progress", "-o", out)
    assert again.returncode == 1 and "silk0:" not in again.stdout   # converged: not redone
    assert "to fit" not in again.stderr         # only the corrupt table left: no estimate


def _wait_for(path, timeout=60.0):
    deadline = time.time() + timeout
    while time.time() < deadline and not path.exists():
        time.sleep(0.1)
    assert path.exists(), f"{path} did not appear"


def test_fit_batch_on_a_dask_scheduler_and_two_workers(tables, tmp_path):
    dask = shutil.which("dask", path=str(Path(sys.executable).parent)) or shutil.which("dask")
    if dask is None:
        pytest.skip("the dask command is not installed")
    sched_file = tmp_path / "scheduler.json"
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", "0",
                               "--no-dashboard", "--scheduler-file", str(sched_file)],
                              env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        _wait_for(sched_file)
        for _ in range(2):
            procs.append(subprocess.Popen(
                [dask, "worker", "--scheduler-file", str(sched_file), "--nworkers", "1",
                 "--nthreads", "1", "--no-dashboard"], env=ENV,
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        out = tmp_path / "out"
        r = microcyl("fit-batch", tables, *FIT, "--scheduler", address, "--no-plots",
                     "-o", out)
        assert r.returncode == 0, r.stdout + r.stderr
        assert "2 converged, 0 not converged, 0 errors" in r.stdout
        assert {(out / n / "results.json").exists() for n in ("silk0", "silk1")} == {True}
    finally:
        for p in procs[::-1]:
            p.terminate()
        for p in procs:
            p.wait(timeout=30)


def test_ctrl_c_stops_the_batch_and_the_same_command_resumes(tables, tmp_path):
    """With the default 8 free parameters each table's fit runs some hundred steps past its
    first checkpoint (at step 25), so Ctrl-C finds the batch fitting."""
    out = tmp_path / "out"
    args = [sys.executable, "-m", "reports", "fit-batch", str(tables), "--fabric",
            "silk_crepe_de_chine", "--check-every", "25", "--workers", "2", "--no-plots",
            "-o", str(out)]
    p = subprocess.Popen(args, env=ENV, preexec_fn=default_sigint, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE,
                         text=True)
    _wait_for(out / "silk0" / "checkpoint.h5", timeout=120)
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == 130, stderr
    last = stderr.strip().splitlines()[-1]
    assert "interrupted" in last and "resumes" in last
    assert "Traceback" not in stderr
    r = microcyl(*args[3:])
    assert r.returncode == 0, r.stderr
    rows = {x["name"]: x for x in json.loads((out / "summary.json").read_text())["tables"]}
    assert {x["status"] for x in rows.values()} == {"converged"}
    assert rows["silk0"]["resumed_from"] > 0 or "silk0" in stdout  # resumed, or had ended


def test_ctrl_c_while_the_cluster_starts_is_one_line(tables, tmp_path):
    """Ctrl-C as the progress bar appears, while the workers start: the one line of the
    interrupt and status 130; no traceback from the half-started cluster, no lock left."""
    out = tmp_path / "out"
    p = subprocess.Popen([sys.executable, "-m", "reports", "fit-batch", str(tables), *FIT,
                          "--workers", "1", "--no-plots", "-o", str(out)], env=ENV,
                         preexec_fn=default_sigint, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    seen = b""
    while b"fits:" not in seen:
        chunk = os.read(p.stderr.fileno(), 4096)
        assert chunk, seen
        seen += chunk
    p.send_signal(signal.SIGINT)
    _, rest = p.communicate(timeout=120)
    err = (seen + rest).decode()
    assert p.returncode == 130, err
    assert err.strip().splitlines()[-1].startswith("microcyl fit-batch: interrupted"), err
    assert "Traceback" not in err and "Task exception" not in err
    assert not (out / ".microcyl.lock").exists()


def test_a_second_batch_into_the_same_folder_is_refused_at_once(tables, tmp_path):
    """Two `fit-batch` runs into one -o folder: the second is refused before any work,
    naming the first's pid; the first goes on and resumes like any other."""
    out = tmp_path / "out"
    args = ["fit-batch", str(tables), *FIT, "--max-steps", "100000", "--workers", "1",
            "--no-plots", "-o", str(out)]
    lock = out / ".microcyl.lock"
    first = subprocess.Popen([sys.executable, "-m", "reports", *args], env=ENV,
                             preexec_fn=default_sigint,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        end = time.monotonic() + 120
        while not (lock.exists() and lock.read_text().strip()) and time.monotonic() < end:
            time.sleep(0.05)
        t0 = time.monotonic()
        second = microcyl(*args)
        assert time.monotonic() - t0 < 30              # refused at once, not after a fit
        assert second.returncode == 1
        assert second.stderr.strip().splitlines()[-1] == (
            f"microcyl fit-batch: error: another batch is running in {out} (pid "
            f"{first.pid}); wait for it to end or use another output")
        assert first.poll() is None                    # the first one is untouched
        _wait_for(out / "silk0" / "checkpoint.h5", timeout=120)    # and fits
    finally:
        first.send_signal(signal.SIGINT)
        _, err = first.communicate(timeout=120)
    assert first.returncode == 130, err
    assert not lock.exists()


# ------------------------------------------------------------- hostile summary.json
def _fake_batch(out, rows, plots=None):
    """A batch folder as fit-batch writes one: summary.json and a fit folder ``good``."""
    (out / "good").mkdir(parents=True)
    (out / "good" / "results.json").write_text(json.dumps(
        {"schema": "microcyl-fit", "schema_version": 2, "converged": True, "reason": "ok",
         "parameters": {}, "fit": {}, "quality": {},
         "plots": plots if plots is not None else {"corner": "corner.png"}}))
    (out / "good" / "corner.png").write_bytes(b"\x89PNG")
    base = {"name": "good", "status": "converged", "error": "", "steps": 10, "wall_s": 1.0,
            "path": "t.csv", "sample": None, "preset": "velvet", "reason": "ok",
            "folder": "good", "kd1_median": 0.2, "kd1_lo95": 0.1, "kd1_hi95": 0.3}
    (out / "summary.json").write_text(json.dumps(
        {"schema": "microcyl-batch", "version": 1, "counts": {},
         "tables": [dict(base, **r) for r in rows]}))
    return out


@pytest.mark.parametrize("row, plots, named", [
    ({"name": "../../escape_target"}, None, "tables[0].name: name '../../escape_target'"),
    ({"folder": "/etc"}, None, "tables[0].folder: name '/etc'"),
    ({"folder": ".."}, None, "tables[0].folder: name '..'"),
    ({"status": "<script>x</script>"}, None, "tables[0].status must be one of"),
    ({"steps": "<script>x</script>"}, None, "tables[0].steps must be an integer"),
    ({"wall_s": [1]}, None, "tables[0].wall_s must be a finite number"),
    ({"kd1_median": "<b>"}, None, "tables[0].kd1_median must be a finite number"),
    ({"error": 3}, None, "tables[0].error must be a string"),
    ({}, {"corner": "../../../x.png"}, "results.json: plots.corner: name '../../../x.png'"),
    ({}, {"corner": "/etc/passwd"}, "results.json: plots.corner: name '/etc/passwd'"),
])
def test_report_batch_refuses_a_hostile_summary_in_one_line(tmp_path, row, plots, named):
    from reports.report_batch import write_batch_page     # in-process: ten cases, fast
    out = _fake_batch(tmp_path / "b", [row], plots)
    with pytest.raises(ValueError) as err:
        write_batch_page(out)
    assert named in str(err.value) and "\n" not in str(err.value)
    assert not (out / "index.html").exists()


def test_report_batch_cli_refuses_names_and_planted_links_in_one_line(tmp_path):
    out = _fake_batch(tmp_path / "b", [{"name": "../../escape_target"}])
    r = microcyl("report", "--batch", out)
    assert r.returncode != 0 and "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "summary.json: tables[0].name" in lines[0], r.stderr
    (tmp_path / "elsewhere").mkdir()
    out = _fake_batch(tmp_path / "c", [{"name": "linked", "folder": "linked"}])
    (out / "linked").symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    r = microcyl("report", "--batch", out)
    assert r.returncode != 0 and "outside" in r.stderr and "linked" in r.stderr
    assert not (out / "index.html").exists()
    good = _fake_batch(tmp_path / "ok", [{}])
    r = microcyl("report", "--batch", good)
    assert r.returncode == 0, r.stderr
    assert 'src="good/corner.png"' in (good / "index.html").read_text()


def test_fit_batch_names_same_stem_tables_by_path_whatever_their_order(tables, tmp_path):
    """Two tables x.csv in two folders and a table ``...csv`` (stem ``..``): the folders are
    named from the paths, so the same command with the inputs in another order resumes each
    fit in its own folder (no "another configuration"), and nothing is written beside -o."""
    src = tmp_path / "in"
    for sub, table in (("a", "silk0.csv"), ("b", "silk1.csv"), ("c", "silk1.csv")):
        (src / sub).mkdir(parents=True)
    shutil.copy(tables / "silk0.csv", src / "a" / "x.csv")
    shutil.copy(tables / "silk1.csv", src / "b" / "x.csv")
    shutil.copy(tables / "silk1.csv", src / "c" / "...csv")
    out = tmp_path / "site" / "out"
    opts = [*FIT, "--max-steps", "20", "--no-plots", "--workers", "1", "--no-progress",
            "-o", out]
    first = microcyl("fit-batch", src / "a", src / "b", src / "c" / "...csv", *opts)
    assert first.returncode == 0, first.stderr + first.stdout
    rows = {r["name"]: r for r in json.loads((out / "summary.json").read_text())["tables"]}
    dotted = [n for n in rows if n.startswith("_-")]
    assert set(rows) == {"a_x", "b_x"} | set(dotted) and len(dotted) == 1
    assert rows["a_x"]["path"].endswith(os.path.join("a", "x.csv"))
    assert rows["b_x"]["path"].endswith(os.path.join("b", "x.csv"))
    assert sorted(p.name for p in (tmp_path / "site").iterdir()) == ["out"]
    assert (out / dotted[0] / "results.json").is_file()
    second = microcyl("fit-batch", src / "c" / "...csv", src / "b", src / "a", *opts)
    assert second.returncode == 0, second.stderr + second.stdout
    assert "another configuration" not in second.stdout + second.stderr
    again = {r["name"]: r for r in json.loads((out / "summary.json").read_text())["tables"]}
    assert set(again) == set(rows)
    for name, r in again.items():
        assert r["status"] == "not_converged" and r["path"] == rows[name]["path"]
        assert r["resumed_from"] > 0                           # resumed in its own folder
    assert sorted(p.name for p in (tmp_path / "site").iterdir()) == ["out"]
