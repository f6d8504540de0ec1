"""The documentation site loads nothing from another host (docs/_ext/microcyl_offline.py):
the scanner that `make docs` runs on the built site finds what a page or stylesheet loads
and leaves links in text alone; a built site, where there is one, passes it."""

import importlib
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
offline = importlib.import_module("microcyl_offline")


@pytest.mark.parametrize("html, expected", [
    ('<script src="https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js"></script>',
     ["<script src=https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js>"]),
    ('<link rel="stylesheet" href="//fonts.googleapis.com/css?family=Lato">',
     ["<link href=//fonts.googleapis.com/css?family=Lato>"]),
    ('<link rel="preload" as="font" href="HTTPS://x.org/f.woff2">',
     ["<link href=HTTPS://x.org/f.woff2>"]),
    ('<img src="a.png" srcset="a.png, https://x.org/a2.png 2x">',
     ["<img srcset=https://x.org/a2.png>"]),
    ('<div style="background: url(\'https://x.org/b.png\')"></div>',
     ["<div style: https://x.org/b.png>"]),
    ("<style>@import 'https://x.org/s.css';</style>", ["<style>: https://x.org/s.css"]),
    ('<iframe src="https://www.youtube.com/embed/x"></iframe>',
     ["<iframe src=https://www.youtube.com/embed/x>"]),
])
def test_scanner_finds_remote_loads(html, expected):
    assert offline.html_remote(html) == expected


def test_scanner_leaves_links_and_local_files_alone():
    html = ('<a href="https://doi.org/10.1145/2451236.2451240">the paper</a>'
            '<link rel="canonical" href="https://example.org/docs/">'
            '<link rel="stylesheet" href="../_static/styles/theme.css?digest=1">'
            '<script src="_static/mathjax/tex-chtml.js"></script>'
            '<img src="../_images/sphx_glr_plot_01_lobes_001.png" alt="x">'
            '<p>see https://www.mathjax.org</p><svg xmlns="http://www.w3.org/2000/svg"></svg>')
    assert offline.html_remote(html) == []


def test_offline_resources_walks_pages_and_stylesheets(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "index.html").write_text('<script src="_static/a.js"></script>')
    (tmp_path / "sub" / "page.html").write_text(
        '<script src="https://cdn.x/m.js"></script><script src="https://cdn.x/n.js"></script>')
    (tmp_path / "theme.css").write_text("@font-face{src:url(https://fonts.x/a.woff2)}")
    (tmp_path / "ok.css").write_text("@font-face{src:url(../webfonts/a.woff2)}")
    assert offline.offline_resources(tmp_path) == {
        "sub/page.html": ["<script src=https://cdn.x/m.js>", "<script src=https://cdn.x/n.js>"],
        "theme.css": ["https://fonts.x/a.woff2"]}


def test_docs_configuration_serves_mathjax_from_the_build():
    """conf.py names the offline MathJax and the check; the package sets mathjax_path to a
    path inside the build (where the docs extra is installed)."""
    conf = (DOCS / "conf.py").read_text()
    assert '"sphinx-mathjax-offline"' in conf and '"microcyl_offline"' in conf
    pytest.importorskip("sphinx", reason="the docs extra (`make docs` installs it) is not "
                        "installed")
    mod = pytest.importorskip("sphinx-mathjax-offline", reason="the docs extra is not installed")
    ship = Path(mod.__file__).parent / "static" / "mathjax"
    assert (ship / "tex-chtml.js").is_file() and (ship / "output" / "chtml" / "fonts").is_dir()

    class App:
        class config:
            mathjax_path = "https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js"

        def connect(self, *args, **kwargs):
            pass

    app = App()
    mod.setup(app)
    assert app.config.mathjax_path == "mathjax/tex-chtml.js"


def test_built_site_loads_nothing_from_another_host():
    """The site `make docs` built last, where there is one (CI runs the same check at the end
    of `make docs`)."""
    html = DOCS / "_build" / "html"
    if not (html / "index.html").is_file():
        pytest.skip("no built site (docs/_build/html): `make docs` builds it and checks it")
    assert offline.offline_resources(html) == {}
    assert (html / "_static" / "mathjax" / "tex-chtml.js").is_file()


def test_thumbnail_cut_from_one_panel(tmp_path):
    """A thumbnail named in microcyl_thumbnail_crops is remade from its box of the figure, at
    sphinx-gallery's thumbnail size; a figure a script skipped is left alone."""
    from PIL import Image
    images = tmp_path / "gallery" / "images"
    (images / "thumb").mkdir(parents=True)
    figure = Image.new("RGB", (900, 600), "white")
    figure.paste(Image.new("RGB", (300, 300), "red"), (0, 0))      # the first panel
    figure.save(images / "sphx_glr_plot_x_001.png")

    class App:
        srcdir = str(tmp_path)

        class config:
            sphinx_gallery_conf = {"thumbnail_size": (400, 280)}
            microcyl_thumbnail_crops = {"gallery/plot_x": (1, (0, 0, 1 / 3, 0.5)),
                                        "gallery/plot_skipped": (1, (0, 0, 0.5, 0.5))}

    offline.crop_thumbnails(App())
    with Image.open(images / "thumb" / "sphx_glr_plot_x_thumb.png") as thumb:
        assert thumb.size == (400, 280)
        r, g, b, a = thumb.convert("RGBA").getpixel((200, 140))
        assert (r, g, b, a) == (255, 0, 0, 255)
    assert not (images / "thumb" / "sphx_glr_plot_skipped_thumb.png").exists()
