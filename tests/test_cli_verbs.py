"""``microcyl VERB`` loads only the module of its verb (reports.cli.VERBS): the table must be
what the modules register, and a short verb must not import the others' dependencies."""

from __future__ import annotations

import argparse
import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

from reports.cli import COMMAND_MODULES, VERBS, build_parser


def _registered(module: str) -> list[str]:
    sub = argparse.ArgumentParser().add_subparsers()
    importlib.import_module(module).register(sub)
    return list(sub.choices)


def test_the_verb_table_is_what_each_module_registers():
    assert {m: list(v) for m, v in COMMAND_MODULES.items()} == \
        {m: _registered(m) for m in COMMAND_MODULES}
    assert len(VERBS) == sum(len(v) for v in COMMAND_MODULES.values())   # no verb twice


@pytest.mark.parametrize("argv", [["sanity", "velvet"], ["-q", "fit", "--help"],
                                  ["--verbose", "plot", "lobes", "velvet"]])
def test_a_verb_gets_its_own_modules_verbs(argv):
    verb = next(a for a in argv if not a.startswith("-"))
    sub = next(a for a in build_parser(argv)._actions
               if isinstance(a, argparse._SubParsersAction))
    assert sorted(sub.choices) == sorted(_registered(VERBS[verb]))


@pytest.mark.parametrize("argv", [[], ["--help"], ["sanitize"], ["-q"]])
def test_without_a_known_verb_the_parser_has_them_all(argv):
    sub = next(a for a in build_parser(argv)._actions
               if isinstance(a, argparse._SubParsersAction))
    assert sorted(sub.choices) == sorted(VERBS)


def test_a_short_verb_does_not_load_the_fit_the_renderers_or_colour_science(tmp_path):
    """``microcyl sanity velvet`` as a user runs it: neither colour-science, arviz, emcee,
    Mitsuba nor the fit's modules end up imported."""
    probe = ("import sys, json, runpy; sys.argv = ['microcyl', 'sanity', 'velvet'];\n"
             "from reports.cli import main\n"
             "status = main()\n"
             "mods = [m for m in ('colour', 'arviz', 'emcee', 'mitsuba', 'analysis.fit.driver',"
             " 'reports.cli.fit', 'reports.cli.export') if m in sys.modules]\n"
             "print(json.dumps([status, mods]))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         cwd=tmp_path, timeout=120)
    assert out.returncode == 0, out.stderr
    status, mods = json.loads(out.stdout.strip().splitlines()[-1])
    assert status == 0 and mods == [], mods


def test_the_report_and_export_verbs_load_no_sampler():
    """``microcyl report`` reads a batch's summary (``analysis.batch.summary``) and
    ``microcyl export`` a fit's posterior draws (``analysis.planning.draws``), but neither
    fits nor plans: importing their modules loads neither emcee nor the fit's driver
    (``analysis.batch`` and ``analysis.planning`` re-export their names on first use)."""
    probe = ("import sys, json; import reports.cli.model, reports.report_batch, "
             "analysis.batch.summary, reports.cli.export, analysis.export.workflow\n"
             "print(json.dumps([m for m in ('emcee', 'analysis.fit.driver', "
             "'analysis.batch.engine') if m in sys.modules]))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         cwd=Path(__file__).resolve().parents[1], timeout=120)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.strip().splitlines()[-1]) == []
