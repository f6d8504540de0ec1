"""Sphinx configuration of microcyl's documentation (``make docs``)."""

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(DOCS / "_ext"))

# The measured data the tutorials read: ../shared/data beside the repository (never copied
# into it); the scripts skip with a note where it is absent.
os.environ.setdefault("MICROCYL_DOCS_DATA", str((ROOT / ".." / "shared" / "data").resolve()))
# Where the scripts write their tables, fits and renders (inside the build folder).
os.environ.setdefault("MICROCYL_DOCS_WORK", str(DOCS / "_build" / "work"))
# Mitsuba's JIT variants need a shared LLVM; Debian's libllvm19 works (see the install page).
_LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if not os.environ.get("DRJIT_LIBLLVM_PATH") and os.path.exists(_LLVM):
    os.environ["DRJIT_LIBLLVM_PATH"] = _LLVM
os.environ.setdefault("MPLBACKEND", "agg")

project = "microcyl"
author = "The microcyl developers"
copyright = "2026, the microcyl developers"
try:
    from importlib.metadata import version as _version
    release = _version("microcyl")
except Exception:            # a source tree that is not installed
    release = "0.1.0"
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    # MathJax 3 served from the build (_static/mathjax), not a CDN: equations render offline
    "sphinx-mathjax-offline",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "microcyl_docs",
    "microcyl_offline",      # figures link to their full size; the build fails on remote loads
]

exclude_patterns = ["_build", "**/GALLERY_HEADER.rst", "tutorials_src", "gallery_src"]
templates_path = []
html_static_path = ["_static"]
html_css_files = ["microcyl.css"]

# literal blocks (::) are mostly commands: no highlighting unless a block names its language
highlight_language = "text"
# "--free" stays two hyphens (no en dashes), quotes stay straight
smartquotes = False

html_theme = "pydata_sphinx_theme"
html_title = "microcyl"
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    # the tutorials' and gallery's scripts give the right-hand column to their figures (pages
    # named one by one: a page matching two wildcard patterns is a warning)
    "secondary_sidebar_items": {"**": ["page-toc"], **{
        f"{out}/{script.stem}": [] for src, out in (("tutorials_src", "tutorials"),
                                                    ("gallery_src", "gallery"))
        for script in sorted((DOCS / src).glob("plot_*.py"))}},
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}

# autodoc / numpydoc: docstrings are numpydoc; class members are documented by autodoc.
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"
autosummary_generate = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()

intersphinx_mapping = {}

sphinx_gallery_conf = {
    "examples_dirs": ["tutorials_src", "gallery_src"],
    "gallery_dirs": ["tutorials", "gallery"],
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "plot_gallery": "True",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "abort_on_example_error": False,
    "only_warn_on_example_error": False,
    "min_reported_time": 0,
    # the execution-time tables load jQuery and DataTables from CDNs (pages that would not
    # work offline, microcyl_offline.py); the build's own timing is not a page for users
    "write_computation_times": False,
}

# Thumbnails of figures of several panels, cut from the figure (microcyl_offline.py): the
# page's figure number and the box (left, top, right, bottom as fractions of its width and
# height); at thumbnail size the whole figure shows its panels as empty frames.
microcyl_thumbnail_crops = {
    "gallery/plot_01_lobes": (1, (0.0, 0.0, 0.34, 0.31)),
    "gallery/plot_02_slices": (1, (0.0, 0.0, 0.5, 0.5)),
    "gallery/plot_07_table": (1, (0.0, 0.07, 0.33, 0.92)),
    "gallery/plot_08_variants": (1, (0.0, 0.0, 0.34, 1.0)),
    "gallery/plot_10_fit_lobes": (1, (0.0, 0.0, 0.36, 1.0)),
}
