"""The documentation's generated pages (docs/_ext/microcyl_docs.py) cover what they claim:
every verb and option of the command line, every package's public names, the presets; and
its docstring filter leaves literal text alone. The site itself is built by `make docs`."""

import argparse
import importlib
import re
import sys
import textwrap
from pathlib import Path

import pytest

import brdf
from reports.cli import build_parser

DOCS = Path(__file__).resolve().parents[1] / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
microcyl_docs = importlib.import_module("microcyl_docs")


def _subparsers(parser):
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))


def test_cli_pages_name_every_verb_and_option(tmp_path):
    verbs = microcyl_docs.write_cli_pages(tmp_path)
    choices = _subparsers(build_parser()).choices
    assert verbs == list(choices) and len(verbs) >= 15
    for verb, parser in choices.items():
        page = (tmp_path / f"{verb}.rst").read_text()
        assert page.startswith(f".. _cli-{verb}:")
        for action in parser._actions:
            if action.help == argparse.SUPPRESS:
                continue
            for opt in action.option_strings or [action.metavar or action.dest]:
                assert f".. option:: {opt}" in page or f", {opt}" in page, (verb, opt)
    index = (tmp_path / "index.rst").read_text()
    assert all(f":doc:`{v}`" in index for v in verbs)


def test_api_modules_cover_the_packages_and_named_submodules():
    modules = microcyl_docs.api_modules()
    for name in ("brdf", "gonio", "analysis", "analysis.fit", "analysis.batch",
                 "analysis.albedo", "reports", "reports.cli", "reports.plots", "brdf.terms"):
        assert name in modules
    assert not any(m.rsplit(".", 1)[-1].startswith("_") for m in modules)
    assert len(modules) == len(set(modules))


def test_api_pages_document_every_public_name(tmp_path):
    pytest.importorskip("sphinx", reason="the docs extra (`make docs` installs it) is not "
                        "installed; `make docs` builds these pages with it")
    microcyl_docs.write_api_pages(tmp_path)
    page = (tmp_path / "brdf.rst").read_text()
    for name in brdf.__all__:
        obj = getattr(brdf, name)
        if not hasattr(obj, "__path__") and type(obj).__name__ != "module":
            assert f":: brdf.{name}\n" in page or f".. py:data:: {name}\n   :module: brdf" \
                in page, name


def test_presets_table_lists_every_preset(tmp_path):
    microcyl_docs.write_presets(tmp_path / "p.rst")
    text = (tmp_path / "p.rst").read_text()
    for name in brdf.PRESETS:
        assert f"``{name}``" in text
    assert text.count("     - T1") == text.count("     - T2") == len(brdf.PRESETS)


@pytest.mark.parametrize("line, expected", [
    ("the error |a - b| / max", r"the error \|a - b\| / max"),
    ("literal ``|x|`` and :math:`|y|` stay", "literal ``|x|`` and :math:`|y|` stay"),
    (r"already \| escaped", r"already \| escaped"),
])
def test_bars_escaped_in_prose_only(line, expected):
    lines = [line]
    microcyl_docs.escape_docstring_bars(None, "function", "f", None, {}, lines)
    assert lines == [expected]


def test_bars_kept_in_doctests_literal_blocks_and_math():
    lines = [">>> print(1 | 2)", "3", "", "Example::", "", "    |x|", "", ".. math::", "",
             "    |y|", "", "after |z|"]
    microcyl_docs.escape_docstring_bars(None, "function", "f", None, {}, lines)
    assert lines[0] == ">>> print(1 | 2)" and lines[5] == "    |x|" and lines[9] == "    |y|"
    assert lines[-1] == r"after \|z\|"


def _python_blocks():
    """The ``.. code-block:: python`` blocks of the hand-written pages, dedented."""
    blocks = []
    for page in sorted(DOCS.glob("*.rst")) + sorted((DOCS / "guide").glob("*.rst")):
        for m in re.finditer(r"\.\. code-block:: python\n\n((?:   .*\n|\n)+)", page.read_text()):
            blocks.append(pytest.param(textwrap.dedent(m.group(1)),
                                       id=f"{page.stem}-{m.start()}"))
    return blocks


@pytest.mark.parametrize("code", _python_blocks())
def test_page_examples_run(code, tmp_path, monkeypatch):
    """The pages' Python examples run as written (the fit of getting_started and the fitting
    page is the README's, tested by test_readme, and gallery/plot_09 runs it at every docs
    build; the Mitsuba page's has its own test below)."""
    if "fit_fabric" in code:
        pytest.skip("the README's fit, run by test_readme and the gallery")
    if "import mitsuba" in code:
        pytest.skip("the Mitsuba page's example, run by test_mitsuba_page_example")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "docs example", "exec"), {})


def test_mitsuba_page_example(tmp_path, monkeypatch):
    """The Mitsuba page's example (docs/guide/mitsuba.rst) runs in scalar_rgb, renders a
    non-black image, writes it, and the edit through mi.traverse changes the render."""
    pytest.importorskip("mitsuba", reason="mitsuba is not installed")
    import numpy as np
    blocks = [b.values[0] for b in _python_blocks() if "import mitsuba" in b.values[0]]
    assert len(blocks) == 1 and 'mi.set_variant("scalar_rgb")' in blocks[0]
    monkeypatch.chdir(tmp_path)
    # Mitsuba resolves relative paths against the folder it was first imported in
    code = blocks[0].replace('"velvet.exr"', repr(str(tmp_path / "velvet.exr")))
    ns = {}
    exec(compile(code, "Mitsuba page example", "exec"), ns)
    img = np.asarray(ns["image"])
    assert img.shape[-1] == 3 and np.isfinite(img).all() and img.mean() > 0
    assert (tmp_path / "velvet.exr").exists()      # write_async=False: written at once
    edited = np.asarray(ns["edited"])               # after the edit through mi.traverse
    assert np.isfinite(edited).all() and edited.mean() > 0
    assert np.abs(edited - img).max() > 0.01 * img.max()
