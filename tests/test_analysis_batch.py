"""Batch fits on Dask (analysis.batch): real LocalClusters of worker processes, a corrupt
table, a worker killed mid-fit, reruns that resume; and the inputs refused up front."""

import json
import os
import random
import signal
import threading
import time
from pathlib import Path

import pytest

import brdf
import gonio
from analysis.batch import (BatchJob, BatchSummary, jobs_from_inputs, parse_samples,
                            run_batch)
from analysis.batch.jobs import table_names
from analysis.params import defaults_from_fabric
from gonio.safenames import name_problem

distributed = pytest.importorskip("distributed")

PRESET = "silk_crepe_de_chine"
FREE = ("kd1", "gamma_s1")


def _tables(folder, specs):
    folder.mkdir(parents=True, exist_ok=True)
    fab = brdf.fabric(PRESET)
    for k, spec in enumerate(specs):
        t = gonio.measure(fab, spec, gonio.Instrument(snr=20, floor=1e-4), seed=k,
                          progress=False)
        gonio.write(t, folder / f"t{k}.csv")
    return folder


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = _tables(tmp_path_factory.mktemp("tables"), ["full:30:45", "full:30", "full:20:45"])
    (d / "corrupt.csv").write_text("theta_i,phi_i,theta_o,phi_o,r,g,b\n10,0,20,0,0.1\n")
    return d


@pytest.fixture(scope="module")
def batch(inputs, tmp_path_factory):
    """The four tables fitted once on a LocalCluster of 2 worker processes."""
    out = tmp_path_factory.mktemp("batch")
    jobs = jobs_from_inputs([str(inputs)], preset=PRESET, free=FREE, ties=(),
                            fit={"max_steps": 3000})
    lines = []
    summary = run_batch(jobs, out, workers=2, progress=False, echo=lines.append)
    return out, jobs, summary, lines


def test_three_fits_and_one_error_naming_the_file(batch):
    out, jobs, summary, lines = batch
    assert [j.name for j in jobs] == ["corrupt", "t0", "t1", "t2"]
    assert summary.counts() == {"error": 1, "converged": 3}
    rows = {r["name"]: r for r in json.loads((out / "summary.json").read_text())["tables"]}
    assert "corrupt.csv" in rows["corrupt"]["error"]
    truth = defaults_from_fabric(brdf.fabric(PRESET))
    for name in ("t0", "t1", "t2"):
        r = rows[name]
        assert r["steps"] > 0 and r["wall_s"] > 0
        for p in FREE:     # the simulated tables' truth inside the 95% intervals
            assert r[f"{p}_lo95"] <= truth[p] <= r[f"{p}_hi95"], (name, p)
        res = json.loads((out / name / "results.json").read_text())
        assert (r["elpd"], r["elpd_se"]) == (res["loo"]["elpd"], res["loo"]["se"])
        # the generating preset describes its own tables; both parameters are informed
        assert r["adequate"] is True and r["warnings"] == "", (name, r["warnings"])
    csv_lines = (out / "summary.csv").read_text().splitlines()
    assert csv_lines[0].startswith("name,status,error,steps,wall_s")
    assert "kd1_median" in csv_lines[0] and ",elpd,elpd_se" in csv_lines[0]
    assert "adequate" in csv_lines[0] and len(csv_lines) == 5
    assert len(lines) == 4 and any(line.startswith("corrupt: error") for line in lines)


def test_a_rerun_does_not_redo_converged_fits(batch):
    out, jobs, summary, _ = batch
    stamps = {n: (out / n / "results.json").stat().st_mtime_ns for n in ("t0", "t1", "t2")}
    lines = []
    again = run_batch(jobs, out, workers=1, progress=False, echo=lines.append)
    assert {n: (out / n / "results.json").stat().st_mtime_ns for n in stamps} == stamps
    assert lines == ["corrupt: error: " + again.rows["corrupt"]["error"]]   # only it reruns
    assert again.rows["t1"] == summary.rows["t1"]


def test_a_changed_table_is_fitted_again(tmp_path, monkeypatch):
    d = _tables(tmp_path / "in", ["full:30:45"])
    jobs = jobs_from_inputs([str(d / "t0.csv")], preset=PRESET, free=FREE, ties=())
    for key in ("OMP_NUM_THREADS", "MALLOC_TRIM_THRESHOLD_", "__DASK_PARENT_PID"):
        monkeypatch.delenv(key, raising=False)
    before = dict(os.environ)
    run_batch(jobs, tmp_path / "out", workers=1, progress=False, echo=None)
    # Dask's nanny sets its workers' variables (OMP_NUM_THREADS=1 ...) in the caller's own
    # environment; the batch leaves the caller's environment as it found it
    assert dict(os.environ) == before
    _tables(d, ["full:30"])                       # same name, other pairs
    jobs = jobs_from_inputs([str(d / "t0.csv")], preset=PRESET, free=FREE, ties=())
    assert not BatchSummary(tmp_path / "out").done(jobs[0])


def _kill_when_checkpointed(cluster, out, victim, state):
    """Wait for ``victim``'s first checkpoint, then SIGKILL the worker process fitting it."""
    with distributed.Client(cluster) as client:
        deadline = time.time() + 120
        while time.time() < deadline and not (out / victim / "checkpoint.h5").exists():
            time.sleep(0.05)
        for addr, keys in client.processing().items():
            if any(victim in str(k) for k in keys):
                pid = client.run(os.getpid, workers=[addr])[addr]
                os.kill(pid, signal.SIGKILL)
                state["killed"] = pid
                return


def test_a_killed_worker_has_its_table_rescheduled_and_resumed(tmp_path):
    d = _tables(tmp_path / "in", ["full:20:45", "full:15:45"])
    out = tmp_path / "out"
    jobs = jobs_from_inputs([str(d)], preset=PRESET, free=FREE + ("gamma_v1",), ties=(),
                            fit={"check_every": 25, "max_steps": 3000})
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0", silence_logs=50) as cluster:
        state = {}
        killer = threading.Thread(target=_kill_when_checkpointed,
                                  args=(cluster, out, "t1", state))
        killer.start()
        summary = run_batch(jobs, out, scheduler=cluster.scheduler_address, progress=False,
                            echo=None)
        killer.join()
    assert state.get("killed"), "no worker was killed: the fit ended before its checkpoint"
    assert summary.counts() == {"converged": 2}
    assert summary.rows["t1"]["resumed_from"] > 0     # rescheduled, from the checkpoint


# ----------------------------------------------------------------------------- inputs
def test_inputs_are_checked_before_any_fit(tmp_path, inputs):
    with pytest.raises(ValueError, match="no such file"):
        jobs_from_inputs([str(tmp_path / "nope.csv")], preset=PRESET)
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(ValueError, match="not a table file"):
        jobs_from_inputs([str(tmp_path / "notes.txt")], preset=PRESET)
    with pytest.raises(ValueError, match="matches no table"):
        jobs_from_inputs([str(tmp_path / "*.bsdf")], preset=PRESET)
    with pytest.raises(ValueError, match="t0.*kd9|kd9.*t0"):
        jobs_from_inputs([str(inputs / "t0.csv")], preset=PRESET, free=("kd9",))
    with pytest.raises(ValueError, match="unknown fabric"):
        jobs_from_inputs([str(inputs)], preset="tweed")


def test_curet_needs_samples_and_names_them(shared_data):
    path = shared_data / "curet" / "abrdf.dat"
    with pytest.raises(ValueError, match="--sample"):
        jobs_from_inputs([str(path)], preset="velvet")
    jobs = jobs_from_inputs([str(path)], preset="velvet", samples="7,42")
    assert [(j.name, j.sample) for j in jobs] == [("curet_07", 7), ("curet_42", 42)]
    assert len(jobs_from_inputs([str(path)], preset="velvet", samples="all")) == 61
    with pytest.raises(ValueError, match="1..61"):
        parse_samples("0,3")


def test_globs_dedupe_names_and_the_per_table_toml(tmp_path, inputs):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "t0.csv").write_bytes((inputs / "t0.csv").read_bytes())
    jobs = jobs_from_inputs([str(inputs / "t*.csv"), str(tmp_path / "a")], preset=PRESET)
    # the two t0 tables are named by their paths below the tables' common folder
    root = Path(os.path.commonpath([inputs.resolve(), (tmp_path / "a").resolve()]))
    other = "_".join((tmp_path / "a").resolve().relative_to(root).parts) + "_t0"
    mine = "_".join(inputs.resolve().relative_to(root).parts) + "_t0"
    assert [j.name for j in jobs] == [mine, "t1", "t2", other]
    again = jobs_from_inputs([str(tmp_path / "a"), str(inputs / "t*.csv"),
                              str(inputs / "t0.csv")], preset=PRESET)   # t0 named twice
    assert {j.name: j.path for j in again} == {j.name: j.path for j in jobs}
    (tmp_path / "a" / "t0.toml").write_text('fabric = "velvet"\nfree = ["kd1"]\n')
    (job,) = jobs_from_inputs([str(tmp_path / "a" / "t0.csv")], preset=PRESET,
                              free=("kd1", "gamma_s1"))
    assert job.preset == "velvet" and job.param_spec().free == ("kd1",)


def test_table_names_are_safe_distinct_and_stable_under_reordering():
    d = Path("/data")
    tables = [(d / "a" / "x.csv", None), (d / "b" / "x.csv", None), (d / "b" / "x.exr", None),
              (d / "c" / "X.csv", None), (d / "c" / "...exr", None), (d / "c" / "....exr", None),
              (d / "a_x.csv", None), (d / "cu" / "abrdf.dat", 7), (d / "e" / "cu" / "abrdf.dat", 7),
              (d / "c" / "y.csv", None)]
    want = dict(zip(tables, table_names(tables)))
    for n in want.values():
        assert name_problem(n) is None and n not in (".", "..")
    assert len({n.casefold() for n in want.values()}) == len(tables)
    assert want[(d / "c" / "y.csv", None)] == "y"                  # unique stems stay
    assert want[(d / "cu" / "abrdf.dat", 7)] == "cu_07"
    assert want[(d / "e" / "cu" / "abrdf.dat", 7)] == "e_cu_07"
    assert want[(d / "b" / "x.csv", None)] == "b_x_csv"            # b/x.exr beside it
    rng = random.Random(0)
    for _ in range(40):
        order = rng.sample(range(len(tables)), len(tables))
        got = table_names([tables[i] for i in order])
        assert got == [want[tables[i]] for i in order]


def test_a_dotted_stem_never_names_a_folder_outside(tmp_path, inputs):
    (tmp_path / "...csv").write_bytes((inputs / "t0.csv").read_bytes())
    (job,) = jobs_from_inputs([str(tmp_path / "...csv")], preset=PRESET)
    out = tmp_path / "out"
    assert name_problem(job.name) is None and (out / job.name).resolve().parent == out.resolve()
    for bad in ("..", "../x", "/abs", ".hidden"):
        with pytest.raises(ValueError, match="job name.*refused"):
            run_batch([BatchJob(bad, str(inputs / "t0.csv"), preset=PRESET)], out)
    assert not out.exists()


def test_job_key_follows_its_inputs(tmp_path, inputs):
    job = BatchJob("t0", str(inputs / "t0.csv"), preset=PRESET, free=FREE)
    assert job.key() == BatchJob("t0", str(inputs / "t0.csv"), preset=PRESET,
                                 free=FREE).key()
    assert job.key() != BatchJob("t0", str(inputs / "t0.csv"), preset=PRESET,
                                 free=("kd1",)).key()


def test_the_batch_estimate_is_tables_times_one_fit_over_the_workers(monkeypatch, inputs):
    """100 s a table (a stand-in for the timing), 5 tables: ceil(5 / 2) x 100 s = 5 min on
    two workers, 500 s = 8 min shared by a scheduler's workers; a table that cannot be read
    is skipped for the estimate; --time-limit caps a table's time."""
    import analysis.batch.engine as engine
    timed = []

    def fake(job):
        timed.append(job.name)
        if job.name == "unreadable":
            raise ValueError("unreadable.csv: not a table")
        return 100.0, "fit: ..."
    monkeypatch.setattr(engine, "estimate_job", fake)
    jobs = [BatchJob(name, f"{name}.csv", preset=PRESET)
            for name in ("unreadable", "a", "b", "c", "d")]
    line = engine.estimate_batch(jobs, workers=2)
    assert timed == ["unreadable", "a"]                  # one fit timed, the first readable
    assert line.startswith("fit-batch: 5 tables to fit, up to 100 s each (estimated on a)")
    assert "so up to 5 min on 2 workers" in line
    assert "up to 8 min of fitting in all, shared by the workers of tcp://h:1" in \
        engine.estimate_batch(jobs, scheduler="tcp://h:1")
    assert "up to 100 s on 5 workers" in engine.estimate_batch(jobs, workers=8)
    capped = [BatchJob("a", "a.csv", preset=PRESET, fit={"time_limit": 30.0})] * 3
    assert "up to 30 s each (estimated on a, --time-limit), so up to 60 s on 2 workers" in \
        engine.estimate_batch(capped, workers=2)
    assert engine.estimate_batch([BatchJob("unreadable", "u.csv")]) is None


def test_estimate_job_times_the_fit_a_worker_runs(inputs):
    from analysis.batch.worker import estimate_job
    job = BatchJob("t1", str(inputs / "t1.csv"), preset=PRESET, free=FREE, ties=(),
                   fit={"max_steps": 1000})
    seconds, line = estimate_job(job)
    assert 0 < seconds < 600 and "for --max-steps 1000" in line
    one = gonio.read(str(inputs / "t1.csv"))
    tiny = gonio.Table(one.wi[:1], one.wo[:1], one.values[:1], sigma=one.sigma[:1])
    with pytest.raises(ValueError, match="table has 3 valid values for"):
        estimate_job(BatchJob("t1", "t1.csv", preset=PRESET, free=("kd1", "gamma_s1", "eta1"),
                              ties=(), loader=lambda: tiny))


def _churn_faults():
    """Minor page faults of allocating, filling and freeing a 1 MiB array 200 times."""
    import resource

    import numpy
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(200):
        numpy.ones(1 << 17)
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before


def test_workers_get_a_steady_allocator(monkeypatch):
    """Dask's MALLOC_TRIM_THRESHOLD_ for its workers makes every large temporary a fresh
    mapping (256 page faults per MiB each time); the batch's workers get fixed thresholds,
    even when this process's environment carries Dask's setting (as after any other
    LocalCluster in it)."""
    from analysis.batch.engine import _client
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "65536")
    with _client(2, None) as client:
        env = client.run(lambda: os.environ.get("MALLOC_TRIM_THRESHOLD_"))
        faults = client.run(_churn_faults)
    assert set(env.values()) == {"65536"}               # the workers did inherit it
    assert max(faults.values()) < 2000, faults        # ~51,000 with Dask's default


def _drjit_threads():
    """In a worker: Dr.Jit's thread count once the brdf kernel has loaded it."""
    from brdf import jit
    if not jit.available()[0]:
        return None
    import drjit
    return drjit.thread_count()


def test_workers_share_the_cores_among_their_drjit_threads():
    """N local workers on C cores give Dr.Jit C // N threads each (at least 1), applied when
    the kernel loads Dr.Jit after the cap was set: N workers x threads <= the cores, where
    Dr.Jit's default (a thread a core) would run N x C."""
    from analysis.batch.engine import _client
    cores = os.cpu_count() or 1
    with _client(2, None) as client:
        got = client.run(_drjit_threads)
    assert len(got) == 2
    if None in got.values():
        pytest.skip("Dr.Jit does not run here")
    assert set(got.values()) == {max(1, cores // 2)}
    assert sum(got.values()) <= max(cores, 2)
