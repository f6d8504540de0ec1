"""The explorer in a Jupyter kernel, as a notebook runs it: a notebook whose cell calls
``explore(brdf.fabric("velvet"))`` executed by nbclient in a real ipykernel; its output is
the app's (Bokeh's server display, served from 127.0.0.1 by the kernel, nothing on stderr),
and a client of that server gets the document with every view and control by name.

Skipped, with the reason, where nbclient or ipykernel is missing (the ``dev`` extra has
them). The page in a real Jupyter front end (Notebook 7, headless Chromium: views drawn,
a slider moved with the keyboard) was checked by hand (docs/guide/explore.rst).
"""

import re
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat", reason="nbformat is not installed (dev extra)")
nbclient = pytest.importorskip("nbclient", reason="nbclient is not installed (dev extra)")
pytest.importorskip("ipykernel", reason="ipykernel is not installed (dev extra)")

ROOT = Path(__file__).resolve().parents[1]
CELL = 'import brdf\nfrom reports.explore import explore\nexplore(brdf.fabric("velvet"))'


def test_a_notebook_cell_shows_the_app_served_by_its_kernel(tmp_path):
    from bokeh.client import pull_session
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(CELL)]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    with client.setup_kernel():
        client.execute_cell(nb.cells[0], 0)
        outs = nb.cells[0].outputs
        kinds = [o.output_type for o in outs]
        assert "error" not in kinds and "stream" not in kinds, outs     # no warning either
        shown = [o for o in outs if "application/vnd.bokehjs_exec.v0+json" in o.get("data", {})]
        assert len(shown) == 1
        assert shown[0].metadata["application/vnd.bokehjs_exec.v0+json"]["server_id"]
        urls = re.findall(r'"(http://127\.0\.0\.1:\d+)/autoload\.js', shown[0].data["text/html"])
        assert len(urls) == 1, shown[0].data["text/html"]
        with pull_session(url=urls[0] + "/") as session:     # the kernel builds the document
            names = {m.name for m in session.document.models if m.name}
    views = {f"view-{v}" for v in ("lobe", "hemisphere", "slice", "sphere", "albedo")}
    assert views <= names
    assert {"param-gamma_s1", "param-theta_i", "param-plane", "param-masking"} <= names
    assert "src-lobe" in names
