"""The promises of SECURITY.md that the sources themselves show: no code path that runs what a
file says (nothing unpickled, unmarshalled or shelved, no eval or exec, no yaml.load, no
shell). Pickling out (``pickle.dumps``, to hand a BRDF to a worker process) is no reading."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCES = sorted(p for pkg in ("brdf", "gonio", "analysis", "reports")
                 for p in (ROOT / pkg).rglob("*.py"))
#: Modules that turn bytes into objects that run code, and their readers.
UNSAFE_MODULES = {"pickle", "cPickle", "_pickle", "dill", "cloudpickle", "marshal", "shelve",
                  "yaml", "joblib"}
READERS = {"load", "loads", "Unpickler", "open", "unsafe_load", "full_load"}


def _problems(tree: ast.AST) -> list[str]:
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] in \
                UNSAFE_MODULES:
            out += [f"line {node.lineno}: imports {node.module}.{a.name}" for a in node.names
                    if a.name in READERS or a.name == "*"]
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        if isinstance(f, ast.Name) and f.id in ("eval", "exec", "compile", "__import__"):
            out.append(f"line {node.lineno}: {f.id}()")
        if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and (
                (f.value.id == "os" and f.attr in ("system", "popen"))
                or (f.value.id in UNSAFE_MODULES and f.attr in READERS)):
            out.append(f"line {node.lineno}: {f.value.id}.{f.attr}()")
        for kw in node.keywords:
            if kw.arg in ("shell", "allow_pickle") and not (
                    isinstance(kw.value, ast.Constant) and kw.value.value is False):
                out.append(f"line {node.lineno}: {kw.arg}={ast.unparse(kw.value)}")
    return out


def test_the_scan_finds_what_it_looks_for():
    code = ("pickle.loads(b)\nfrom yaml import load\nx = eval('1')\nimport subprocess\n"
            "subprocess.run('ls', shell=True)\nnp.load(p, allow_pickle=True)\nos.system('x')\n"
            "shelve.open(p)\n")
    assert len(_problems(ast.parse(code))) == 7
    assert _problems(ast.parse("fab.eval(wi, wo)\nsubprocess.run(['ls'], shell=False)\n"
                               "import pickle\npickle.dumps(fab)")) == []


def test_no_code_runs_what_a_file_says():
    assert len(SOURCES) > 50
    found = {str(p.relative_to(ROOT)): probs for p in SOURCES
             if (probs := _problems(ast.parse(p.read_text(encoding="utf-8"))))}
    assert found == {}
