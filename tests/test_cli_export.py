"""`microcyl export` run as a user runs it: a preset to glTF and OpenPBR, the fidelity on the
terminal and beside the file, the export read back by `microcyl eval`, refusals in one line."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
from pathlib import Path

from brdf.baselines import Charlie

ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}


def microcyl(*args, cwd):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV, cwd=cwd,
                          capture_output=True, text=True, timeout=300)


def test_export_gltf_prints_fidelity_and_reads_back(tmp_path):
    r = microcyl("export", "silk_shot", "-o", "silk.glb", "--grid", "3x6", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert "gltf (charlie projection) -> silk.glb" in out
    assert "relative L2 error of f_r cos cos: luminance" in out and "CIEDE2000" in out
    assert "cannot follow: anisotropy" in out and "cannot follow: colour shift" in out
    doc = json.loads((tmp_path / "silk.glb.fidelity.json").read_text())
    assert doc["target"] == "gltf" and doc["fidelity"]["grid"]["pairs"] == 18 * 18
    v = doc["projection"]["values"]
    e = microcyl("eval", "silk.glb", "--wi", "30,0", "--wo", "40,180", "--json", cwd=tmp_path)
    assert e.returncode == 0, e.stderr
    got = np.array(json.loads(e.stdout)["f_r"])
    t1, t2 = np.radians(30), np.radians(40)
    wi = np.array([np.sin(t1), 0, np.cos(t1)])
    wo = np.array([-np.sin(t2), 0, np.cos(t2)])
    ref = Charlie(base=tuple(v["base"]), sheen=tuple(v["sheen"]),
                  roughness=v["roughness"]).eval(wi, wo)
    assert np.allclose(got, ref, rtol=1e-6)


def test_export_refusals_are_one_line(tmp_path):
    bad = [(("export", "velvet", "--to", "gltf", "-o", "v.mtlx"), "must end in .gltf, .glb"),
           (("export", "velvet", "-o", "v.obj"), "must end in .json, .xml, .mtlx, .gltf, .glb, .py, .blend"),
           (("export", "velvet", "-o", "v.glb", "--grid", "4by8"), "--grid '4by8'"),
           (("export", "velvet", "-o", "v.glb", "--draws", "-1"), "--draws -1")]
    procs = [subprocess.Popen([sys.executable, "-m", "reports", *argv], env=ENV, cwd=tmp_path,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for argv, _ in bad]                      # side by side: each pays the start-up
    for (argv, words), p in zip(bad, procs):
        out, err = p.communicate(timeout=300)
        r = subprocess.CompletedProcess(argv, p.returncode, out, err)
        assert r.returncode != 0 and words in r.stderr, (argv, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert list(tmp_path.iterdir()) == []
