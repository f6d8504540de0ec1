"""The nine measured datasets fitted by every model (``microcyl fit-measured --models all``),
timed, and the measured page's table and sentences written from the fits' own files.

With ``--run`` the fits are made into ``--fits DIR`` (resumable: converged fits are not redone,
so the wall time is that of this run); without it an existing folder is read. The fragment
(``--rst FILE``, the one ``docs/guide/measured.rst`` includes: ``measured_fits.inc``) holds,
per dataset, the microcylinder's convergence step and time, every model's PSIS-LOO elpd (the
best in bold), the microcylinder's rotation and area share (95% intervals), its left/right
and light/view residual splits (Mann-Whitney p of :mod:`analysis.fit.adequacy`) and its
verdict; every sentence under it is made from those numbers.

Run: DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \
     .venv/bin/python bench/bench_measured.py --fits fits [--run] [--rst F]
"""

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from analysis.families import model_names
from gonio.atomic import atomic_write

#: Every registered model, in the registry's order (the microcylinder first).
MODELS = model_names()


def _load(path: Path) -> dict:
    return json.loads(path.read_text())


def _p(x) -> str:
    """A p-value as the page writes it: two digits, or the power of ten below 1e-3."""
    if x is None:
        return "--"
    return f"{x:.2f}" if x >= 0.01 else f"{x:.0e}".replace("e-0", "e-")


def _interval(s: dict, unit: str = "") -> str:
    return f"{s['median']:.3g} [{s['lo95']:.3g}, {s['hi95']:.3g}]{unit}"


def dataset_row(fits: Path, name: str, entry: dict) -> dict:
    """What the table says of one dataset, read from its fits' files."""
    res = _load(fits / name / "results.json")
    regions = res["quality"].get("adequacy", {}).get("regions", {})
    models = entry.get("models", {})
    elpd = {m: (models[m]["elpd"], models[m]["se"]) for m in MODELS
            if m in models and models[m].get("elpd") is not None}
    best = max(elpd, key=lambda m: elpd[m][0]) if elpd else None
    params = res["parameters"]
    return {"name": name, "converged": res["converged"], "steps": entry.get("steps"),
            "wall_s": entry.get("wall_s"), "elpd": elpd, "best": best,
            "rank": models.get("microcylinder", {}).get("rank"),
            "d_se": {m: (models[m].get("d_elpd"), models[m].get("d_se")) for m in models},
            "rotation": params.get("rotation"), "area1": params.get("area1"),
            "left_right": regions.get("left_right", {}).get("p"),
            "light_view": regions.get("light_view", {}).get("p"),
            "adequate": res.get("adequate"),
            "adequate_models": sum(bool(models[m].get("adequate")) for m in models)}


def _list_table(head: list[str], body: list[list[str]]) -> list[str]:
    out = [".. list-table::", "   :header-rows: 1", ""]
    for cells in [head, *body]:
        out += [f"   {'*' if i == 0 else ' '} - {c}" for i, c in enumerate(cells)]
    return out


def table_rst(rows: list[dict]) -> list[str]:
    """Two tables that fit a page's column: every model's elpd, then the microcylinder's
    convergence, orientation and residual splits."""
    elpd = []
    for r in rows:
        cells = [r["name"]]
        for m in MODELS:
            e = r["elpd"].get(m)
            text = "--" if e is None else f"{e[0]:.0f} ± {e[1]:.0f}"
            cells.append(f"**{text}**" if m == r["best"] else text)
        elpd.append(cells)
    fits = []
    for r in rows:
        conv = (f"{r['steps']:,} ({r['wall_s']:.0f} s)" if r["converged"]
                else f"not converged ({r['steps']:,} steps)")
        fits.append([r["name"], conv,
                     _interval(r["rotation"]) if r["rotation"] else "fixed (0)",
                     _interval(r["area1"]) if r["area1"] else "--",
                     _p(r["left_right"]), _p(r["light_view"])])
    return [*_list_table(["dataset", *MODELS], elpd), "",
            "The microcylinder's fits: the step its convergence checks passed (its wall time), "
            "its rotation and area share (median [95% interval]), and the Mann-Whitney p of its "
            "residuals split left against right and light against view (the adequacy checks' "
            "region tests):", "",
            *_list_table(["dataset", "converged at step (wall)", "rotation (deg)", "area1",
                          "left/right p", "light/view p"], fits)]


def sentences(rows: list[dict], wall: float | None) -> list[str]:
    """The page's findings, each made from the rows."""
    n = len(rows)
    conv = [r for r in rows if r["converged"]]
    steps = [r["steps"] for r in conv]
    out = [f"- **Convergence.** {len(conv)} of the {n} microcylinder fits converged within "
           f"20,000 steps" + (f" (at {min(steps):,} to {max(steps):,} steps)" if steps else "")
           + "."]
    felts = [r for r in rows if r["name"].startswith("rgl_")]
    if felts:
        out.append("- **The felts** took " + ", ".join(
            f"{r['wall_s']:.0f} s ({r['name'].split('_')[1]})" for r in felts)
            + " in wall time, two fits at once on the two cores.")
    first = [r["name"] for r in rows if r["best"] == "microcylinder"]
    out.append(f"- **Ranking.** The microcylinder model has the highest elpd on {len(first)} "
               f"of the {n}" + (f" ({', '.join(first)})" if first else "") + "; " + "; ".join(
                   f"{r['best']} on {r['name']}" for r in rows
                   if r["best"] not in (None, "microcylinder")) + ".")
    close = []
    for r in rows:
        if r["best"] == "microcylinder":
            continue
        d, se = r["d_se"].get("microcylinder", (None, None))
        if d is not None and se and abs(d) <= 2 * se:
            close.append(f"{r['name']} ({abs(d):.0f} ± {se:.0f})")
    if close:
        out.append("- Within 2 standard errors of the best, where the data cannot separate "
                   "them: the microcylinder on " + ", ".join(close) + ".")
    curet = [r for r in rows if r["name"].startswith("curet_")]
    split = [r["name"] for r in curet if r["left_right"] is not None and r["left_right"] < 0.01]
    out.append(f"- **The left/right pattern** (p < 0.01) remains on {len(split)} of the "
               f"{len(curet)} CUReT fits" + (f" ({', '.join(split)})" if split else "") + ".")
    adequate = sum(bool(r["adequate"]) for r in rows)
    models = sum(r["adequate_models"] for r in rows)
    total = sum(len(r["elpd"]) for r in rows)
    out.append(f"- **Adequate**: {adequate} of the {n} microcylinder fits, {models} of all "
               f"{total} fits.")
    if wall is not None:
        out.append(f"- **Time**: {wall / 60:.1f} min for all {total} fits "
                   f"(``--models all``, two Dask workers).")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fits", type=Path, required=True)
    ap.add_argument("--run", action="store_true", help="run fit-measured --models all first")
    ap.add_argument("--rst", type=Path, help="write the page's fragment here")
    ap.add_argument("--wall", type=float, help="the wall time of the run that made the fits, "
                    "seconds (where it was not this script's --run)")
    ap.add_argument("--load", type=float, help="the load average during that run (default: "
                    "the 1-minute load at the end of --run, or now)")
    args = ap.parse_args(argv)
    wall = args.wall
    if args.run:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "reports", "fit-measured", "--models", "all",
                        "--workers", "2", "-o", str(args.fits)], check=False)
        wall = time.perf_counter() - t0
    doc = _load(args.fits / "measured.json")
    rows = [dataset_row(args.fits, n, e) for n, e in doc["datasets"].items()]
    load = args.load if args.load is not None else os.getloadavg()[0]
    lines = [f"Fitted {time.strftime('%Y-%m-%d')} on {platform.machine()} with "
             f"{os.cpu_count()} cores at a load of {load:.1f} (``bench/bench_measured.py``; "
             f"``fit-measured --models all``, seed 0, ``--max-steps 20000``). PSIS-LOO elpd "
             f"± se of each model's fit, the best in bold:", "", *table_rst(rows), "",
             *sentences(rows, wall), ""]
    print("\n".join(lines))
    if args.rst:
        with atomic_write(args.rst, "w") as fh:
            fh.write("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
