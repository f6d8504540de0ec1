"""The site works offline, and its figures open at full size.

- ``offline_resources(html_dir)``: every resource a built page or stylesheet loads from
  another host (``<script src>``, ``<link rel=stylesheet|icon|preload href>``, ``<img src>``,
  ``srcset``, ``<iframe>``, CSS ``url()`` and ``@import``); links in text (``<a href>``, to
  papers and databases) are not loaded and not listed. ``make docs`` fails when there is one
  (the ``build-finished`` hook below), and tests/test_docs_offline.py checks the scanner.
- sphinx-gallery's figures (its ``imgsgnode``) are wrapped in a link to the image itself, so
  that a figure shown narrower than its pixels opens at full size in the browser.
- ``microcyl_thumbnail_crops`` (conf.py): the gallery thumbnail of a figure of several panels
  is cut from one panel of it, so that it does not show as empty frames.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser
from pathlib import Path

#: What a tag loads: (tag, attribute); <link> only for the rel values below.
LOADED = {("script", "src"), ("img", "src"), ("img", "srcset"), ("source", "src"),
          ("source", "srcset"), ("iframe", "src"), ("embed", "src"), ("object", "data"),
          ("video", "src"), ("video", "poster"), ("audio", "src"), ("track", "src"),
          ("input", "src"), ("image", "href"), ("use", "href")}
LINK_RELS = {"stylesheet", "icon", "shortcut", "preload", "modulepreload", "prefetch",
             "manifest", "apple-touch-icon", "mask-icon"}
_REMOTE = re.compile(r"^\s*(?:https?:)?//", re.IGNORECASE)
_CSS_URL = re.compile(r"""url\(\s*['"]?([^'")\s]+)|@import\s+['"]([^'"]+)""", re.IGNORECASE)


def _remote(value: str) -> list[str]:
    """The URLs on another host in an attribute value (a srcset holds several)."""
    parts = [p.strip().split()[0] for p in value.split(",") if p.strip()] if value else []
    return [p for p in parts if _REMOTE.match(p)]


def css_remote(text: str) -> list[str]:
    """The URLs on another host that CSS text loads (``url(...)``, ``@import``).

    >>> css_remote("a{background:url(https://x.org/a.png)} @import '//cdn.x/y.css';")
    ['https://x.org/a.png', '//cdn.x/y.css']
    >>> css_remote("@font-face{src:url(../webfonts/fa.woff2)}")
    []
    """
    return [a or b for a, b in _CSS_URL.findall(text) if _REMOTE.match(a or b)]


class _Scanner(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.found: list[str] = []
        self._in_style = False

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        rels = set((attrs.get("rel") or "").lower().split())
        for name, value in attrs.items():
            if value is None:
                continue
            if (tag, name) in LOADED or (tag == "link" and name == "href" and rels & LINK_RELS):
                self.found += [f"<{tag} {name}={u}>" for u in _remote(value)]
            elif name == "style":
                self.found += [f"<{tag} style: {u}>" for u in css_remote(value)]
        self._in_style = tag == "style"

    def handle_endtag(self, tag):
        self._in_style = False

    def handle_data(self, data):
        if self._in_style:
            self.found += [f"<style>: {u}" for u in css_remote(data)]


def html_remote(text: str) -> list[str]:
    """What an HTML page loads from another host, one string each.

    >>> html_remote('<script src="https://cdn.x/mathjax.js"></script>'
    ...             '<a href="https://doi.org/10.1145/x">the paper</a>'
    ...             '<link rel="stylesheet" href="_static/a.css">')
    ['<script src=https://cdn.x/mathjax.js>']
    """
    scanner = _Scanner()
    scanner.feed(text)
    scanner.close()
    return scanner.found


def offline_resources(html_dir) -> dict[str, list[str]]:
    """Per file (relative path) of a built site, what it loads from another host: every
    .html page and every .css file; empty when the site is self-contained."""
    html_dir = Path(html_dir)
    found = {}
    for path in sorted(html_dir.rglob("*")):
        if path.suffix == ".html":
            hits = html_remote(path.read_text(encoding="utf-8", errors="replace"))
        elif path.suffix == ".css":
            hits = css_remote(path.read_text(encoding="utf-8", errors="replace"))
        else:
            continue
        if hits:
            found[path.relative_to(html_dir).as_posix()] = hits
    return found


def _check_offline(app, exc):
    if exc is not None or app.builder.format != "html":
        return
    found = offline_resources(app.outdir)
    if found:
        lines = [f"  {page}: {', '.join(hits[:3])}" + (" ..." if len(hits) > 3 else "")
                 for page, hits in list(found.items())[:10]]
        raise RuntimeError(f"{len(found)} built files load resources from another host "
                           "(the site must work offline):\n" + "\n".join(lines))


_SRC = re.compile(r'<img src="([^"]+)" srcset="([^"]*)"')


def _visit_linked(original):
    """sphinx-gallery's visitor of a figure, its <img> wrapped in a link to its largest
    image."""
    def visit(self, node):
        start = len(self.body)
        original(self, node)
        html = "".join(self.body[start:])
        m = _SRC.search(html)
        if m is None:                       # no srcset: Sphinx's own image visitor ran
            return
        target = m.group(2).split(",")[-1].strip().split()[0] or m.group(1)
        self.body[start:] = [f'<a class="reference internal image-reference" '
                             f'href="{target}">{html}</a>']
    return visit


def crop_thumbnails(app):
    """Remake the thumbnails named in ``microcyl_thumbnail_crops`` from a box of their figure
    (after sphinx-gallery has run the scripts), at sphinx-gallery's thumbnail size."""
    from PIL import Image
    src = Path(app.srcdir)
    size = app.config.sphinx_gallery_conf.get("thumbnail_size", (400, 280))
    for page, (number, (left, top, right, bottom)) in app.config.microcyl_thumbnail_crops.items():
        folder, name = page.rsplit("/", 1)
        figure = src / folder / "images" / f"sphx_glr_{name}_{number:03d}.png"
        thumb = src / folder / "images" / "thumb" / f"sphx_glr_{name}_thumb.png"
        if not figure.is_file():          # the script skipped its figure (no data, no LLVM)
            continue
        with Image.open(figure) as im:
            w, h = im.size
            panel = im.convert("RGBA").crop((round(left * w), round(top * h),
                                             round(right * w), round(bottom * h)))
        panel.thumbnail(size, Image.LANCZOS)
        canvas = Image.new("RGBA", size, (255, 255, 255, 0))
        canvas.paste(panel, ((size[0] - panel.width) // 2, (size[1] - panel.height) // 2))
        canvas.save(thumb)


def setup(app):
    app.add_config_value("microcyl_thumbnail_crops", {}, "env")
    # after sphinx-gallery's own builder-inited hook, which runs the scripts (priority 500)
    app.connect("builder-inited", crop_thumbnails, priority=800)
    from sphinx_gallery import directives as sgd
    app.add_node(sgd.imgsgnode, override=True,
                 html=(_visit_linked(sgd.visit_imgsg_html), sgd.depart_imgsg_html),
                 latex=(sgd.visit_imgsg_latex, sgd.depart_imgsg_latex))
    # after the other build-finished hooks (sphinx-mathjax-offline copies MathJax in one)
    app.connect("build-finished", _check_offline, priority=900)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
