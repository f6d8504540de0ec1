"""The HTML report: every preset's parameters, lobes, slices, masking, energy, reciprocity
and renders, and an overview page comparing them.

Layout of the output folder::

    index.html            overview: parameter table, combined lobes, albedo comparison
    NAME.html             one page per fabric, one <section> per report section
    NAME/*.png            its figures;  NAME/*.json, NAME/*.csv  its data
    overview/*.png|csv    the overview's figures and data
    summary.json          everything the pages say, as data
    .microcyl-report      marker: this folder is a report that a later run may replace

Optional sections come from *providers* that may be absent: energy (``analysis.albedo_curve``
or ``analysis.albedo``), reciprocity statistics (``analysis.reciprocity``; the reciprocity
maps themselves are computed here), renders (``reports.render.render``) and fitting results
(``results.json`` files of ``microcyl fit``). A missing provider makes its section say
"not available" and why; it never stops the report.

Nothing is written half: the report is built in a hidden temporary folder beside the output
folder (every file in it written through a temporary file and ``os.replace``) and renamed into
place at the end; an interrupted or failed run removes the temporary folder.
"""

from __future__ import annotations

import csv
import dataclasses
import datetime
import html
import importlib
import io
import json
import os
import shutil
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gonio.atomic import atomic_write, file_mode
from gonio.jsonplain import plain
from gonio.progress import progress_bar

__all__ = ["build_report", "SECTIONS", "QUALITIES", "Unavailable", "check_output_dir"]

#: Per-fabric sections in page order.
SECTIONS = ("parameters", "lobes", "slices", "hemisphere", "masking", "energy", "reciprocity",
            "renders", "fit")

_TITLES = {
    "parameters": "Parameters", "lobes": "Lobes in the planes of incidence",
    "slices": "Slices (BRDF Explorer)", "hemisphere": "Hemisphere and 3-D lobe",
    "masking": "Shadowing and masking", "energy": "Energy: directional albedo",
    "reciprocity": "Reciprocity", "renders": "Renders", "fit": "Fitting results",
}

#: Resolutions per quality. "default" keeps plotting near 5 s a preset on 2 cores;
#: "fast" is for tests and previews.
QUALITIES = {
    "default": dict(lobe=181, hemi=101, image=90, recip=45, lobe3d=(30, 60),
                    albedo_theta=np.arange(0.0, 90.0, 3.0), render=(320, 180, 16), dpi=100),
    "fast": dict(lobe=37, hemi=21, image=12, recip=8, lobe3d=(6, 10),
                 albedo_theta=np.array([0.0, 45.0, 85.0]), render=(32, 18, 1), dpi=50),
}

_MARKER = ".microcyl-report"


class Unavailable(Exception):
    """A section's provider is absent or cannot answer; the message says why."""


# --------------------------------------------------------------------------- output folder

def check_output_dir(out_dir) -> Path:
    """Check that ``out_dir`` can be (re)written as a report folder; return it resolved.

    Raises
    ------
    OSError
        If the folder's parent cannot be created or written, or ``out_dir`` is a file.
    ValueError
        If ``out_dir`` exists and is not a report written by this module (no
        ``.microcyl-report`` marker) nor a folder holding nothing but ``summary.json`` and
        ``index.html`` (an earlier ``microcyl report``): it is never replaced then.
    """
    out = Path(out_dir).expanduser().resolve()
    if out.exists() and not out.is_dir():
        raise OSError(f"output folder {out} exists and is a file")
    if out.is_dir() and not (out / _MARKER).is_file() and not {
            c.name for c in out.iterdir()} <= {"summary.json", "index.html"}:
        raise ValueError(f"output folder {out} exists, is not empty and is not a microcyl "
                         f"report; remove it or choose another")
    parent = out.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OSError(f"cannot create output folder {parent}: {exc.strerror or exc}") from None
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OSError(f"output folder {parent} is not writable")
    return out


def _plain(obj):
    """Strict-JSON data of ``obj`` (NaN and infinities as null): :func:`gonio.jsonplain.plain`."""
    return plain(obj, nonfinite="null")


def _atomic_write(path: Path, data: bytes | str) -> None:
    with atomic_write(path, "w" if isinstance(data, str) else "wb") as fh:
        fh.write(data)


# --------------------------------------------------------------------------- page context

@dataclasses.dataclass
class _Page:
    """What one section of one fabric writes into: its folder and a summary dict."""

    root: Path            # temporary report root
    folder: str           # sub-folder name, relative to root
    name: str
    fabric: Any
    q: dict
    summary: dict

    def path(self, filename: str) -> Path:
        d = self.root / self.folder
        d.mkdir(exist_ok=True)
        return d / filename

    def rel(self, filename: str) -> str:
        return f"{self.folder}/{filename}"

    def figure(self, fig, filename: str, caption: str) -> str:
        """Save ``fig`` atomically beside the page, close it, return its <figure> HTML."""
        from reports._plotting import save_figure
        try:
            save_figure(fig, self.path(filename), dpi=self.q["dpi"])
        finally:
            _close(fig)
        return (f'<figure><img src="{html.escape(self.rel(filename))}" '
                f'alt="{html.escape(caption)}"><figcaption>{html.escape(caption)}'
                f'</figcaption></figure>')

    def json(self, filename: str, data) -> str:
        _atomic_write(self.path(filename), json.dumps(_plain(data), indent=1))
        return f'<a href="{html.escape(self.rel(filename))}">{html.escape(filename)}</a>'

    def csv(self, filename: str, header: list[str], rows) -> str:
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(header)
        for row in rows:
            w.writerow([f"{v:.9g}" if isinstance(v, (float, np.floating)) else v for v in row])
        _atomic_write(self.path(filename), buf.getvalue())
        return f'<a href="{html.escape(self.rel(filename))}">{html.escape(filename)}</a>'


def _close(fig):
    import matplotlib.pyplot as plt
    if plt.fignum_exists(getattr(fig, "number", -1)):
        plt.close(fig)


def _figure(ncols=1, nrows=1, figsize=None, polar=False, **kw):
    from matplotlib.figure import Figure
    fig = Figure(figsize=figsize or (4.6 * ncols, 3.8 * nrows), layout="constrained")
    axes = [fig.add_subplot(nrows, ncols, k + 1, projection="polar" if polar else None, **kw)
            for k in range(ncols * nrows)]
    return fig, axes


def _table(header, rows) -> str:
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _fmt(v) -> str:
    if isinstance(v, (list, tuple, np.ndarray)):
        return "(" + ", ".join(_fmt(x) for x in v) + ")"
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.4g}"
    return str(v)


def _optional(module: str, attr: str):
    """``module.attr`` or None when the module or the attribute is absent."""
    try:
        mod = importlib.import_module(module)
    except ImportError:
        return None
    return getattr(mod, attr, None)


# --------------------------------------------------------------------------- sections

_THREAD_FIELDS = ("eta", "albedo", "kd", "gamma_s", "gamma_v", "area", "offsets", "lengths")


def _parameters(fab) -> dict:
    threads = []
    for t in getattr(fab, "threads", ()) or ():
        threads.append({f: _plain(getattr(t, f, None)) for f in _THREAD_FIELDS})
    return {"threads": threads, "options": _plain(dict(getattr(fab, "options", {}) or {}))}


def _sec_parameters(p: _Page) -> str:
    params = _parameters(p.fabric)
    p.summary["parameters"] = params
    link = p.json("parameters.json", params)
    if not params["threads"]:
        return f"<p>This BRDF exposes no threads.</p><p>Data: {link}</p>"
    rows = [[f"T{j + 1}"] + [_fmt(t[f]) for f in _THREAD_FIELDS]
            for j, t in enumerate(params["threads"])]
    header = ["thread", "eta", "A (RGB)", "k_d", "γs (deg)", "γv (deg)", "area a",
              "offsets (deg)", "lengths"]
    opts = ", ".join(f"{k} = {_fmt(v)}" for k, v in params["options"].items()) or "n/a"
    from reports.standard import STANDARD_GEOMETRIES, standard_values
    values = standard_values(p.fabric)
    p.summary["standard_geometries"] = values
    std = _table(["geometry", "θi, φi (deg)", "θo, φo (deg)", "f_r R", "f_r G", "f_r B (1/sr)"],
                 [[g[0], f"{g[1]:g}, {g[2]:g}", f"{g[3]:g}, {g[4]:g}"]
                  + [f"{v:.5g}" for v in values[g[0]]] for g in STANDARD_GEOMETRIES])
    return (f"{_table(header, rows)}<p>Options: {html.escape(opts)}</p>"
            f"<h3>f_r at standard geometries</h3>{std}<p>Data: {link}</p>")


_LOBE_THETAS = (0.0, 30.0, 60.0)
_PLANES = (0.0, 45.0, 90.0)


def _sec_lobes(p: _Page) -> str:
    from reports.plot_lobes import plane_directions, plot_lobe_planes
    from reports._plotting import eval_brdf
    from reports.colour import luminance
    out = []
    for scale in ("linear", "log"):
        fig, _ = plot_lobe_planes(p.fabric, _LOBE_THETAS, _PLANES, scale=scale,
                                  resolution=p.q["lobe"])
        out.append(p.figure(fig, f"lobes_{scale}.png",
                            f"Luminance f_r (1/sr, {scale}) in the planes φ = 0° (warp), 45° and "
                            f"90° (weft), for θi = 0°, 30°, 60°."))
    fig, _ = plot_lobe_planes(p.fabric, (30.0, 60.0), _PLANES, quantity="rgb", scale="linear",
                              resolution=p.q["lobe"])
    out.append(p.figure(fig, "lobes_rgb.png", "f_r per channel (red, green, blue curves), "
                        "linear, θi = 30° (solid) and 60° (dashed)."))
    theta_o = np.linspace(-90.0, 90.0, p.q["lobe"])
    cols, header = [theta_o], ["theta_o_deg"]
    for phi in _PLANES:
        for ti in _LOBE_THETAS:
            wi, wo = plane_directions(ti, theta_o, phi)
            f = eval_brdf(p.fabric, wi, wo)
            for k, c in enumerate("rgb"):
                cols.append(f[:, k])
                header.append(f"f_{c}_phi{phi:g}_ti{ti:g}")
            cols.append(luminance(f))
            header.append(f"f_Y_phi{phi:g}_ti{ti:g}")
    link = p.csv("lobes.csv", header, np.stack(cols, axis=1))
    return "".join(out) + f"<p>Data (f_r in 1/sr, signed θo in degrees): {link}</p>"


def _sec_slices(p: _Page) -> str:
    from reports.plot_slices import (plot_slice_image, plot_slice_theta_d, plot_slice_theta_h,
                                     plot_slice_theta_o)
    fig, axes = _figure(3, 1, figsize=(14.0, 3.8))
    plot_slice_theta_o(p.fabric, 30.0, 180.0, 0.0, resolution=p.q["lobe"], ax=axes[0], log=True)
    plot_slice_theta_h(p.fabric, 10.0, 90.0, 0.0, resolution=p.q["lobe"], ax=axes[1])
    plot_slice_theta_d(p.fabric, 0.0, 90.0, 0.0, resolution=p.q["lobe"], ax=axes[2])
    out = [p.figure(fig, "slices.png", "Cartesian slices, per channel in red, green and blue: "
                    "f_r against θo (θi = 30°, light on the −x side, view in the warp plane); "
                    "against θh (θd = 10°, φd = 90°, φh = 0); against θd (θh = 0, φd = 90°).")]
    fig, axes = _figure(2, 1, figsize=(10.0, 4.0))
    for ax, phi_h in zip(axes, (0.0, 90.0)):
        plot_slice_image(p.fabric, 90.0, phi_h, resolution=p.q["image"], ax=ax)
    out.append(p.figure(fig, "slice_image.png", "Luminance f_r (1/sr, log) over θh × θd at "
                        "φd = 90°, with the half vector in the warp plane (φh = 0) and the weft "
                        "plane (φh = 90°)."))
    return "".join(out)


def _sec_hemisphere(p: _Page) -> str:
    from reports.plot_hemisphere import plot_hemisphere
    from reports.plot_lobes import plot_lobe_3d
    fig, axes = _figure(3, 1, figsize=(15.0, 4.2))
    plot_hemisphere(p.fabric, 45.0, 0.0, resolution=p.q["hemi"], ax=axes[0])
    plot_hemisphere(p.fabric, 45.0, 90.0, resolution=p.q["hemi"], ax=axes[1])
    plot_hemisphere(p.fabric, 60.0, 45.0, resolution=p.q["hemi"], ax=axes[2])
    out = [p.figure(fig, "hemisphere.png", "Luminance f_r(wo) (1/sr, log colour scale) over "
                    "the viewing hemisphere, equal-area projection (+x warp, +y weft), for the "
                    "light at θi = 45° along the warp, 45° along the weft, and 60° at φ = 45°.")]
    from reports.plot_hemisphere import hemisphere_image
    from reports.colour import luminance
    img = hemisphere_image(p.fabric, 45.0, 0.0, p.q["hemi"])
    peak = float(np.nanmax(luminance(img))) if np.any(np.isfinite(img)) else 0.0
    exposure = float(np.log2(0.7 / peak)) if peak > 0 else 0.0
    fig, axes = _figure(2, 1, figsize=(10.0, 4.2))
    plot_hemisphere(p.fabric, 45.0, 0.0, quantity="srgb", exposure=exposure,
                    resolution=p.q["hemi"], ax=axes[0],
                    title=f"f_r(wo) colour, sRGB, exposure {exposure:+.1f} stops")
    plot_lobe_3d(p.fabric, 45.0, 0.0, resolution=p.q["lobe3d"], ax=_replace_3d(fig, axes[1]))
    out.append(p.figure(fig, "lobe3d.png", "Left: the colour of f_r(wo) (θi = 45°, φi = 0), "
                        "linear RGB encoded to sRGB by colour-science, exposure set so the "
                        "peak luminance shows at 0.7. Right: the 3-D lobe, radius = luminance "
                        "f_r cos θo (1/sr)."))
    return "".join(out)


def _replace_3d(fig, ax):
    spec = ax.get_subplotspec()
    ax.remove()
    return fig.add_subplot(spec, projection="3d")


def _sec_masking(p: _Page) -> str:
    from reports.plot_masking import plot_masking_lobes
    if not callable(getattr(p.fabric, "replace", None)):
        raise Unavailable("this BRDF has no replace(masking=...)")
    try:
        p.fabric.replace(masking=False)
    except TypeError as exc:
        raise Unavailable(f"replace(masking=False) failed: {exc}") from None
    fig, axes = _figure(3, 1, figsize=(13.0, 3.8), polar=True)
    for ax, phi in zip(axes, _PLANES):
        plot_masking_lobes(p.fabric, 60.0, phi, resolution=p.q["lobe"], ax=ax)
    out = [p.figure(fig, "masking_lobes.png", "Luminance f_r (1/sr) at θi = 60° with shadowing "
                    "and masking on (solid, the fabric's colour) and off (dashed, grey), in the "
                    "planes φ = 0° (warp), 45° and 90° (weft).")]
    fig, axes = _figure(3, 1, figsize=(13.0, 3.8), polar=True)
    for ax, phi in zip(axes, _PLANES):
        plot_masking_lobes(p.fabric, 80.0, phi, resolution=p.q["lobe"], ax=ax, scale="log")
    out.append(p.figure(fig, "masking_lobes_grazing.png", "The same at grazing incidence "
                        "θi = 80°, log scale."))
    out.append('<p>The terms M, P and u themselves are drawn on the <a href="index.html#masking">'
               'overview page</a>.</p>')
    return "".join(out)


def _sec_energy(p: _Page) -> str:
    from reports.plot_albedo import plot_albedo
    from reports.colour import line_colour
    theta = np.asarray(p.q["albedo_theta"], dtype=np.float64)
    curve_fn = _optional("analysis", "albedo_curve")
    albedo_fn = _optional("analysis", "albedo")
    if curve_fn is None and albedo_fn is None:
        raise Unavailable("the analysis package provides neither albedo_curve nor albedo "
                          "(the energy issue has not landed)")
    phis = (0.0, 90.0)
    t0 = time.perf_counter()
    try:
        if curve_fn is not None:
            res = curve_fn(p.fabric, theta, np.array(phis))
            value, error = np.asarray(res.value), np.asarray(res.error)       # (T, P, 3)
        else:
            from brdf.frames import from_angles
            T, P = np.meshgrid(np.radians(theta), np.radians(phis), indexing="ij")
            res = albedo_fn(p.fabric, from_angles(T, P))
            value, error = np.asarray(res.value), np.asarray(res.error)
    except Exception as exc:  # a provider's failure is reported, not fatal
        raise Unavailable(f"analysis albedo failed: {type(exc).__name__}: {exc}") from None
    seconds = time.perf_counter() - t0
    fig, axes = _figure(2, 1, figsize=(10.0, 3.8))
    for ax, j, phi in zip(axes, range(2), phis):
        plot_albedo(theta, value[:, j], error[:, j], ax=ax,
                    title=f"albedo ρ(wo) = ∫ f_r cos θi dwi, wo at φ = {phi:g}°")
    out = [p.figure(fig, "albedo.png", "Directional albedo per channel (red, green, blue) "
                    "against θo, with the provider's error bounds, for wo along the warp "
                    "(φ = 0) and the weft (φ = 90°); the dotted line is 1.")]
    rows = [[t, phi] + list(value[i, j]) + list(error[i, j])
            for i, t in enumerate(theta) for j, phi in enumerate(phis)]
    link = p.csv("albedo.csv", ["theta_deg", "phi_deg", "albedo_r", "albedo_g", "albedo_b",
                                "error_r", "error_g", "error_b"], rows)
    idx = np.unravel_index(int(np.argmax(value)), value.shape)
    summ = {"max": float(value[idx]), "max_error": float(error[idx]),
            "max_theta_deg": float(theta[idx[0]]), "max_phi_deg": float(phis[idx[1]]),
            "max_channel": "RGB"[idx[2]], "exceeds_one": bool(value[idx] - error[idx] > 1.0),
            "seconds": seconds, "theta_deg": theta, "phi_deg": list(phis), "value": value,
            "error": error, "colour": line_colour(p.fabric)}
    p.summary["energy"] = summ
    verdict = ("exceeds 1 (energy is created)" if summ["exceeds_one"]
               else "stays at or below 1 within the error" if summ["max"] - summ["max_error"]
               <= 1.0 else "is uncertain")
    out.append(f"<p>Largest albedo {summ['max']:.4f} ± {summ['max_error']:.1e} "
               f"({summ['max_channel']} channel, θ = {summ['max_theta_deg']:g}°, "
               f"φ = {summ['max_phi_deg']:g}°): it {verdict}. Data: {link}</p>")
    return "".join(out)


def _sec_reciprocity(p: _Page) -> str:
    from reports.plot_reciprocity import plot_reciprocity_map, reciprocity_map
    maps = {}
    fig, axes = _figure(2, 1, figsize=(10.0, 4.0))
    for ax, (pi, po, label) in zip(axes, ((180.0, 0.0, "warp"), (270.0, 90.0, "weft"))):
        theta, err = reciprocity_map(p.fabric, pi, po, p.q["recip"])
        maps[label] = {"phi_i_deg": pi, "phi_o_deg": po, "theta_deg": theta, "error": err,
                       "median": float(np.median(err)), "max": float(np.max(err))}
        plot_reciprocity_map(theta_deg=theta, error=err, phi_i_deg=pi, phi_o_deg=po, ax=ax)
    out = [p.figure(fig, "reciprocity.png", "Relative reciprocity error of the luminance "
                    "|f(wi,wo) − f(wo,wi)| / max over θi × θo, light and viewer on opposite "
                    "sides of the warp plane (left) and the weft plane (right).")]
    link = p.json("reciprocity.json", maps)
    p.summary["reciprocity_maps"] = {k: {"median": v["median"], "max": v["max"]}
                                     for k, v in maps.items()}
    rows = [[k, f"{v['median']:.3g}", f"{v['max']:.3g}"] for k, v in maps.items()]
    out.append(_table(["plane", "median error", "max error"], rows))
    out.append(f"<p>Data: {link}</p>")
    fn = _optional("analysis", "reciprocity")
    if fn is None:
        out.append("<p>Statistics over random pairs: not available (the analysis package "
                   "provides no reciprocity function yet).</p>")
        return "".join(out)
    try:
        res = fn(p.fabric)
    except Exception as exc:
        out.append(f"<p>Statistics over random pairs: not available (analysis.reciprocity "
                   f"failed: {html.escape(type(exc).__name__)}: {html.escape(str(exc))}).</p>")
        return "".join(out)
    stats = {k: _plain(getattr(res, k)) for k in ("median", "p95", "max")
             if hasattr(res, k)}
    p.summary["reciprocity"] = stats
    out.append("<p>Over random pairs (analysis.reciprocity): "
               + html.escape(", ".join(f"{k} {_fmt(v)}" for k, v in stats.items())) + "</p>")
    return "".join(out)


#: Renders in the report: (file stem, scene, masking, caption).
_RENDERS = (("curtain", "curtain", True, "curtain"),
            ("cylinder", "cylinder", True, "cylinder, masking on"),
            ("cylinder_nomask", "cylinder", False, "cylinder, masking off"))


def _sec_renders(p: _Page) -> str:
    render = _optional("reports.render", "render")
    if render is None:
        raise Unavailable("reports.render is not installed (the renders issue has not landed)")
    from reports.colour import luminance, to_srgb
    import matplotlib.image as mimage
    width, height, spp = p.q["render"]
    out = []
    stats = {}
    for stem, scene, masking, caption in _RENDERS:
        fab = p.fabric
        if not masking:
            if not callable(getattr(fab, "replace", None)):
                continue
            fab = fab.replace(masking=False)
        try:
            img = np.asarray(render(scene, fab, width=width, height=height, spp=spp,
                                    progress=False), dtype=np.float64)
        except Exception as exc:
            out.append(f"<p>{html.escape(caption)}: render failed ({html.escape(type(exc).__name__)}"
                       f": {html.escape(str(exc))}).</p>")
            continue
        stats.setdefault("exposure_reference", None)
        if stats["exposure_reference"] is None:  # one exposure for all renders of a fabric
            y = luminance(img)
            ref = float(np.percentile(y[y > 0], 99)) if np.any(y > 0) else 1.0
            stats["exposure_reference"] = ref
        exposure = float(np.log2(0.8 / stats["exposure_reference"]))
        png = (to_srgb(img, exposure=exposure) * 255.0 + 0.5).astype(np.uint8)
        buf = io.BytesIO()
        mimage.imsave(buf, png, format="png")
        _atomic_write(p.path(f"render_{stem}.png"), buf.getvalue())
        out.append(f'<figure><img src="{html.escape(p.rel(f"render_{stem}.png"))}" '
                   f'alt="{html.escape(caption)}"><figcaption>{html.escape(caption)}, '
                   f'{width} × {height}, {spp} spp, exposure {exposure:+.1f} stops (sRGB via '
                   f'colour-science)</figcaption></figure>')
        stats[stem] = {"scene": scene, "masking": masking, "width": width, "height": height,
                       "spp": spp, "exposure": exposure, "mean_luminance": float(luminance(img).mean())}
    p.summary["renders"] = stats
    return "".join(out) or "<p>No renders.</p>"


def _sec_fit(p: _Page) -> str:
    results = p.q.get("fit_results", {}).get(p.name)
    if results is None:
        raise Unavailable("no fitting results for this fabric (run `microcyl fit` and pass its "
                          "results.json)")
    from analysis.fit.results import read_results
    try:
        data = read_results(results)
    except ValueError as exc:
        raise Unavailable(str(exc)) from None
    rows = [[k] + [_fmt(v.get(f)) for f in ("median", "lo68", "hi68", "lo95", "hi95", "tau",
                                            "rhat", "ess")]
            for k, v in data["parameters"].items()]
    p.summary["fit"] = data
    verdict = data.get("converged")
    return (_table(["parameter", "median", "lo68", "hi68", "lo95", "hi95", "τ", "R-hat", "ESS"],
                   rows) + f"<p>Converged: {html.escape(_fmt(verdict))}</p>")


_BUILDERS: dict[str, Callable[[_Page], str]] = {
    "parameters": _sec_parameters, "lobes": _sec_lobes, "slices": _sec_slices,
    "hemisphere": _sec_hemisphere, "masking": _sec_masking, "energy": _sec_energy,
    "reciprocity": _sec_reciprocity, "renders": _sec_renders, "fit": _sec_fit,
}


# --------------------------------------------------------------------------- pages

_CSS = """
body{font-family:system-ui,sans-serif;max-width:1400px;margin:1em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
figure{display:inline-block;margin:.5em;vertical-align:top;max-width:100%}
figure img{max-width:100%;border:1px solid #eee}figcaption{font-size:.85em;color:#555;max-width:900px}
table{border-collapse:collapse;font-size:.9em;margin:.5em 0}td,th{border:1px solid #ccc;padding:.2em .5em}
th{background:#f4f4f4}.na{color:#a33}nav a{margin-right:1em}.swatch{display:inline-block;width:1em;
height:1em;border:1px solid #999;vertical-align:middle;margin-right:.3em}
"""


def _page(title: str, nav: str, body: str) -> str:
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>"
            f"<nav>{nav}</nav><h1>{html.escape(title)}</h1>{body}"
            f"<footer><p><small>microcyl report, {html.escape(_now())}</small></p></footer>"
            f"</body></html>\n")


def _now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def _swatch(fab) -> str:
    from reports.colour import fabric_colour
    r, g, b = (int(round(255 * c)) for c in fabric_colour(fab))
    return f'<span class="swatch" style="background:rgb({r},{g},{b})"></span>'


def _nav(names, current=None, measured=False) -> str:
    links = ['<a href="index.html">overview</a>']
    for n in names:
        label = f"<b>{html.escape(n)}</b>" if n == current else html.escape(n)
        links.append(f'<a href="{html.escape(n)}.html">{label}</a>')
    if measured:
        label = "<b>measured fits</b>" if current == "measured" else "measured fits"
        links.append(f'<a href="measured.html">{label}</a>')
    return "".join(links)


def _overview(root: Path, fabrics: dict, summaries: dict, sections, q) -> str:
    from reports.plot_albedo import plot_albedo
    from reports.plot_lobes import plot_lobe_comparison
    from reports.plot_masking import plot_masking_terms
    p = _Page(root, "overview", "overview", None, q, {})
    out = ['<section id="overview"><h2>Fabrics</h2>']
    rows = []
    for name, fab in fabrics.items():
        params = _parameters(fab)
        for j, t in enumerate(params["threads"]):
            rows.append([name if j == 0 else "", f"T{j + 1}"] +
                        [_fmt(t[f]) for f in _THREAD_FIELDS])
        if not params["threads"]:
            rows.append([name, "n/a"] + [""] * len(_THREAD_FIELDS))
    table = _table(["fabric", "thread", "eta", "A (RGB)", "k_d", "γs (deg)", "γv (deg)",
                    "area a", "offsets (deg)", "lengths"], rows)
    out.append(table)
    out.append("<ul>" + "".join(
        f'<li>{_swatch(fab)}<a href="{html.escape(n)}.html">{html.escape(n)}</a></li>'
        for n, fab in fabrics.items()) + "</ul>")
    out.append("</section>")
    out.append('<section id="combined-lobes"><h2>Lobes compared</h2>')
    for ti, phi in ((30.0, 0.0), (60.0, 0.0), (60.0, 90.0)):
        fig, ax = plot_lobe_comparison(fabrics, ti, phi, resolution=q["lobe"])
        out.append(p.figure(fig, f"lobes_ti{ti:g}_phi{phi:g}.png",
                            f"Luminance f_r (1/sr, log) of every fabric, θi = {ti:g}°, plane "
                            f"φ = {phi:g}°; each curve in the fabric's own sRGB colour."))
    out.append("</section>")
    out.append('<section id="albedo-comparison"><h2>Albedo compared</h2>')
    have = {n: s["energy"] for n, s in summaries.items() if "energy" in s}
    if have:
        fig, axes = _figure(2, 1, figsize=(11.0, 4.0))
        for j, (ax, phi) in enumerate(zip(axes, (0.0, 90.0))):
            for name, e in have.items():
                plot_albedo(e["theta_deg"], np.asarray(e["value"])[:, j],
                            np.asarray(e["error"])[:, j], quantity="luminance",
                            colour=e["colour"], label=name, ax=ax,
                            title=f"luminance albedo, wo at φ = {phi:g}°")
        out.append(p.figure(fig, "albedo_comparison.png", "Rec. 709 luminance of the "
                            "directional albedo of every fabric, against θo, wo along the warp "
                            "(left) and the weft (right), each in the fabric's own colour."))
        rows = [[n, f"{e['max']:.4f}", f"{e['max_error']:.1e}", f"{e['max_theta_deg']:g}",
                 f"{e['max_phi_deg']:g}", e["max_channel"], "yes" if e["exceeds_one"] else "no"]
                for n, e in have.items()]
        out.append(_table(["fabric", "max albedo", "error", "θ (deg)", "φ (deg)", "channel",
                           "exceeds 1"], rows))
    else:
        out.append('<p class="na">Not available: no fabric has energy results (the analysis '
                   'package provides no albedo function yet, or the energy section was not '
                   'requested).</p>')
    out.append("</section>")
    out.append('<section id="masking"><h2>Shadowing, masking and reweighting terms</h2>')
    fig, ax = plot_masking_terms(resolution=max(q["lobe"], 61))
    out.append(p.figure(fig, "masking_terms.png", "M(φ) = max(cos φ, 0) (and P(ψ), the same "
                        "form), the blend u with σu = 20°, and the paired weight M(wi, wo) "
                        "against φo for φi = 0°, 30°, 60° (MODEL.md)."))
    out.append("</section>")
    recs = {n: s["reciprocity_maps"] for n, s in summaries.items() if "reciprocity_maps" in s}
    if recs:
        out.append('<section id="reciprocity-comparison"><h2>Reciprocity compared</h2>')
        out.append(_table(["fabric", "warp plane median", "warp plane max", "weft plane median",
                           "weft plane max"],
                          [[n, f"{r['warp']['median']:.3g}", f"{r['warp']['max']:.3g}",
                            f"{r['weft']['median']:.3g}", f"{r['weft']['max']:.3g}"]
                           for n, r in recs.items()]))
        out.append("</section>")
    out.append(f"<p>Sections per fabric: {html.escape(', '.join(sections))}. "
               f'Data: <a href="summary.json">summary.json</a>.</p>')
    return "".join(out)


# --------------------------------------------------------------------------- entry point

def _resolve_fabrics(fabrics) -> dict:
    import brdf
    if fabrics is None:
        fabrics = tuple(brdf.PRESETS)
    if isinstance(fabrics, str):
        fabrics = (fabrics,)
    if isinstance(fabrics, dict):
        items = list(fabrics.items())
    else:
        items = []
        for f in fabrics:
            if isinstance(f, str):
                items.append((f, None))
            elif isinstance(f, tuple) and len(f) == 2:
                items.append(f)
            else:
                raise ValueError(f"fabrics must hold preset names or (name, BRDF) pairs; "
                                 f"got {f!r}")
    if not items:
        raise ValueError("fabrics is empty; give at least one of " + ", ".join(brdf.PRESETS))
    out = {}
    for name, fab in items:
        if not isinstance(name, str) or not name or "/" in name or name.startswith(".") \
                or name in ("index", "overview", "summary"):
            raise ValueError(f"fabric name {name!r} cannot name a report page")
        if fab is None and name not in brdf.PRESETS:
            raise ValueError(f"unknown fabric {name!r}; valid: {', '.join(brdf.PRESETS)}")
        if name in out:
            raise ValueError(f"fabric {name!r} is given twice")
        out[name] = fab
    return out


def build_report(fabrics=None, out_dir="report", *, sections=None, progress=True,
                 quality="default", fit_results=None, measured=None,
                 title="microcyl report") -> Path:
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
    quality : {"default", "fast"}
        Resolutions of plots and renders (:data:`QUALITIES`).
    fit_results : mapping of str to path, optional
        Fabric name -> ``results.json`` of a fit, shown in the "fit" section.
    measured : path, optional
        Output folder of ``microcyl fit-measured``: adds the page ``measured.html`` (fits to
        the measured felts and CUReT fabrics) and its table on the overview.
    title : str
        Title of the overview page.

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
    failure or interrupt removes the temporary folder and leaves ``out_dir`` as it was.
    """
    if quality not in QUALITIES:
        raise ValueError(f"quality must be one of {', '.join(QUALITIES)}; got {quality!r}")
    if sections is None:
        sections = SECTIONS
    sections = list(dict.fromkeys(sections))
    bad = [s for s in sections if s not in SECTIONS]
    if bad:
        raise ValueError(f"unknown section {bad[0]!r}; valid: {', '.join(SECTIONS)}")
    sections = [s for s in SECTIONS if s in sections]
    resolved = _resolve_fabrics(fabrics)
    measured_fits = None
    if measured is not None:
        from reports.report_measured import read_measured
        measured_fits = read_measured(measured)
    has_measured = measured_fits is not None
    out = check_output_dir(out_dir)
    q = dict(QUALITIES[quality])
    q["fit_results"] = {str(k): v for k, v in dict(fit_results or {}).items()}

    import brdf

    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-", dir=out.parent))
    except OSError as exc:
        raise OSError(f"output folder {out.parent} is not writable: {exc.strerror or exc}") \
            from None
    t_start = time.perf_counter()
    try:
        os.chmod(tmp, file_mode(0o777))
        fabs = {n: (f if f is not None else brdf.fabric(n)) for n, f in resolved.items()}
        summaries: dict[str, dict] = {}
        bar = progress_bar(len(fabs) * len(sections) + 1, desc="report", unit="section",
                           enabled=progress)
        names = list(fabs)
        for name, fab in fabs.items():
            summary: dict[str, Any] = {"sections": {}}
            body = [f"<p>{_swatch(fab)}Fabric <b>{html.escape(name)}</b>.</p>"]
            for sec in sections:
                bar.set_description(f"{name}: {sec}")
                page = _Page(tmp, name, name, fab, q, summary)
                t0 = time.perf_counter()
                try:
                    frag = _BUILDERS[sec](page)
                    status = "ok"
                except Unavailable as exc:
                    frag = f'<p class="na">Not available: {html.escape(str(exc))}</p>'
                    status = f"not available: {exc}"
                summary["sections"][sec] = {"status": status,
                                            "seconds": round(time.perf_counter() - t0, 3)}
                body.append(f'<section id="{sec}" class="report-section" data-fabric='
                            f'"{html.escape(name)}"><h2>{html.escape(_TITLES[sec])}</h2>'
                            f"{frag}</section>")
                bar.update(1)
            summaries[name] = summary
            _atomic_write(tmp / f"{name}.html",
                          _page(f"{title}: {name}", _nav(names, name, has_measured), "".join(body)))
        bar.set_description("overview")
        overview = _overview(tmp, fabs, summaries, sections, q)
        measured_summary = None
        if has_measured:
            from reports.report_measured import measured_page, overview_table
            mbody, measured_summary = measured_page(tmp, measured_fits)
            _atomic_write(tmp / "measured.html", _page(f"{title}: fits to measured data",
                                                       _nav(names, "measured", True), mbody))
            overview += ('<section id="measured-fits"><h2>Fits to measured data</h2>'
                         + overview_table(measured_fits)
                         + '<p>Details: <a href="measured.html">measured.html</a>.</p></section>')
        fabric_sections = "".join(
            f'<section class="fabric" id="fabric-{html.escape(n)}"><h2>{_swatch(fabs[n])}'
            f'<a href="{html.escape(n)}.html">{html.escape(n)}</a></h2><ul>'
            + "".join(f"<li>{html.escape(_TITLES[s])}: {html.escape(v['status'])}</li>"
                      for s, v in summaries[n]["sections"].items())
            + "</ul></section>" for n in names)
        _atomic_write(tmp / "index.html", _page(title, _nav(names, None, has_measured),
                                                  overview + fabric_sections))
        bar.update(1)
        bar.close()
        doc = {"title": title, "generated": _now(), "quality": quality, "sections": sections,
               "fabrics": summaries, "seconds": round(time.perf_counter() - t_start, 2)}
        if measured_summary is not None:
            doc["measured"] = measured_summary
        _atomic_write(tmp / "summary.json", json.dumps(_plain(doc), indent=1))
        _atomic_write(tmp / _MARKER, "microcyl report folder: replaced whole by the next run\n")
        _swap_into_place(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out / "index.html"


def _swap_into_place(tmp: Path, out: Path) -> None:
    """Rename the finished ``tmp`` folder to ``out``, replacing an old report there."""
    old = None
    if out.exists():
        old = out.with_name(f".{out.name}.old-{os.getpid()}-{time.monotonic_ns()}")
        os.replace(out, old)
    try:
        os.replace(tmp, out)
    except BaseException:
        if old is not None:
            os.replace(old, out)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
