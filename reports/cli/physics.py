"""Verbs about physical plausibility: ``energy`` and ``reciprocity``."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import brdf
from analysis import sources
from analysis.energy import VARIANTS, EnergyReport
from analysis.plausibility import energy_document, reciprocity_document, sanity_results
from analysis.variants import Named
from gonio.terminal import shown
from reports.cli import options as cliutil
from reports.prose import energy_statements, energy_summary, reciprocity_statements

log = logging.getLogger("microcyl")


def _sources(args, tables: bool = False) -> list:
    """The FABRIC argument (positional or --fabric) resolved: every preset for ``all``,
    else the one source (:func:`analysis.sources.resolve`)."""
    text = cliutil.fabric_argument(args)
    if text == "all":
        return [sources.resolve(name) for name in brdf.PRESETS]
    return [cliutil.source_from_args(text, args, tables=tables)]


def _named(s):
    """A source for :mod:`analysis.energy` and :mod:`analysis.reciprocity`: a preset by its
    name, another fabric named by its label, a fit of a baseline model as a
    :class:`analysis.variants.Named` BRDF (the default variant only)."""
    if s.kind == "preset":
        return s.label
    if s.is_fabric:
        return s.brdf.replace(name=s.label)
    return Named(s.label, s.brdf, s.model)


def _presets(args) -> tuple:
    """The fabrics of the FABRIC argument for :mod:`analysis.energy` and
    :mod:`analysis.reciprocity` (:func:`_named`)."""
    return tuple(_named(s) for s in _sources(args))


def _variants(text: str | None):
    if text is None:
        return tuple(VARIANTS)
    out = tuple(v.strip() for v in text.split(",") if v.strip())
    for v in out:
        if v not in VARIANTS:
            raise ValueError(f"unknown variant {v!r}; variants are {', '.join(VARIANTS)}")
    return out


def _floats(text: str, what: str) -> tuple[float, ...]:
    try:
        vals = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise ValueError(f"{what} must be comma-separated numbers in degrees; got {text!r}") \
            from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise ValueError(f"{what} must be comma-separated finite numbers; got {text!r}")
    return vals


def register(sub):
    """Add ``energy``, ``reciprocity`` and ``sanity`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "energy", help="albedo curves, white furnace: does the model create energy?",
        description="Directional albedo of each preset and variant (furnace: integral over wi "
                    "of f_r cos theta_i; reflectance: integral over wo of f_r cos theta_o), "
                    "with error bars, and a white-furnace scan (A = 1) over eta, k_d and gamma "
                    "that finds where the albedo exceeds 1.")
    cliutil.add_fabric_argument(p, extra=", or all (every preset)")
    p.add_argument("--variants", metavar="V1,V2",
                   help="variants (default all: default, masking_off, reweighting_off, "
                        "transmission_longitudinal, gap_outgoing)")
    p.add_argument("--theta-step", type=float, default=10.0, metavar="DEG",
                   help="step of the theta sweep, degrees (default 10; 85 and 89 are always "
                        "added)")
    p.add_argument("--phi", default="0,90", metavar="DEG,...",
                   help="azimuths of the sweep, degrees from the warp (default 0,90)")
    p.add_argument("--tol", type=float, default=1e-3, help="albedo tolerance (default 1e-3)")
    p.add_argument("--no-furnace", action="store_true", help="skip the white-furnace scan")
    p.add_argument("--no-hemispherical", action="store_true",
                   help="skip the hemispherical-hemispherical albedo")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="processes (default: up to 2)")
    p.add_argument("--json", metavar="PATH", help="write the full results as JSON")
    p.add_argument("--verbose", action="store_true",
                   help="print the full tables and findings after the summary")
    cliutil.add_quiet_options(p)
    p.set_defaults(func=run_energy)

    p = sub.add_parser(
        "reciprocity", help="how far f_r(wi, wo) is from f_r(wo, wi)",
        description="Relative reciprocity error |f(wi,wo) - f(wo,wi)| / max(...) on luminance, "
                    "over random pairs and a gonio full grid, per preset and variant; the RGL "
                    "acrylic felts are shown as a measured contrast.")
    cliutil.add_fabric_argument(p, tables=True, extra=", or all (every preset)")
    p.add_argument("--variants", metavar="V1,V2",
                   help="variants (default all; a measured table is shown as it is)")
    p.add_argument("-n", type=int, default=20000, help="random pairs (default 20000)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random pairs (default 0)")
    p.add_argument("--grid-step", type=float, default=15.0, metavar="DEG",
                   help="step of the gonio full grid (default 15; 0 skips it)")
    p.add_argument("--channel", default="luminance", choices=("luminance", "r", "g", "b"))
    p.add_argument("--data", default=None, metavar="DIR",
                   help="measured data folder with rgl/ (default $MICROCYL_DATA or "
                        "../shared/data); missing felts are skipped with a note")
    p.add_argument("--no-felts", action="store_true", help="skip the measured felts")
    p.add_argument("--json", metavar="PATH", help="write the full results as JSON")
    p.set_defaults(func=run_reciprocity)

    p = sub.add_parser(
        "sanity", help="finite, non-negative f_r at the edges of the domain?",
        description="Evaluate each preset on direction sets built for its edge cases (grazing, "
                    "retro and mirror pairs, along the threads, below the horizon) and at edge "
                    "parameter sets; report every NaN, infinite or negative value and every "
                    "RuntimeWarning. Exits 1 when one is found.")
    cliutil.add_fabric_argument(p, tables=True, extra=", or all (every preset)")
    p.add_argument("--json", metavar="PATH", help="write every check as JSON")
    p.set_defaults(func=run_sanity)


def format_energy(rep) -> str:
    """The energy report (its :func:`analysis.plausibility.document`) as text tables."""
    d = rep.to_dict() if isinstance(rep, EnergyReport) else rep
    lines = ["Directional albedo maxima (value +- error bound; theta, phi of the fixed "
             "direction in degrees)",
             f"{'preset':32s} {'variant':27s} {'mode':12s} {'max':>20s} {'theta':>6s} "
             f"{'phi':>5s} ch  >1?"]
    for c in d["curves"]:
        m = c["max"]
        flag = "YES" if m["exceeds_one"] else ("maybe" if m["possibly_exceeds_one"] else "no")
        lines.append(f"{c['preset']:32s} {c['variant']:27s} {c['mode']:12s} "
                     f"{m['value']:10.4f} +- {m['error']:.1e} {m['theta_deg']:6g} "
                     f"{m['phi_deg']:5g} {'RGB'[m['channel']]}   {flag}")
    if d["hemispherical"]:
        lines += ["", "Hemispherical-hemispherical albedo (default variant), R G B"]
        for h in d["hemispherical"]:
            vals = "  ".join(f"{v:.4f} +- {e:.1e}" for v, e in zip(h["value"], h["error"]))
            lines.append(f"{h['preset']:32s} {vals}")
    if d["furnace"]:
        lines += ["", "White furnace (A = 1, both threads), max over the scan directions",
                  f"{'curves of':32s} {'parameter':10s} {'value':>7s} "
                  + " ".join(f"{m:>24s}" for m in d["settings"]["modes"])]
        for f in d["furnace"]:
            cells = []
            for m in d["settings"]["modes"]:
                x = f[m]
                mark = "!" if x["exceeds_one"] else " "
                cells.append(f"{x['value']:9.3f} +- {x['error']:.0e}{mark} "
                             f"@{x['theta_deg']:g}/{x['phi_deg']:g}".rjust(24))
            val = "" if f["value"] is None else f"{f['value']:g}"
            lines.append(f"{f['curves']:32s} {f['parameter']:10s} {val:>7s} " + " ".join(cells))
    lines += ["", "Findings"] + [f"- {s}" if not s.startswith("  ") else f"  {s.strip()}"
                                 for s in d["statements"]]
    lines.append(f"({d['seconds']:.1f} s)")
    return "\n".join(lines)


def format_energy_summary(doc: dict) -> str:
    """The summary ``microcyl energy`` prints first (:func:`reports.prose.energy_summary`)."""
    s = doc["settings"]
    head = (f"Energy: directional albedos (value +- error bound; angles in degrees; theta "
            f"{', '.join(f'{t:g}' for t in s['theta_deg'])}; phi "
            f"{', '.join(f'{p:g}' for p in s['phi_deg'])})")
    tail = f"({doc['seconds']:.1f} s; the full tables with --verbose, every value with --json)"
    return "\n".join([head] + energy_summary(doc) + [tail])


def run_energy(args) -> int:
    """``microcyl energy``."""
    presets = _presets(args)
    variants = _variants(args.variants)
    phi = _floats(args.phi, "--phi")
    if not (0 < args.theta_step <= 90):
        raise ValueError(f"--theta-step must be in (0, 90] degrees; got {args.theta_step}")
    if not (args.tol > 0):
        raise ValueError(f"--tol must be > 0; got {args.tol}")
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers must be >= 1; got {args.workers}")
    doc = energy_document(presets, variants, theta_step=args.theta_step, phi_deg=phi,
                          tol=args.tol, hemispherical=not args.no_hemispherical,
                          furnace=not args.no_furnace, workers=args.workers,
                          progress=cliutil.progress(args), statements=energy_statements,
                          json_path=args.json)
    print(shown(format_energy_summary(doc), lines=True))
    if args.verbose:
        print()
        print(shown(format_energy(doc), lines=True))
    if args.json is not None:
        log.info(f"wrote {Path(args.json)}")
    return 0


def format_reciprocity(rep: dict) -> str:
    """The reciprocity report (its :func:`analysis.plausibility.document`, with ``notes``)
    as a text table."""
    lines = [f"Reciprocity error r = |f(wi,wo) - f(wo,wi)| / max(...), on "
             f"{rep['settings']['channel']}; {rep['settings']['n']} random pairs"
             + (", and a gonio full grid" if rep['settings']['geometry'] else ""),
             f"{'brdf':32s} {'variant':27s} {'median':>7s} {'p95':>7s} {'max':>7s} "
             f"{'zero':>6s} {'cos_i med':>9s}"
             + (f" {'grid med':>8s} {'grid p95':>8s}" if rep['settings']['geometry'] else "")]
    for r in rep["rows"]:
        s = r["random"]
        c = r["random_cos_i"]

        def f(x):
            return "   n/a" if x is None else f"{x:7.3f}"
        row = (f"{r['name']:32s} {r['variant'] or '(measured)':27s} {f(s['median'])} "
               f"{f(s['p95'])} {f(s['max'])} {s['n_zero']:6d} {f(c['median']):>9s}")
        if "geometry" in r:
            g = r["geometry"]
            row += f" {f(g['median']):>8s} {f(g['p95']):>8s}"
        lines.append(row)
    worst = [r for r in rep["rows"] if r["random"]["worst"]]
    if worst:
        lines += ["", "Worst pair per BRDF (default variant), degrees: theta_i phi_i theta_o phi_o"]
        for r in worst:
            if r["variant"] not in (None, "default"):
                continue
            w = r["random"]["worst"][0]
            lines.append(f"{r['name']:32s} {w['theta_i']:7.2f} {w['phi_i']:7.2f} "
                         f"{w['theta_o']:7.2f} {w['phi_o']:7.2f}  f(wi,wo) = {w['f_io']:.4g}, "
                         f"f(wo,wi) = {w['f_oi']:.4g}, r = {w['r']:.4f}")
    lines += ["", "Findings"] + [f"- {s}" for s in rep["statements"]]
    lines += [f"- note: {n}" for n in rep.get("notes", [])]
    lines.append(f"({rep['seconds']:.1f} s)")
    return "\n".join(lines)


def run_reciprocity(args) -> int:
    """``microcyl reciprocity``."""
    chosen = _sources(args, tables=True)
    presets = tuple(_named(s) for s in chosen if s.kind != "table")
    tables = [(s.label, s.brdf) for s in chosen if s.kind == "table"]
    variants = _variants(args.variants)
    if args.n < 1:
        raise ValueError(f"-n must be >= 1; got {args.n}")
    if not (0 <= args.grid_step <= 90):
        raise ValueError(f"--grid-step must be in [0, 90] degrees (0 skips); got {args.grid_step}")
    doc = reciprocity_document(
        presets, variants, tables=tables, n=args.n, seed=args.seed, grid_step=args.grid_step,
        channel=args.channel, data_dir=None if args.no_felts else cliutil.data_dir(args.data),
        statements=reciprocity_statements, json_path=args.json)
    print(shown(format_reciprocity(doc), lines=True))
    if args.json is not None:
        log.info(f"wrote {Path(args.json)}")
    return 0


def format_sanity(name: str, result) -> list[str]:
    """One line for a fabric's sanity scan, and one per check that found something."""
    evals = sum(c["n"] for c in result.checks)
    bad = result.violations
    lines = [f"{name}: {'ok' if result.ok else 'VIOLATIONS'} ({len(result.checks)} checks, "
             f"{evals} evaluations{'' if result.ok else f', {len(bad)} failing'})"]
    for c in bad:
        lines.append(f"   {c['params']} / {c['directions']}: {c['n_nonfinite']} non-finite, "
                     f"{c['n_negative']} negative, {len(c['warnings'])} warnings"
                     + (f"; e.g. {c['examples'][0]}" if c["examples"] else ""))
    return lines


def run_sanity(args) -> int:
    """``microcyl sanity``: :func:`analysis.plausibility.sanity_results` of each fabric,
    printed."""
    chosen = _sources(args, tables=True)
    results = sanity_results({s.label: s.label if s.kind == "preset" else s.brdf
                              for s in chosen}, json_path=args.json)
    for name, r in results.items():
        print(shown("\n".join(format_sanity(name, r)), lines=True))
    if args.json is not None:
        log.info(f"wrote {Path(args.json)}")
    return 0 if all(r.ok for r in results.values()) else 1
