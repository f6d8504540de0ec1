"""Every verb that takes a FABRIC, run as a user types it (a subprocess), with each kind of
source: a preset, a fit folder, and the fit exported as .json and as .xml
(:mod:`analysis.sources`); and the command line's surface: no abbreviations, options between
inputs, FABRIC as ``--fabric``, output suffixes refused before any work."""

import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import brdf
from reports.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
KINDS = ("preset", "fit", "json", "xml")


def start(*args, cwd=None):
    return subprocess.Popen([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                            cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def finish(proc, timeout=300):
    out, err = proc.communicate(timeout=timeout)
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


def microcyl(*args, cwd=None):
    return finish(start(*args, cwd=cwd))


def each(argv_of, kinds=KINDS):
    """Run ``argv_of(kind)`` for every kind at once (subprocesses side by side)."""
    procs = {k: start(*argv_of(k)) for k in kinds}
    return {k: finish(p) for k, p in procs.items()}


@pytest.fixture(scope="module")
def sources(fit_folder, tmp_path_factory):
    """kind -> the FABRIC text: velvet, the session's fit folder, and that fit exported by
    `microcyl export` as exported.json and exported.xml."""
    folder, _ = fit_folder
    d = tmp_path_factory.mktemp("exported")
    runs = {s: start("export", folder, "-o", d / f"exported{s}") for s in (".json", ".xml")}
    for s, p in runs.items():
        r = finish(p)
        assert r.returncode == 0, r.stderr
        assert "velvet: medians of gamma_s1, kd1" in r.stdout
    return {"preset": "velvet", "fit": str(folder), "json": str(d / "exported.json"),
            "xml": str(d / "exported.xml")}


def _fit_reference(folder: Path) -> brdf.Fabric:
    """The fit's fabric from its results.json by hand: velvet with masking off, rotation 0.25
    rad (the fixture's), gamma_s1 and kd1 at their medians, kd2 tied to kd1."""
    med = {k: v["median"] for k, v in
           json.loads((folder / "results.json").read_text())["parameters"].items()}
    t1, t2 = brdf.preset_threads("velvet")
    threads = (t1.replace(gamma_s=med["gamma_s1"], kd=med["kd1"]), t2.replace(kd=med["kd1"]))
    return brdf.Fabric(threads, name="velvet", masking=False, rotation=0.25)


def test_eval_of_each_source(sources, fit_folder):
    runs = each(lambda k: ["eval", sources[k], "--wi", "40,10", "--wo", "35,200", "--json"])
    wi = brdf.directions.from_angles(math.radians(40), math.radians(10))
    wo = brdf.directions.from_angles(math.radians(35), math.radians(200))
    refs = {"preset": brdf.fabric("velvet").eval(wi, wo)}
    refs["fit"] = refs["json"] = refs["xml"] = _fit_reference(fit_folder[0]).eval(wi, wo)
    assert not np.allclose(refs["preset"], refs["fit"])      # the fit is another fabric
    for kind, r in runs.items():
        assert r.returncode == 0, (kind, r.stderr)
        doc = json.loads(r.stdout)
        assert doc["kind"] == kind
        np.testing.assert_allclose(doc["f_r"], refs[kind], rtol=1e-9, err_msg=kind)


def test_eval_options_change_a_fit_and_keep_its_own(sources):
    """Variant flags given replace the source's; those not given keep it (the fit's masking
    off stays off)."""
    r = each(lambda k: ["eval", sources["fit"], "--wi", "40,10", "--wo", "35,200", "--json",
                        *(["--masking", "on"] if k == "on" else [])], kinds=("on", "own"))
    on, own = (json.loads(r[k].stdout) for k in ("on", "own"))
    assert own["options"]["masking"] is False and on["options"]["masking"] is True
    assert math.isclose(own["options"]["rotation"], 0.25)


def test_plot_lobes_of_every_kind_at_once(sources, tmp_path):
    out = tmp_path / "lobes.png"
    r = microcyl("plot", "lobes", sources["preset"], sources["fit"], "--fabric",
                 sources["json"], sources["xml"], "--resolution", "9", "-o", out)
    # exported.json and exported.xml share a label: refused by name, before drawing
    assert r.returncode == 1 and "'exported' given twice" in r.stderr and not out.exists()
    r = microcyl("plot", "lobes", sources["preset"], sources["fit"], "--fabric",
                 sources["xml"], "--resolution", "9", "-o", out)
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 1000 and "wrote" in r.stdout
    r = microcyl("plot", "slices", "--fabric", sources["json"], "--resolution", "9",
                 "-o", tmp_path / "s.png")
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("verb, extra, expect", [
    ("energy", ["--variants", "default", "--theta-step", "45", "--phi", "0", "--no-furnace",
                "--no-hemispherical", "--tol", "1e-2", "-q"], "Energy: directional albedos"),
    ("reciprocity", ["-n", "200", "--grid-step", "0", "--no-felts", "--variants",
                     "default"], "Reciprocity error"),
    ("sanity", [], "ok ("),
])
def test_physics_verbs_take_each_source(sources, verb, extra, expect):
    runs = each(lambda k: [verb, sources[k], *extra])
    for kind, r in runs.items():
        assert r.returncode == 0, (kind, r.stderr)
        assert expect in r.stdout
        label = {"preset": "velvet", "fit": "fit", "json": "exported", "xml": "exported"}[kind]
        assert label in r.stdout, (kind, r.stdout)


def test_render_of_each_source(sources, tmp_path):
    runs = each(lambda k: ["render", "sphere", sources[k], "--width", "8", "--height", "6",
                           "--spp", "1", "--no-progress", "-o", tmp_path / f"{k}.png"])
    for kind, r in runs.items():
        assert r.returncode == 0, (kind, r.stderr)
        assert (tmp_path / f"{kind}.png").stat().st_size > 0
        assert "wrote" in r.stderr


def test_render_quiet_spellings(sources, tmp_path):
    """-q and the old --quiet: no progress bar and no 'wrote' line; --no-progress: the line
    stays."""
    runs = each(lambda k: ["render", "sphere", "velvet", "--width", "8", "--height", "6",
                           "--spp", "1", k, "-o", tmp_path / f"{k.strip('-')}.png"],
                kinds=("-q", "--quiet", "--no-progress"))
    assert runs["-q"].stderr == runs["--quiet"].stderr == ""
    assert "wrote" in runs["--no-progress"].stderr
    bar = runs["--no-progress"].stderr
    assert "tile/s" not in bar and "render sphere" not in bar       # no progress bar


def test_export_then_render_and_measure_the_xml(fit_folder, tmp_path):
    """`microcyl export fit/ -o fabric.xml` then `render sphere fabric.xml` (the issue's case)
    and `measure fabric.xml`: the fabric read back is the fit's."""
    folder, _ = fit_folder
    xml = tmp_path / "fabric.xml"
    r = microcyl("export", folder, "-o", xml)
    assert r.returncode == 0, r.stderr
    r = microcyl("render", "sphere", xml, "--width", "8", "--height", "6", "--spp", "1",
                 "--no-progress", "-o", tmp_path / "s.exr")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "s.exr").is_file() and (tmp_path / "s.png").is_file()
    r = microcyl("measure", xml, "--geometry", "plane:warp:45", "-q", "-o", tmp_path / "m.csv")
    assert r.returncode == 0, r.stderr and r.stderr == ""
    assert r.stdout.startswith("fabric: ")


def test_export_and_measure_of_each_source(sources, tmp_path):
    runs = each(lambda k: ["export", sources[k], "-o", tmp_path / f"{k}.xml"])
    for kind, r in runs.items():
        assert r.returncode == 0, (kind, r.stderr)
    # the fit and its exports export to the same bytes
    texts = {k: (tmp_path / f"{k}.xml").read_text() for k in KINDS}
    assert texts["fit"] == texts["json"] == texts["xml"] != texts["preset"]
    runs = each(lambda k: ["measure", sources[k], "--geometry", "plane:warp:45",
                           "--no-progress", "-o", tmp_path / f"{k}.csv"])
    for kind, r in runs.items():
        assert r.returncode == 0, (kind, r.stderr)
        assert (tmp_path / f"{kind}.csv").is_file()


@pytest.mark.slow      # two report pages with their renders: about 20 s on an idle 2-core machine
def test_report_of_a_fit_and_an_xml(sources, tmp_path):
    out = tmp_path / "rep"
    r = microcyl("report", "--fabric", sources["fit"], "--fabric", sources["xml"],
                 "--quality", "fast", "--no-progress", "-o", out)
    assert r.returncode == 0, r.stderr
    assert (out / "fit.html").is_file() and (out / "exported.html").is_file()
    assert list(json.loads((out / "summary.json").read_text())["fabrics"]) == \
        ["fit", "exported"]


@pytest.mark.parametrize("verb", ["eval", "render", "measure", "energy", "sanity",
                                  "export"])
def test_one_error_names_what_is_accepted(verb, tmp_path):
    argv = {"eval": ["--wi", "0,0", "--wo", "0,0"], "render": ["-o", tmp_path / "x.png"],
            "measure": ["-o", tmp_path / "x.csv"], "export": ["-o", tmp_path / "x.json"],
            "energy": [], "sanity": []}[verb]
    args = ([verb, "sphere", "denim"] if verb == "render" else [verb, "denim"]) + argv
    r = microcyl(*args)
    assert r.returncode == 1 and r.stderr.count("\n") == 1, r.stderr
    assert "FABRIC 'denim': not a preset (linen_plain" in r.stderr
    assert "a `microcyl fit` output folder" in r.stderr and ".xml fabric file" in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_hostile_xml_is_one_line(tmp_path):
    bomb = tmp_path / "bomb.xml"
    bomb.write_text('<?xml version="1.0"?><!DOCTYPE b [<!ENTITY a "aaaaaaaa">'
                    '<!ENTITY b "&a;&a;&a;&a;&a;&a;">]><bsdf type="microcylinder">'
                    '<string name="fabric" value="&b;"/></bsdf>')
    r = microcyl("eval", bomb, "--wi", "0,0", "--wo", "0,0")
    assert r.returncode == 1 and "document type declaration" in r.stderr
    assert r.stderr.count("\n") == 1


# --------------------------------------------------------------------------- the parsers
def test_no_abbreviations(tmp_path):
    """`--out` is not taken as `--output` (argparse's prefix matching is off everywhere)."""
    t0 = time.perf_counter()
    r = microcyl("fit", tmp_path / "t.csv", "--fabric", "velvet", "--out", tmp_path / "o")
    assert r.returncode == 2 and "unrecognized arguments: --out" in r.stderr
    assert time.perf_counter() - t0 < 30 and list(tmp_path.iterdir()) == []
    parser = build_parser()
    with pytest.raises(SystemExit):
        parser.parse_args(["render", "sphere", "velvet", "--out", "x.png"])
    with pytest.raises(SystemExit):
        parser.parse_args(["plot", "lobes", "velvet", "--res", "9", "-o", "x.png"])


def test_fit_batch_takes_inputs_between_options(tmp_path):
    parser = build_parser()
    args = parser.parse_args(["fit-batch", "a.dat", "--sample", "3,22", "b.csv", "c.csv",
                              "--fabric", "linen_plain", "-o", "out"])
    assert args.inputs == ["a.dat", "b.csv", "c.csv"] and args.sample == "3,22"
    # as a user types it: the third input is read as an input (and is missing), not refused
    # as an unrecognized argument
    (tmp_path / "b.csv").write_text("theta_i,phi_i,theta_o,phi_o,f_r\n0,0,0,0,0.1\n")
    r = microcyl("fit-batch", tmp_path / "b.csv", "--sample", "3", tmp_path / "c.csv",
                 "--fabric", "linen_plain", "-o", tmp_path / "out")
    assert r.returncode == 1, r.stderr
    assert "unrecognized" not in r.stderr and "c.csv" in r.stderr
    assert not (tmp_path / "out").exists()


def test_plot_table_takes_the_preset_as_fabric(tmp_path):
    table = tmp_path / "t.csv"
    r = microcyl("measure", "linen_plain", "--geometry", "plane:warp:30", "-q", "-o", table)
    assert r.returncode == 0, r.stderr
    runs = {k: start("plot", "table", table, *argv, "-o", tmp_path / f"{k}.png")
            for k, argv in (("positional", ["linen_plain"]),
                            ("option", ["--fabric", "linen_plain"]))}
    for k, p in runs.items():
        r = finish(p)
        assert r.returncode == 0, (k, r.stderr)
        assert (tmp_path / f"{k}.png").is_file()


def test_fabric_given_twice_is_refused(tmp_path):
    r = microcyl("eval", "velvet", "--fabric", "silk_shot", "--wi", "0,0", "--wo", "0,0")
    assert r.returncode == 1 and "FABRIC given twice ('velvet' and 'silk_shot')" in r.stderr
    r = microcyl("eval", "--wi", "0,0", "--wo", "0,0")
    assert r.returncode == 1 and "FABRIC is required (positional or --fabric): a preset" \
        in r.stderr


@pytest.mark.parametrize("argv, message", [
    (["measure", "velvet", "-o", "x.txt"], "-o 'x.txt': must end in .exr, .csv, .binary, .alta"),
    (["measure", "velvet", "-o", "nowhere/x.exr"], "does not exist"),
    (["export", "velvet", "-o", "x.txt"], "-o 'x.txt': must end in .json, .xml"),
])
def test_output_refused_before_any_work(argv, message, tmp_path):
    t0 = time.perf_counter()
    r = microcyl(*argv, cwd=tmp_path)
    assert r.returncode == 1 and message in r.stderr, r.stderr
    assert time.perf_counter() - t0 < 30
    assert list(tmp_path.iterdir()) == []


def test_measure_txt_refused_before_a_long_measurement(tmp_path):
    """`measure -o x.txt` on a geometry that would take minutes: refused at once."""
    t0 = time.perf_counter()
    r = microcyl("measure", "velvet", "--geometry", "full:2", "-o", "x.txt", cwd=tmp_path)
    assert r.returncode == 1 and "must end in" in r.stderr
    assert time.perf_counter() - t0 < 30 and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [
    ["fit", "t.csv", "--fabric", "velvet", "-o", "o"],
    ["fit-batch", "t.csv", "--fabric", "velvet", "-o", "o"],
    ["fit-measured", "-o", "o"], ["measure", "velvet", "-o", "t.exr"],
    ["render", "sphere", "velvet", "-o", "x.png"], ["report"], ["energy", "velvet"],
])
def test_long_verbs_have_the_same_flags(argv):
    parser = build_parser()
    for flags, progress_off, quiet in ((["--no-progress"], True, False), (["-q"], False, True),
                                       (["--quiet"], False, True), ([], False, False)):
        args = parser.parse_args(argv + flags)
        assert (args.no_progress, args.quiet) == (progress_off, quiet), (argv, flags)
