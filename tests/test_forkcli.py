"""The fork server of the suite's CLI runs (``tests/_forkcli.py``): a forked run is the run a
new interpreter makes, in its output, status, streams, environment, directory and signals."""

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

import _forkcli
from _signals import default_sigint

ROOT = Path(__file__).resolve().parents[1]


def _env(**extra) -> dict:
    """The worker's environment as it is now (a library imported by another test module may
    have added a variable since collection: KMP_DUPLICATE_LIB_OK), with the suite's own."""
    return dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100", **extra)


EVAL = ["eval", "velvet", "--wi", "30,0", "--wo", "30,180"]
CASES = [
    ["--help"],
    EVAL,
    ["eval", "velvet", "--wi", "30,0"],                          # usage error: status 2
    ["eval", "no_such_fabric", "--wi", "30,0", "--wo", "30,180"],  # one line: status 1
    ["fabrics"],
]


def _run(argv, spawn, **kw):
    cls = _forkcli.SPAWN if spawn else _forkcli.Popen
    kw.setdefault("env", _env())
    with cls([sys.executable, "-m", "reports", *argv], stdout=subprocess.PIPE,
             stderr=subprocess.PIPE, text=True, **kw) as p:
        out, err = p.communicate(timeout=300)
        return p, out, err


def _forked(p) -> bool:
    return getattr(p, "forked", False)


@pytest.mark.parametrize("argv", CASES, ids=lambda a: " ".join(a[:2]))
def test_a_forked_run_prints_and_exits_as_a_new_interpreter(argv):
    forked, out, err = _run(argv, spawn=False)
    spawned, out2, err2 = _run(argv, spawn=True)
    assert _forked(forked) and not _forked(spawned)
    assert (forked.returncode, out, err) == (spawned.returncode, out2, err2)


def test_environment_directory_and_streams_are_the_requests(tmp_path):
    """The environment as given (a variable the toolkit reads when it runs), the working
    directory for relative paths, the streams the test passes."""
    env = _env(MICROCYL_BACKEND="bogus")
    forked, out, err = _run(EVAL, spawn=False, env=env)
    spawned, out2, err2 = _run(EVAL, spawn=True, env=env)
    assert _forked(forked) and forked.returncode == 1 and "'bogus'" in err
    assert (forked.returncode, out, err) == (spawned.returncode, out2, err2)
    p = _forkcli.Popen([sys.executable, "-m", "reports", "plot", "lobes", "velvet", "-o",
                        "lobes.png"], env=_env(), cwd=tmp_path, stdin=subprocess.PIPE,
                       stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
    p.communicate("", timeout=300)
    assert _forked(p) and p.returncode == 0
    assert (tmp_path / "lobes.png").stat().st_size > 1000


def test_a_start_up_variable_that_differs_starts_a_real_interpreter():
    p, out, err = _run(["--help"], spawn=False, env=_env(MPLBACKEND="pdf"))
    assert not _forked(p) and p.returncode == 0


def test_a_variable_set_in_the_worker_after_the_server_started_still_forks(monkeypatch):
    """A library imported by one test module may set a variable in the worker (CI saw this:
    every run after it started a new interpreter). The worker's runs then get a server in
    the new environment, and a variable of the run's environment still reaches the run."""
    _run(EVAL, spawn=False)                                  # the server runs
    monkeypatch.setenv("SET_BY_A_LIBRARY", "1")
    forked, out, err = _run(["eval", "no_such_fabric", "--wi", "30,0", "--wo", "30,180"],
                            spawn=False)
    assert _forked(forked) and forked.returncode == 1 and "no_such_fabric" in err
    env = _env(MICROCYL_BACKEND="bogus")                     # and the environment reaches it
    assert env["SET_BY_A_LIBRARY"] == "1"
    forked, out, err = _run(EVAL, spawn=False, env=env)
    assert _forked(forked) and forked.returncode == 1 and "'bogus'" in err


def test_a_killed_run_has_the_status_of_a_killed_child(tmp_path):
    """SIGKILL: status -9 as for any child, and nothing written. (Ctrl-C, with
    ``default_sigint``, is each long verb's own test: ``test_cli_fit_e2e``,
    ``test_cli_fit_batch``.)"""
    png = tmp_path / "a.png"
    p = _forkcli.Popen([sys.executable, "-m", "reports", "plot", "lobes", "velvet", "-o",
                        str(png)], env=_env(), preexec_fn=default_sigint,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert _forked(p) and p.poll() is None
    p.kill()
    p.communicate(timeout=120)
    assert p.returncode == -signal.SIGKILL and not png.exists()


def test_the_suite_routes_cli_runs_through_the_server():
    assert subprocess.Popen is (_forkcli.SPAWN if os.environ.get("MICROCYL_TEST_SPAWN")
                                else _forkcli.Popen)
    r = subprocess.run([sys.executable, "-m", "reports", "--version"], env=_env(),
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stdout.startswith("microcyl ")
