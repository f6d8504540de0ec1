"""``build_report``: every fabric's page, the overview and summary.json, swapped in whole."""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

import brdf
from analysis.folderlock import output_lock
from gonio.atomic import file_mode
from gonio.progress import progress_bar
from gonio.terminal import shown
from reports.report.folder import (check_output_dir, check_report_folder, make_build_folder,
                                   swap_into_place, write_file, write_marker)
from reports.plots.common import series_styles
from reports.report.cards import cards
from reports.report.markup import (CSS_NAME, Markup, html, join, nav, now, page, plain_json,
                                   run_header, stylesheet, swatch, version)
from reports.report.overview import overview
from reports.report.page import Page
from reports.report.sec_energy import EnergyData
from reports.report.sec_fit import FitData
from reports.report.sec_renders import ENGINES, RendersData, check_engine
from reports.report.sections import FabricReport, run_section
from reports.prose import overview_sentence
from reports.report.settings import QUALITIES, SECTIONS
from reports.report_measured import measured_page, overview_table, read_measured

__all__ = ["build_report", "resolve_fabrics"]

_RESERVED = ("index", "overview", "summary")


def _items(fabrics) -> list:
    if fabrics is None:
        fabrics = tuple(brdf.PRESETS)
    if isinstance(fabrics, str):
        fabrics = (fabrics,)
    if isinstance(fabrics, dict):
        return list(fabrics.items())
    items = []
    for f in fabrics:
        if isinstance(f, str):
            items.append((f, None))
        elif isinstance(f, tuple) and len(f) == 2:
            items.append(f)
        else:
            raise ValueError(f"fabrics must hold preset names or (name, BRDF) pairs; "
                             f"got {f!r}")
    return items


def resolve_fabrics(fabrics) -> dict:
    """Name -> BRDF, or None for a preset given by name; see :func:`build_report`.

    Raises
    ------
    ValueError
        For an empty selection, an unknown preset, a name given twice, or a name that cannot
        name a page.
    """
    items = _items(fabrics)
    if not items:
        raise ValueError("fabrics is empty; give at least one of " + ", ".join(brdf.PRESETS))
    out = {}
    for name, fab in items:
        if not isinstance(name, str) or not name or "/" in name or name.startswith(".") \
                or name in _RESERVED:
            raise ValueError(f"fabric name {name!r} cannot name a report page")
        if fab is None:
            brdf.check_preset(name)
        if name in out:
            raise ValueError(f"fabric {name!r} is given twice")
        out[name] = fab
    return out


def _sections(sections) -> list[str]:
    sections = list(dict.fromkeys(SECTIONS if sections is None else sections))
    bad = [s for s in sections if s not in SECTIONS]
    if bad:
        raise ValueError(f"unknown section {bad[0]!r}; valid: {', '.join(SECTIONS)}")
    return [s for s in SECTIONS if s in sections]


def _fabric_page(tmp: Path, name: str, given, sections, q, fit_results, bar) -> FabricReport:
    """Build every section of one fabric; return what was built (the page is not written)."""
    fab = given if given is not None else brdf.fabric(name)
    rep = FabricReport(name, fab)
    pg = Page(tmp, name, fab, q, preset=name if given is None else None,
              fit_results=fit_results.get(name))
    for sec in sections:
        bar.set_description(shown(f"{name}: {sec}"))
        rep.runs.append(run_section(sec, pg))
        bar.update(1)
    return rep


def _engines(reports: list[FabricReport]) -> str:
    """The render engines the report used, in words."""
    used = {v.get("engine") for r in reports if (d := r.data(RendersData)) is not None
            for v in (getattr(d, "renders", None) or {}).values()}
    used.discard(None)
    if not used:
        return "no renders (the renders section was not built)"
    return "; ".join(ENGINES.get(e, str(e)) for e in sorted(used))


def _lede(reports: list[FabricReport]) -> str:
    """The overview's first sentences: what the report holds and what the albedos show."""
    findings = {r.name: (e.findings() if (e := r.data(EnergyData)) is not None else {})
                for r in reports}
    return (f"{len(reports)} fabric{'s' if len(reports) != 1 else ''} of the microcylinder "
            "cloth model (Sadeghi et al. 2013), each on its own page with its lobes, "
            "albedos, reciprocity, sanity checks and renders. " + overview_sentence(findings))


def _run_info(reports, quality: str, command: str | None, generated: str) -> dict:
    """What was run, for every page's header."""
    return {"microcyl": version(), "generated": generated,
            "command": ("code", command or "reports.report.build_report(...) (Python)"),
            "renders": _engines(reports), "quality": quality}


def _fabric_header(rep: FabricReport, colour, run: dict) -> Markup:
    e = rep.data(EnergyData)
    if isinstance(rep.fabric, brdf.Fabric):
        what = ("A preset fabric" if rep.name in brdf.PRESETS else "A fabric") \
            + " of the microcylinder cloth model (Sadeghi et al. 2013)"
    elif isinstance(rep.fabric, brdf.Model):
        what = f"A fit of the baseline model {brdf.model_name(rep.fabric)} (not the microcylinder)"
    else:
        what = "A BRDF that is no microcylinder fabric"
    f = rep.data(FitData)
    fitted = "" if f is None else {
        True: "; its fit is adequate (the model describes the data to within its noise)",
        False: "; its fit is NOT adequate (the model does not describe the data to within "
               "its noise: see the fit section)"}.get(f.results.get("adequate"), "")
    lede = html("{}{}; energy: {}.", what, fitted,
                e.verdict() if e is not None else "not computed (no energy section)")
    return run_header(rep.name, lede, run, swatch(colour))


def _measured(tmp: Path, title: str, names, measured_fits) -> tuple[Markup, dict]:
    """Write measured.html; return the overview's section on it and the summary's entry."""
    mbody, summary = measured_page(tmp, measured_fits)
    write_file(tmp / "measured.html", page(f"{title}: fits to measured data",
                                           nav(names, "measured", True), mbody))
    return html('<section id="measured-fits"><h2>Fits to measured data</h2>{}'
                '<p>Details: <a href="measured.html">measured.html</a>.</p></section>',
                overview_table(measured_fits)), summary


def _write(tmp: Path, resolved: dict, sections, quality: str, fit_results: dict,
           measured_fits, title: str, progress: bool, render_engine: str = "auto",
           command: str | None = None) -> None:
    """Write the whole report into ``tmp``."""
    t_start = time.perf_counter()
    generated = now()
    q = dict(QUALITIES[quality], render_engine=render_engine)
    names = list(resolved)
    colours = {n: st["color"] for n, st in series_styles(names).items()}
    has_measured = measured_fits is not None
    bar = progress_bar(len(names) * len(sections) + 1, desc="report", unit="section",
                       enabled=progress)
    reports = [_fabric_page(tmp, name, given, sections, q, fit_results, bar)
               for name, given in resolved.items()]
    run = _run_info(reports, quality, command, generated)
    write_file(tmp / CSS_NAME, stylesheet())
    for rep in reports:
        write_file(tmp / f"{rep.name}.html",
                   page(f"{title}: {rep.name}", nav(names, rep.name, has_measured),
                        join(r.html(rep.name) for r in rep.runs),
                        _fabric_header(rep, colours[rep.name], run)))
    bar.set_description("overview")
    body = cards(tmp, reports, colours) + overview(tmp, reports, sections, q, colours)
    measured_summary = None
    if has_measured:
        section, measured_summary = _measured(tmp, title, names, measured_fits)
        body += section
    write_file(tmp / "index.html", page(title, nav(names, None, has_measured), body,
                                        run_header(title, _lede(reports), run)))
    bar.update(1)
    bar.close()
    doc = {"title": title, "generated": generated, "microcyl": version(), "command": command,
           "quality": quality, "sections": sections,
           "fabrics": {r.name: r.summary() for r in reports},
           "seconds": round(time.perf_counter() - t_start, 2)}
    if measured_summary is not None:
        doc["measured"] = measured_summary
    write_file(tmp / "summary.json", json.dumps(plain_json(doc), indent=1))
    write_marker(tmp)


def build_report(fabrics=None, out_dir="report", *, sections=None, progress=True,
                 quality="default", fit_results=None, measured=None,
                 title="microcyl report", render_engine="auto",
                 command: str | None = None) -> Path:
    """Write the HTML report on ``fabrics`` to ``out_dir``; return the path of index.html.

    Parameters
    ----------
    fabrics : str, sequence or mapping, optional
        Preset names (default every name in ``brdf.PRESETS``), or (name, BRDF) pairs, or a
        mapping name -> BRDF (any object with ``.eval``; presets are made with default
        options when only a name is given).
    out_dir : str or path
        Output folder. Replaced as a whole at the end if it already holds a report written
        by this function; an existing folder that is not a report is never touched.
    sections : sequence of str, optional
        Per-fabric sections, a subset of :data:`SECTIONS` (default all), in any order.
    progress : bool
        Show a tqdm bar over fabrics and sections.
    quality : {"default", "high", "fast"}
        Resolutions of plots and renders (:data:`QUALITIES`).
    fit_results : mapping of str to path, optional
        Fabric name -> ``results.json`` of a fit, shown in the "fit" section.
    measured : path, optional
        Output folder of ``microcyl fit-measured``: adds the page ``measured.html`` (fits to
        the measured felts and CUReT fabrics) and its table on the overview.
    title : str
        Title of the overview page.
    render_engine : {"auto", "builtin", "mitsuba"}
        The renders' engine (:func:`reports.report.sec_renders.render_engine`): ``auto`` is
        Mitsuba 3 where it runs in llvm_ad_rgb, else the built-in renderer.
    command : str, optional
        The command line that asked for the report, shown in every page's header (the
        CLI passes its own; default: the Python call).

    Returns
    -------
    pathlib.Path
        ``out_dir/index.html``.

    Raises
    ------
    ValueError
        For an unknown fabric, section or quality, or an output folder that is not a report;
        raised before any work.
    OSError
        If the output folder cannot be written; raised before any work.

    Notes
    -----
    Built in a temporary folder beside ``out_dir`` and renamed into place at the end; a
    failure or interrupt removes the temporary folder and leaves ``out_dir`` as it was. The
    build holds ``out_dir``'s lock, the one a fit or a batch there takes
    (:func:`analysis.folderlock.output_lock`: a second run into it is refused, ``another
    report is running in DIR (pid N)``), and first removes the temporary folders a killed
    build left. A folder holding anything but an earlier report (a fit, a batch, other
    files) is refused, naming what is there (:func:`reports.report.folder.check_report_folder`).
    """
    if quality not in QUALITIES:
        raise ValueError(f"quality must be one of {', '.join(QUALITIES)}; got {quality!r}")
    check_engine(render_engine)                  # refused now, not page by page
    sections = _sections(sections)
    resolved = resolve_fabrics(fabrics)
    measured_fits = read_measured(measured) if measured is not None else None
    out = check_output_dir(out_dir)
    fits = {str(k): v for k, v in dict(fit_results or {}).items()}
    with output_lock(out, "report"):     # removes a killed build's temporaries
        check_report_folder(out)         # again, under the lock: nothing written meanwhile
        tmp = make_build_folder(out)
        try:
            os.chmod(tmp, file_mode(0o777))
            _write(tmp, resolved, sections, quality, fits, measured_fits, title, progress,
                   render_engine, command)
            swap_into_place(tmp, out)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
    return out / "index.html"
