"""The layout rules of CONTRIBUTING.md, checked on the source (ast, nothing imported).

Fails on what issue 26 requires: no upward import (brdf <- gonio <- analysis <- reports), no
import circle, at most 25 modules directly in reports/ (once it is split by concern), at most
10 imports inside functions, each of a costly library or with a comment saying which one it
defers, no module over 400 lines and no function over 80. Prints, without failing, the modules
no test imports by name.
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


def test_test_layout_reported():
    """CONTRIBUTING.md's Tests: tests by topic; printed, not failed: the modules that no test
    module imports by name and that have no doctest (exercised only through other modules or
    the command line's end-to-end tests)."""
    tests = "\n".join(p.read_text() for p in (ROOT / "tests").glob("*.py"))
    unnamed = []
    for name, path in MODULES.items():
        pkg, _, leaf = name.rpartition(".")
        if path.name in ("__init__.py", "__main__.py") or ">>> " in path.read_text():
            continue
        if not (re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", tests) or
                re.search(rf"from {re.escape(pkg)} import [^\n]*\b{leaf}\b", tests)):
            unnamed.append(name)
    print(f"\n{len(unnamed)} modules with no doctest that no test imports by name:",
          *unnamed or ["none"], sep="\n  ")
