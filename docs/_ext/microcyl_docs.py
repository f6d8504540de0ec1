"""Pages generated at build time, so that they cannot drift from the code.

- ``cli/<verb>.rst``: every verb of ``microcyl`` and each of its options, read from the argparse
  parsers (:func:`reports.cli.build_parser`).
- ``api/<module>.rst``: every public name in the ``__all__`` of each package (brdf, gonio,
  analysis and its subpackages, reports and every module or subpackage below it that has an
  ``__all__``), documented from its docstring by autodoc; a name exported by several modules is
  indexed once, on the page of the first (the packages come first).

Both are written into ``docs/_generated/`` (not tracked) when the builder starts.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import pkgutil
import re
import sys
from pathlib import Path

#: Packages whose ``__all__`` the API reference documents, in order; every module below
#: ``reports`` with an ``__all__`` follows (whatever subpackages it is moved into).
API_PACKAGES = ("brdf", "gonio", "analysis", "analysis.fit", "analysis.batch",
                "analysis.albedo", "analysis.planning")
WALKED = ("reports",)

_RST_SPECIAL = re.compile(r"([\\*`|_\[\]<>])")


def rst_text(text: str) -> str:
    """Plain text made inert for reStructuredText (markup characters escaped)."""
    return _RST_SPECIAL.sub(r"\\\1", " ".join(str(text).split()))


def _title(text: str, char: str = "=") -> str:
    return f"{text}\n{char * len(text)}\n"


# -- the command line ------------------------------------------------------------------------
def _help(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    if action.help in (None, argparse.SUPPRESS):
        return ""
    params = dict(vars(action), prog=parser.prog)
    for key, value in list(params.items()):
        if value is argparse.SUPPRESS:
            del params[key]
        elif hasattr(value, "__name__"):
            params[key] = value.__name__
    if params.get("choices") is not None:
        params["choices"] = ", ".join(map(str, params["choices"]))
    try:
        return action.help % params
    except (KeyError, TypeError, ValueError):
        return action.help


def _invocation(action: argparse.Action) -> str:
    if not action.option_strings:
        return action.metavar or action.dest
    if action.nargs == 0:
        return ", ".join(action.option_strings)
    meta = action.metavar or action.dest.upper()
    if isinstance(meta, tuple):
        meta = " ".join(meta)
    return ", ".join(f"{o} {meta}" for o in action.option_strings)


def _options_rst(parser: argparse.ArgumentParser, program: str) -> list[str]:
    lines = [f".. program:: {program}", ""]
    for group in parser._action_groups:       # argparse has no public accessor for these
        actions = [a for a in group._group_actions
                   if a.help is not argparse.SUPPRESS
                   and not isinstance(a, argparse._SubParsersAction)]
        if not actions:
            continue
        lines += [_title(str(group.title).capitalize(), "-"), ""]
        for action in actions:
            lines.append(f".. option:: {_invocation(action)}")
            lines.append("")
            text = _help(parser, action)
            extra = []
            if action.choices is not None and not isinstance(action.choices, dict):
                extra.append("one of " + ", ".join(map(str, action.choices)))
            if action.required and action.option_strings:
                extra.append("required")
            default = action.default
            if (action.option_strings and action.nargs != 0 and default is not None
                    and default is not argparse.SUPPRESS and "default" not in text):
                extra.append(f"default {default}")
            body = " ".join(p for p in (rst_text(text), rst_text("; ".join(extra)) and
                                        f"({rst_text('; '.join(extra))})") if p)
            lines += ["   " + body, ""] if body else []
    return lines


def write_cli_pages(out: Path) -> list[str]:
    """One page a verb, and an index; returns the verbs."""
    from reports.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {c.dest: c.help for c in sub._choices_actions}
    out.mkdir(parents=True, exist_ok=True)
    verbs = list(sub.choices)
    index = [_title("Every verb and option"), "",
             "Generated from the command line's own parsers when these pages are built, so it",
             "says what the installed ``microcyl`` accepts. ``microcyl VERB --help`` prints the",
             "same.", "", ".. code-block:: text", "",
             *("   " + line for line in parser.format_usage().splitlines()),
             "", *_options_rst(parser, "microcyl"), _title("Verbs", "-"), "",
             ".. list-table::", "   :widths: 20 80", ""]
    for verb in verbs:
        index += [f"   * - :doc:`{verb}`", f"     - {rst_text(helps.get(verb) or '')}"]
    index += ["", ".. toctree::", "   :hidden:", "", *(f"   {v}" for v in verbs), ""]
    (out / "index.rst").write_text("\n".join(index))
    for verb, p in sub.choices.items():
        page = [f".. _cli-{verb}:", "", _title(f"microcyl {verb}"), "",
                rst_text(p.description or helps.get(verb) or ""), "",
                ".. code-block:: text", "",
                *("   " + line for line in p.format_usage().splitlines()), ""]
        page += _options_rst(p, f"microcyl-{verb}")
        if p.epilog:
            page += ["", ".. code-block:: text", "",
                     *("   " + line for line in p.epilog.splitlines()), ""]
        (out / f"{verb}.rst").write_text("\n".join(page))
    return verbs


# -- the API reference -----------------------------------------------------------------------
def api_modules() -> list[str]:
    """The modules documented: the packages, then every module below ``reports`` that has an
    ``__all__``, then modules named in an ``__all__`` (brdf.terms, ...) not yet listed."""
    names = list(API_PACKAGES)
    for top in WALKED:
        pkg = importlib.import_module(top)
        names.append(top)
        for info in pkgutil.walk_packages(pkg.__path__, top + "."):
            if info.name.rsplit(".", 1)[-1].startswith("_"):     # __main__ runs the CLI
                continue
            mod = importlib.import_module(info.name)
            if getattr(mod, "__all__", None):
                names.append(info.name)
    k = 0
    while k < len(names):
        mod = importlib.import_module(names[k])
        for n in getattr(mod, "__all__", ()):
            obj = getattr(mod, n, None)
            if inspect.ismodule(obj) and obj.__name__ not in names:
                names.append(obj.__name__)
        k += 1
    return names


def _directive(obj) -> str:
    if inspect.isclass(obj):
        return "autoclass"
    if inspect.isfunction(obj) or inspect.isbuiltin(obj) or callable(obj):
        return "autofunction"
    return "autodata"


def attr_doc(module: str, name: str, obj) -> list[str]:
    """The ``#:`` comment that documents ``name`` where it is defined: in ``module`` or any
    loaded module of the same top-level package holding the same object under that name."""
    from sphinx.pycode import ModuleAnalyzer

    top = module.split(".")[0]
    candidates = [module] + sorted(m for m in list(sys.modules)
                                   if m == top or m.startswith(top + "."))
    for modname in candidates:
        mod = sys.modules.get(modname)
        if mod is None or getattr(mod, name, None) is not obj:
            continue
        try:
            docs = ModuleAnalyzer.for_module(modname).find_attr_docs()
        except Exception:          # a module without source (a C extension): no comment
            continue
        if ("", name) in docs:
            return [line for line in docs[("", name)]]
    return []


def _foreign_members(cls) -> list[str]:
    """The public attributes a class's own dictionary holds but another library wrote
    (matplotlib gives each Artist subclass a generated ``set`` with matplotlib's docstring and
    roles): not ours to document."""
    ours = tuple(API_PACKAGES) + tuple(WALKED)
    return sorted(n for n, v in vars(cls).items() if not n.startswith("_") and callable(v)
                  and not str(getattr(v, "__module__", "") or "").startswith(ours))


def write_api_pages(out: Path) -> list[str]:
    """One page a module; returns the module names."""
    out.mkdir(parents=True, exist_ok=True)
    modules = api_modules()
    seen: dict = {}
    for name in modules:
        mod = importlib.import_module(name)
        public = list(getattr(mod, "__all__", ()))
        page = [_title(name), "", f".. automodule:: {name}", "   :no-members:", ""]
        submods = [n for n in public if inspect.ismodule(getattr(mod, n, None))]
        objs = [n for n in public if n not in submods and hasattr(mod, n)]
        if submods:
            page += ["Modules: " + ", ".join(f":mod:`{getattr(mod, n).__name__}`"
                                             for n in submods), ""]
        data = [n for n in objs if _directive(getattr(mod, n)) == "autodata"]
        code = [n for n in objs if n not in data]
        if code:
            page += [".. autosummary::", "   :nosignatures:", "",
                     *(f"   {n}" for n in code), ""]
        if data:
            page += ["Constants: " + ", ".join(f":data:`{name}.{n}`" for n in data), ""]
        for n in code + data:
            obj = getattr(mod, n)
            kind = _directive(obj)
            key = id(obj)
            dup = key in seen or f"{name}.{n}" in modules
            if kind == "autodata":
                key = (n, id(obj))        # a small int is one object under many names
                page += [f".. py:data:: {n}", f"   :module: {name}"]
                if key in seen:
                    page.append("   :no-index:")
                page += ["", *("   " + _escape_bars(line) for line in attr_doc(name, n, obj))]
                if key in seen:
                    page += ["", f"   The same object as :data:`{seen[key]}`."]
                seen.setdefault(key, f"{name}.{n}")
                page.append("")
                continue
            page.append(f".. {kind}:: {name}.{n}")
            if kind == "autoclass" and key not in seen:
                page.append("   :members:")
                foreign = _foreign_members(obj)
                if foreign:
                    page.append("   :exclude-members: " + ", ".join(foreign))
            if dup:
                page.append("   :no-index:")
            if key in seen:
                page += ["", f"   The same object as :obj:`{seen[key]}`."]
            seen.setdefault(key, f"{name}.{n}")
            page.append("")
        if not public:
            page += ["This package exports its parts as modules; see the pages below.", ""]
        (out / f"{name}.rst").write_text("\n".join(page))
    return modules


# -- docstrings: |x| is an absolute value, not a substitution ----------------------------------
_BARS = re.compile(r"(?<!\\)\|")


def _escape_bars(line: str) -> str:
    """``|`` outside backquoted text escaped (``|x|`` in prose means an absolute value)."""
    parts = re.split(r"(`+[^`]*`+)", line)
    return "".join(p if p.startswith("`") else _BARS.sub(r"\\|", p) for p in parts)


def escape_docstring_bars(app, what, name, obj, options, lines):
    """Escape ``|`` in docstring prose; literal blocks, directives' bodies (math), doctests
    and simple tables (lines of ``=`` rules) are left as written."""
    literal_indent = None
    in_doctest = False
    for k, line in enumerate(lines):
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None:
            if not stripped or indent > literal_indent:
                continue
            literal_indent = None
        if in_doctest:
            if stripped:
                continue
            in_doctest = False
        if stripped.startswith(">>>"):
            in_doctest = True
            continue
        if stripped.endswith("::"):
            literal_indent = indent
            if not stripped.startswith(".."):
                lines[k] = _escape_bars(line)
            continue
        lines[k] = _escape_bars(line)


def write_presets(path: Path) -> None:
    """The presets' threads as a table, read from :data:`brdf.PRESETS`."""
    import brdf

    cols = ("eta", "albedo", "kd", "gamma_s", "gamma_v", "area", "offsets", "lengths")
    fmt = lambda v: ", ".join(f"{x:.4g}" for x in v) if isinstance(v, tuple) else f"{v:.4g}"
    lines = [".. list-table::", "   :header-rows: 1", "", "   * - preset", "     - thread",
             *(f"     - {c}" for c in cols)]
    for name in brdf.PRESETS:
        fab = brdf.fabric(name)
        for j, t in enumerate(fab.threads, 1):
            lines += [f"   * - ``{name}``" if j == 1 else "   * -", f"     - T{j}",
                      *(f"     - {rst_text(fmt(getattr(t, c)))}" for c in cols)]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def _generate(app):
    root = Path(app.srcdir) / "_generated"
    write_presets(root / "presets.rst")
    verbs = write_cli_pages(root / "cli")
    modules = write_api_pages(root / "api")
    index = [_title("API reference"), "",
             "Every public name of each package (its ``__all__``), from its docstring. Packages",
             "first; a name exported by several modules is indexed where it appears first.", "",
             ".. toctree::", "   :maxdepth: 1", "", *(f"   {m}" for m in modules), ""]
    (root / "api" / "index.rst").write_text("\n".join(index))
    app.config.microcyl_generated = {"verbs": verbs, "modules": modules}


def setup(app):
    app.add_config_value("microcyl_generated", {}, "env")
    app.connect("builder-inited", _generate)
    app.connect("autodoc-process-docstring", escape_docstring_bars, priority=600)
    return {"version": "1", "parallel_read_safe": True}
