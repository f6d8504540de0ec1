"""The layout rules of CONTRIBUTING.md, checked on the source (ast, nothing imported).

Fails on what issue 26 requires: no upward import (brdf <- gonio <- analysis <- reports), no
import circle, at most 25 modules directly in reports/ (once it is split by concern), at most
10 imports inside functions, each of a costly library or with a comment saying which one it
defers, no module over 400 lines and no function over 80, every module with a doctest or a
test that names it (a verb module: a test that runs its verb), and no verb module of
reports/cli/ writing a file itself.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ("brdf", "gonio", "analysis", "reports")
#: Libraries imported on use because they cost the command line about a second each (or are
#: optional at run time): CONTRIBUTING.md's documented lazy imports.
LAZY = {"matplotlib", "corner", "colour", "distributed", "mitsuba", "drjit", "arviz", "xarray"}
#: Circles being removed by another branch: (module, module) pairs, each to be deleted here
#: when that branch lands (the test says so when one is gone).
KNOWN_CYCLES: set[frozenset] = set()
MAX_REPORTS_TOP = 25
#: Issue 26: at most 10 imports inside functions, each of a costly library (LAZY) or with a
#: comment saying which costly library it defers; everything else sits at the module's top.
MAX_FUNCTION_IMPORTS = 10
MODULE_LINES, FUNCTION_LINES = 400, 80


def _modules() -> dict[str, Path]:
    out = {}
    for layer in LAYERS:
        for p in sorted((ROOT / layer).rglob("*.py")):
            parts = list(p.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = p
    return out


MODULES = _modules()
TREES = {name: ast.parse(p.read_text(), str(p)) for name, p in MODULES.items()}


def _targets(name: str, node) -> list[str]:
    """The project modules an import statement loads (a submodule, else its package)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name in MODULES]
    if node.level:                                  # relative: resolve against the package
        base = name.split(".")
        if not MODULES[name].name == "__init__.py":
            base = base[:-1]
        base = base[:len(base) - node.level + 1]
        mod = ".".join(base + ([node.module] if node.module else []))
    else:
        mod = node.module or ""
    out = []
    for a in node.names:
        sub = f"{mod}.{a.name}"
        if sub in MODULES:
            out.append(sub)
        elif mod in MODULES:
            out.append(mod)
    return sorted(set(out))


def _imports():
    """(module, node, in_function) for every import statement of the project."""
    for name, tree in TREES.items():
        inside = set()
        for fn in ast.walk(tree):
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                inside.update(id(n) for n in ast.walk(fn) if isinstance(n, (ast.Import,
                                                                           ast.ImportFrom)))
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                yield name, node, id(node) in inside


def _graph() -> dict[str, set]:
    graph = {name: set() for name in MODULES}
    for name, node, _ in _imports():
        for t in _targets(name, node):
            if t != name and not name.startswith(t + "."):   # a module's own package
                graph[name].add(t)
    return graph


def _cycles(graph) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]; counter[0] += 1
        stack.append(root); on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]; counter[0] += 1
                    stack.append(w); on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop(); on.discard(w); comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_no_upward_import():
    bad = []
    for name, node, _ in _imports():
        level = LAYERS.index(name.split(".")[0])
        for t in _targets(name, node):
            if LAYERS.index(t.split(".")[0]) > level:
                bad.append(f"{MODULES[name].relative_to(ROOT)}:{node.lineno} imports {t}")
    assert not bad, "imports flow brdf <- gonio <- analysis <- reports:\n" + "\n".join(bad)


def test_no_import_circle():
    cycles = _cycles(_graph())
    new = [c for c in cycles if not any(k <= set(c) for k in KNOWN_CYCLES)]
    gone = [k for k in KNOWN_CYCLES if not any(k <= set(c) for c in cycles)]
    for k in gone:
        print(f"KNOWN_CYCLES: {sorted(k)} is gone; delete its entry")
    assert not new, "import circles (function-level imports included):\n" + "\n".join(
        " <-> ".join(c) for c in new)


def _documented(name: str, node) -> bool:
    """A function-level import says why: a comment on its line or just above it."""
    lines = MODULES[name].read_text().splitlines()
    here = lines[node.lineno - 1:node.end_lineno]
    above = lines[max(0, node.lineno - 3):node.lineno - 1]
    return any("#" in line for line in here + above)


def test_function_level_imports_documented():
    found, undocumented = [], []
    for name, node, inside in _imports():
        if not inside:
            continue
        mod = node.names[0].name if isinstance(node, ast.Import) else (node.module or ".")
        where = f"{MODULES[name].relative_to(ROOT)}:{node.lineno} {mod}"
        found.append(where)
        if mod.split(".")[0] not in LAZY and not _documented(name, node):
            undocumented.append(where)
    print(f"\n{len(found)} imports inside functions (issue 26 asks for at most 10, "
          f"the documented lazy ones):\n  " + "\n  ".join(found))
    print(f"{len(undocumented)} of them without a comment saying which costly library they "
          f"defer:\n  " + "\n  ".join(undocumented))
    assert not undocumented, (
        "imports inside functions without a comment saying which costly library they defer "
        "(move them to the top):\n" + "\n".join(undocumented))
    assert len(found) <= MAX_FUNCTION_IMPORTS, (
        f"{len(found)} imports inside functions (at most {MAX_FUNCTION_IMPORTS}: import each "
        "costly library in one place, everything else at the top):\n" + "\n".join(found))


def test_reports_split_by_concern():
    top = sorted(p.name for p in (ROOT / "reports").glob("*.py"))
    if not (ROOT / "reports" / "plots").is_dir():
        pytest.skip(f"reports/ not split yet ({len(top)} modules directly in it; "
                    "/work/reorg/reorg.py does it)")
    assert len(top) <= MAX_REPORTS_TOP, (f"{len(top)} modules directly in reports/ "
                                         f"(at most {MAX_REPORTS_TOP}): {top}")


def test_sizes():
    """CONTRIBUTING.md: each module under ~400 lines, each function under ~80 (docstring
    included); fails on any over."""
    long_modules, long_functions = [], []
    for name, tree in TREES.items():
        n = len(MODULES[name].read_text().splitlines())
        if n > MODULE_LINES:
            long_modules.append(f"{MODULES[name].relative_to(ROOT)}: {n} lines")
        for fn in ast.walk(tree):
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = fn.end_lineno - fn.lineno + 1
                if length > FUNCTION_LINES:
                    long_functions.append(f"{MODULES[name].relative_to(ROOT)}:{fn.lineno} "
                                          f"{fn.name}: {length} lines")
    assert not long_modules and not long_functions, (
        f"modules over {MODULE_LINES} lines: {long_modules or 'none'}; functions over "
        f"{FUNCTION_LINES} lines: {long_functions or 'none'} (split them: CONTRIBUTING.md)")


def _verbs_run_by_tests() -> set[str]:
    """The verbs the tests run as a user would: the first argument of ``main([...])`` or of
    a ``microcyl(...)`` helper, and the word after ``"reports"`` in an argument list
    (``[sys.executable, "-m", "reports", VERB, ...]``)."""
    verbs = set()
    for path in (ROOT / "tests").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            words = []
            if isinstance(node, ast.Call) and node.args:
                name = getattr(node.func, "id", getattr(node.func, "attr", ""))
                first = node.args[0]
                if name == "main" and isinstance(first, ast.List) and first.elts:
                    words = first.elts[:1]
                elif name.endswith("microcyl"):
                    words = [first]
            elif isinstance(node, ast.List):
                items = [e.value if isinstance(e, ast.Constant) else None for e in node.elts]
                words = [node.elts[i + 1] for i, v in enumerate(items[:-1]) if v == "reports"]
            verbs.update(w.value for w in words
                         if isinstance(w, ast.Constant) and isinstance(w.value, str))
    return verbs


def _verbs_of(name: str) -> set[str]:
    """The verbs a ``reports.cli`` module registers (``sub.add_parser("VERB", ...)``)."""
    return {n.args[0].value for n in ast.walk(TREES[name])
            if isinstance(n, ast.Call) and getattr(n.func, "attr", "") == "add_parser"
            and n.args and isinstance(n.args[0], ast.Constant)}


def _public(name: str) -> list[str]:
    """The names of a module's ``__all__`` (a literal list or tuple), else none."""
    for node in TREES[name].body:
        if (isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "__all__"
                                                 for t in node.targets)
                and isinstance(node.value, (ast.List, ast.Tuple))):
            return [e.value for e in node.value.elts if isinstance(e, ast.Constant)]
    return []


def _public_name_used(name: str, tests: list[str]) -> bool:
    """Whether a test module uses a public name of module ``name`` through a package above
    it, which re-exports it (``gonio.read_alta``; ``from analysis.fit import (...,
    LockStep)``; ``from reports import plots`` then ``plots.plot_albedo``): the test
    exercises this module."""
    parts = name.split(".")
    names = "|".join(_public(name))
    if not names:
        return False
    for k in range(1, len(parts)):
        pkg, parent, leaf = ".".join(parts[:k]), ".".join(parts[:k - 1]), parts[k - 1]
        used = [rf"(?<![\w.]){re.escape(pkg)}\.({names})\b",
                rf"from {re.escape(pkg)} import (\([^)]*|[^\n]*)\b({names})\b"]
        for text in tests:
            if any(re.search(u, text) for u in used):
                return True
            if (parent and re.search(rf"from {re.escape(parent)} import [^\n]*\b{leaf}\b",
                                     text)
                    and re.search(rf"(?<![\w.]){leaf}\.({names})\b", text)):
                return True
    return False


def _untested_modules() -> list[str]:
    """The modules with no doctest that no test imports by name and, for a verb module of
    ``reports.cli``, none of whose verbs a test runs."""
    texts = [p.read_text() for p in (ROOT / "tests").glob("*.py")]
    tests = "\n".join(texts)
    run = _verbs_run_by_tests()
    unnamed = []
    for name, path in MODULES.items():
        pkg, _, leaf = name.rpartition(".")
        if path.name in ("__init__.py", "__main__.py") or ">>> " in path.read_text():
            continue
        if (re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", tests) or
                re.search(rf"from {re.escape(pkg)} import [^\n]*\b{leaf}\b", tests) or
                _public_name_used(name, texts)):
            continue
        if name.startswith("reports.cli.") and _verbs_of(name) & run:
            continue
        unnamed.append(name)
    return unnamed


def test_every_module_has_a_doctest_or_a_named_test():
    """CONTRIBUTING.md's Tests: every module is exercised by a doctest (an Example in its
    docstrings), a test that imports it by name, or, for a verb module of ``reports.cli``, a
    test that runs one of its verbs as a user would."""
    unnamed = _untested_modules()
    assert not unnamed, ("modules with no doctest, no test importing them by name and (verb "
                         "modules) no test running their verbs: add an Example or a test:\n  "
                         + "\n  ".join(unnamed))


#: Calls that write or remove files themselves: the builtin ``open``, gonio's atomic writer,
#: pathlib's and json's and csv's writers, numpy's savers, and os/shutil file operations.
WRITERS = {"open", "atomic_write", "write_text", "write_bytes", "dump", "writer", "save",
           "savez", "savez_compressed", "savetxt", "mkdir", "makedirs", "touch", "unlink",
           "rmtree", "replace", "rename", "remove", "copyfile", "copy", "move",
           "NamedTemporaryFile", "mkstemp"}
#: Of those, the names that are also ordinary methods (``str.replace``,
#: ``dataclasses.replace``, ``dict.copy``): writers only as ``os.X`` / ``shutil.X``.
AMBIGUOUS = {"replace", "rename", "remove", "copy", "move", "save"}


def _verb_modules() -> list[str]:
    """The modules of ``reports.cli.COMMAND_MODULES`` (read from its source)."""
    for node in TREES["reports.cli"].body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == \
                "COMMAND_MODULES":
            return [e.value for e in node.value.keys]      # {module: (verb, ...)}
    raise AssertionError("reports/cli/__init__.py has no COMMAND_MODULES")


def test_verb_modules_write_no_file_themselves():
    """CONTRIBUTING.md: a verb module parses, calls one workflow and prints. It opens,
    writes, renames or removes no file itself (the workflows in analysis/, gonio's writers
    and the report's and renderer's functions do), so every file a verb leaves is written
    where the rules of writing (atomic, locked, never through a link) are kept."""
    bad = []
    for name in _verb_modules():
        for node in ast.walk(TREES[name]):
            if not isinstance(node, ast.Call):
                continue
            f = node.func
            called = f.id if isinstance(f, ast.Name) else f.attr if isinstance(
                f, ast.Attribute) else ""
            owner = f.value.id if isinstance(f, ast.Attribute) and isinstance(
                f.value, ast.Name) else None
            if called not in WRITERS:
                continue
            if called in AMBIGUOUS and owner not in ("os", "shutil", "np", "numpy"):
                continue
            if called == "writer" and owner != "csv":
                continue
            bad.append(f"{MODULES[name].relative_to(ROOT)}:{node.lineno} {called}(")
    assert not bad, ("verb modules writing files themselves (move the writing into a "
                     "workflow of analysis/):\n" + "\n".join(bad))
