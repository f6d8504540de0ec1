"""Shared test fixtures."""

import fcntl
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

import _forkcli

#: ``python -m reports ...`` runs fork from a server that has imported the toolkit once per
#: worker (``tests/_forkcli.py``); ``MICROCYL_TEST_SPAWN=1`` starts each in a new interpreter.
if not os.environ.get("MICROCYL_TEST_SPAWN"):
    _forkcli.install()

#: Property tests take their time on a loaded machine (`make test` runs one worker per core,
#: beside the fits' and renders' own processes): no per-example deadline by default.
settings.register_profile("microcyl", deadline=None)
settings.load_profile("microcyl")


@pytest.fixture(autouse=True)
def _environment_restored():
    """Each test leaves the worker's environment as it found it, whatever a library it ran
    set there: the next test's runs (and their fork server, ``tests/_forkcli.py``, which
    forks only runs in the worker's environment) see the suite's environment."""
    before = dict(os.environ)
    yield
    if os.environ != before:
        os.environ.clear()
        os.environ.update(before)


#: ../shared/data, the measured BRDF data kept beside this repository (never copied in).
SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path to ../shared/data; tests that need it skip cleanly when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"measured data not found at {SHARED_DATA}")
    return SHARED_DATA


@pytest.fixture(scope="session")
def fit_folder(tmp_path_factory):
    """A real (short) fit of velvet with a variant and a tie, written by fit_fabric: its
    folder and its FitResult (free gamma_s1 and kd1, kd2 tied to kd1; masking off, rotation
    0.25 rad)."""
    tmp_path = tmp_path_factory.mktemp("fit")
    import brdf
    from analysis.fit import fit_fabric, fit_spec
    from gonio.table import Table
    fab = brdf.fabric("velvet", masking=False, rotation=0.25)
    rng = np.random.default_rng(2)
    wi = brdf.directions.from_angles(rng.uniform(0, 1.3, 300), rng.uniform(-3, 3, 300))
    wo = brdf.directions.from_angles(rng.uniform(0, 1.3, 300), rng.uniform(-3, 3, 300))
    f = fab.eval(wi, wo)
    table = Table(wi, wo, f * (1 + 0.05 * rng.normal(size=f.shape)), sigma=0.05 * f + 1e-5)
    spec = fit_spec(fab, "gamma_s1,kd1", ["kd2=kd1"], None)
    out = tmp_path / "fit"
    res = fit_fabric(table, fab, spec, out, max_steps=100, ensembles=2, progress=False,
                     config_extra={"fabric": "velvet", "options": fab.options})
    return out, res


def run_once(tmp_path_factory, name: str, build) -> Path:
    """``build(folder)`` once in this test run, whichever xdist worker asks first (the
    others wait on a lock, then share it): the folder of an expensive artefact several
    modules read (a fit, a batch). Its readers must not change it. Without xdist it is
    this process's own, like any session fixture."""
    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    folder, done = root / name, root / f"{name}.done"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not done.exists():
            shutil.rmtree(folder, ignore_errors=True)     # a build that failed in another
            folder.mkdir()
            build(folder)
            done.touch()
    return folder


@pytest.fixture(scope="session")
def velvet_two_models(tmp_path_factory, shared_data):
    """``microcyl fit-measured curet_07_velvet --models microcylinder,lambert --max-steps 60
    --no-plots`` as a user runs it, once a test run (:func:`run_once`): (the output folder,
    its stdout, its stderr). 60 steps: neither fit converges, both are inadequate."""
    def build(folder):
        env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]),
                   COLUMNS="100")
        r = subprocess.run([sys.executable, "-m", "reports", "fit-measured",
                            "curet_07_velvet", "--models", "microcylinder,lambert",
                            "--max-steps", "60", "--no-plots", "--data", str(shared_data),
                            "-o", str(folder / "out")], env=env, capture_output=True,
                           text=True, timeout=900)
        assert r.returncode in (0, 1), r.stderr          # 1: not converged in 60 steps
        (folder / "stdout.txt").write_text(r.stdout)
        (folder / "stderr.txt").write_text(r.stderr)
    folder = run_once(tmp_path_factory, "velvet_two_models", build)
    return (folder / "out", (folder / "stdout.txt").read_text(),
            (folder / "stderr.txt").read_text())
