"""The workflow of ``microcyl fit-images``: a fabric's parameters from photographs.

:func:`fit_images` takes images (each with the scene it shows, the render's seed), a start
fabric and the free parameters, and a ``render(scene, fabric, seed) -> (H, W, 3)`` callable
(the CLI passes the renderer the scene file names, :mod:`reports.render` or Mitsuba: analysis
imports no renderer). The method:

1. the noise model (:mod:`analysis.imagefit.noise`): the camera's shot and read noise, and the
   render's own Monte Carlo variance from ``mc_seeds`` renders of independent seeds;
2. Levenberg-Marquardt (:mod:`analysis.imagefit.solver`) on the normalized residuals of all
   images, every render with the fit's one seed (common random numbers), Jacobian by forward
   finite differences of the renders;
3. the Monte Carlo variance estimated again at the optimum and the fit polished with it;
4. the Laplace approximation at the optimum (:func:`analysis.imagefit.solver.laplace`), in
   flat coordinates (:mod:`analysis.imagefit.summary`), widened by chi2 per degree of freedom
   where the residuals exceed the noise model.

``DIR/results.json`` (schema ``microcyl-fit-images``) holds the parameters' medians and
intervals, the correlation, ``converged`` and ``reason``, ``warnings``, the noise model and
the history; ``DIR/state.json`` the last step, so that the same command run again resumes
there (after SIGKILL too); ``plots(...)`` (optional) draws the figures.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import time
from pathlib import Path
from typing import Callable

import numpy as np

import brdf
from analysis.fit.outputs import check_fit_folder, claim_fit_folder
from analysis.folderlock import output_lock
from analysis.imagefit.noise import NoiseModel, mc_covariance, pool
from analysis.imagefit.solver import laplace, levenberg_marquardt
from analysis.imagefit.summary import Params, summaries, warnings_of
from analysis.paramnames import parse_free
from gonio.atomic import atomic_write
from gonio.jsonplain import plain
from gonio.progress import progress_bar
from gonio.statefields import load_json

__all__ = ["Observation", "fit_images", "SCHEMA", "SCHEMA_VERSION"]

SCHEMA, SCHEMA_VERSION = "microcyl-fit-images", 1
#: Seed stride between the Monte Carlo noise's renders (distinct from the fit's seeds).
SEED_STRIDE = 7919
#: The second seed of the decorrelated loss: the image's seed plus this.
PAIR_OFFSET = 104729


@dataclasses.dataclass(frozen=True)
class Observation:
    """One image: ``name`` (its file), ``image`` (H, W, 3) linear RGB, ``scene`` (whatever
    ``render`` takes), ``seed`` (the fit's renders of it) and ``image_mc``: the image's own
    Monte Carlo variance in units of one of the fit's renders' (0, a photograph's; an image
    rendered at N samples a pixel, fitted by renders of n, has n / N)."""

    name: str
    image: np.ndarray
    scene: object
    seed: int
    image_mc: float = 0.0


def _checked(observations, fabric, free) -> tuple[list, Params]:
    if not isinstance(fabric, brdf.Fabric):
        raise ValueError("--fabric: the start must be a microcylinder fabric (a preset, a fit "
                         "folder or a fabric file), not a table")
    if not observations:
        raise ValueError("IMAGE: give at least one image")
    for ob in observations:
        img = np.asarray(ob.image)
        if img.ndim != 3 or img.shape[2] != 3 or not np.all(np.isfinite(img)):
            raise ValueError(f"{ob.name}: must be a finite (H, W, 3) RGB image")
        mc = ob.image_mc
        if isinstance(mc, bool) or not isinstance(mc, (int, float)) \
                or not (np.isfinite(mc) and mc >= 0):
            raise ValueError(f"{ob.name}: image_mc {mc!r}: must be a finite number >= 0 (the "
                             f"image's Monte Carlo variance in units of a fit render's)")
    names = parse_free(free)
    values = fabric.values()
    bad = [n for n in names if n not in values]
    if bad:
        raise ValueError(f"--free {bad[0]}: not a parameter of the fabric "
                         f"({', '.join(values)})")
    return [dataclasses.replace(ob, image=np.asarray(ob.image, float)) for ob in observations], \
        Params.of(names)


def _digest(observations, params, start, noise, mc_seeds) -> str:
    h = hashlib.sha256()
    for ob in observations:
        h.update(ob.image.tobytes())
        h.update(repr((ob.name, ob.scene, ob.seed, float(ob.image_mc))).encode())
    h.update(repr((params.names, start.tolist(), noise, mc_seeds)).encode())
    return h.hexdigest()


class _Model:
    """The renders of every image at flat coordinates ``u`` (counted)."""

    def __init__(self, observations, fabric, params, render):
        self.obs, self.fabric, self.params, self.render = observations, fabric, params, render
        self.renders = 0
        self.sd = None

    def fabric_at(self, u):
        x = self.params.to_natural(u)
        return self.fabric.with_values(dict(zip(self.params.names, map(float, x))))

    def images(self, u, seed_offset=0) -> list:
        fab = self.fabric_at(u)
        out = []
        for ob in self.obs:
            img = np.asarray(self.render(ob.scene, fab, ob.seed + seed_offset), float)
            if img.shape != ob.image.shape:
                raise ValueError(f"{ob.name}: the render is {img.shape[1]} x {img.shape[0]}, "
                                 f"the image {ob.image.shape[1]} x {ob.image.shape[0]}")
            out.append(img)
        self.renders += len(self.obs)
        return out

    def estimate_noise(self, u, noise, mc_seeds) -> None:
        """The residuals' sd (camera, the render's Monte Carlo and the image's own: the
        weights, from the Monte Carlo variance pooled over 3 x 3 pixels), and the covariance
        ``C`` of each pixel's three normalized residuals of the mean of two seeds' renders
        (camera, half the render's Monte Carlo covariance, the image's own; each pixel's
        own Monte Carlo covariance, unbiased for the sums over pixels it enters)."""
        runs = [self.images(u, SEED_STRIDE * (k + 1)) for k in range(mc_seeds)]
        self.sd, blocks = [], []
        for i, ob in enumerate(self.obs):
            cov = mc_covariance([r[i] for r in runs], pooled=False)   # each pixel's own
            mc = np.diagonal(pool(cov), axis1=-2, axis2=-1)       # pooled, for the weights
            mean = np.mean([r[i] for r in runs], axis=0)
            var = noise.variance(mean, mc * (1.0 + ob.image_mc))
            sd = np.sqrt(var)
            camera = var - mc * (1.0 + ob.image_mc)
            c = cov * (0.5 + ob.image_mc) + camera[..., None] * np.eye(3)
            blocks.append((c / (sd[..., :, None] * sd[..., None, :])).reshape(-1, 3, 3))
            self.sd.append(sd)
        self.C = np.concatenate(blocks)

    @property
    def v(self) -> np.ndarray:
        """Each normalized residual's variance (the diagonal of ``C``), in the residuals'
        order."""
        return np.diagonal(self.C, axis1=-2, axis2=-1).ravel()

    def residuals(self, u, offset=0) -> np.ndarray:
        return np.concatenate([((m - ob.image) / sd).ravel() for m, ob, sd
                               in zip(self.images(u, offset), self.obs, self.sd)])

    def pair(self, u) -> tuple:
        """The normalized residuals of two renders of independent seeds."""
        return self.residuals(u), self.residuals(u, PAIR_OFFSET)


def _resume(state_path, digest):
    """The checkpoint's (u, history) when it belongs to this fit, else (None, []); read as a
    state file from others (:func:`gonio.statefields.load_json`: no link, no FIFO, capped)."""
    if not state_path.exists():
        return None, []
    try:
        state = load_json(state_path, "fit-images checkpoint")
        if state.get("digest") == digest:
            return np.asarray(state["u"], float), list(state["history"])
    except (ValueError, KeyError, TypeError, AttributeError):
        pass
    return None, []


def fit_images(observations, fabric, free, out_dir, *, render: Callable,
               noise: NoiseModel = NoiseModel(), mc_seeds: int = 4, max_iter: int = 30,
               plots: Callable | None = None, progress: bool = False,
               log: Callable | None = None) -> dict:
    """Fit the ``free`` parameters of ``fabric`` to ``observations`` (module notes).

    Parameters
    ----------
    observations : list of Observation
    fabric : brdf.Fabric
        The start and the fixed values.
    free : str or sequence of str
        Free parameter names (``kd1,gamma_s1``; aliases such as ``albedo1`` expand).
    out_dir : path
        Written: ``results.json``, ``state.json`` and the figures.
    render : callable
        ``render(scene, fabric, seed) -> (H, W, 3)`` linear RGB.
    noise : NoiseModel
        The camera's noise.
    mc_seeds : int
        Independent renders for the Monte Carlo variance (at least 2).
    max_iter : int
        Steps of the optimizer at most.
    plots : callable, optional
        ``plots(doc, panels, out_dir) -> {name: file}``; ``panels`` a list of
        ``(name, image, fitted render, normalized residual)``.
    progress : bool
        A progress bar over the steps.
    log : callable, optional
        ``log(str)`` for one line a stage.

    Returns
    -------
    dict
        The ``results.json`` document.
    """
    if isinstance(mc_seeds, bool) or not isinstance(mc_seeds, int) or not 2 <= mc_seeds <= 64:
        raise ValueError(f"--mc-seeds {mc_seeds!r}: must be an integer from 2 to 64")
    if isinstance(max_iter, bool) or not isinstance(max_iter, int) or not 1 <= max_iter <= 1000:
        raise ValueError(f"--max-steps {max_iter!r}: must be an integer from 1 to 1000")
    observations, params = _checked(observations, fabric, free)
    out = Path(out_dir)
    with output_lock(out, "fit"):             # a fit's folder: locked, and only its files
        check_fit_folder(out)
        claim_fit_folder(out, STATE_FILES + (PLOT_FILES if plots is not None else ()))
        return _fit_in(out, observations, fabric, params, render=render, noise=noise,
                       mc_seeds=mc_seeds, max_iter=max_iter, plots=plots, progress=progress,
                       log=log)


#: What fit-images writes into its folder: its checkpoint and results, then its figures
#: (:data:`reports.plots.imagefit.FILES`).
STATE_FILES = ("state.json", "results.json")
PLOT_FILES = ("images.png", "steps.png")


def _fit_in(out, observations, fabric, params, *, render, noise, mc_seeds, max_iter, plots,
            progress, log) -> dict:
    """:func:`fit_images` in its locked, checked folder ``out``."""
    say = log or (lambda s: None)
    t0 = time.perf_counter()
    start = np.clip([fabric.values()[n] for n in params.names], params.lo, params.hi)
    model = _Model(observations, fabric, params, render)
    lo, hi = params.flat_bounds
    digest = _digest(observations, params, start, noise, mc_seeds)
    u0, history = _resume(out / "state.json", digest)
    if u0 is not None:
        say(f"resuming from step {len(history)} of {out / 'state.json'}")
    u0 = params.to_flat(start) if u0 is None else u0
    say(f"Monte Carlo noise: {mc_seeds} renders of independent seeds of each of "
        f"{len(observations)} images")
    model.estimate_noise(u0, noise, mc_seeds)
    sol = _optimize(model, u0, lo, hi, max_iter, history, out, digest, progress)
    say(f"{sol.reason}; Monte Carlo noise again at the optimum")
    model.estimate_noise(sol.u, noise, mc_seeds)
    sol = _optimize(model, sol.u, lo, hi, max(3, max_iter // 3), sol.history, out, digest,
                    progress)
    doc = _document(model, sol, start, noise, mc_seeds, time.perf_counter() - t0)
    if plots is not None:
        fitted = model.images(sol.u)
        panels = [(ob.name, ob.image, m, (m - ob.image) / sd)
                  for ob, m, sd in zip(observations, fitted, model.sd)]
        doc["plots"] = plots(doc, panels, out)
    with atomic_write(out / "results.json", "w") as fh:
        json.dump(plain(doc), fh, indent=1)
        fh.write("\n")
    return doc


def _optimize(model, u0, lo, hi, max_iter, history, out, digest, progress):
    """Levenberg-Marquardt from ``u0``, a checkpoint (``state.json``) and a tick a step."""
    hist = list(history)
    with progress_bar(max_iter, desc="fit-images", unit="step", enabled=progress) as bar:
        def on_step(entry):
            hist.append(entry)
            if not entry.get("start"):
                bar.update()
            bar.set_postfix(loss=f"{entry['loss']:.6g}")
            with atomic_write(out / "state.json", "w") as fh:
                json.dump({"digest": digest, "u": entry["u"], "history": hist}, fh)

        sol = levenberg_marquardt(model.pair, u0, lo, hi, max_iter=max_iter,
                                  on_step=on_step, history=hist)
    sol.history = hist
    return sol


def _document(model, sol, start, noise, mc_seeds, seconds) -> dict:
    params = model.params
    r = 0.5 * (sol.r[0] + sol.r[1])          # the two seeds' mean render, normalized
    n, p = r.size, len(params.names)
    chi2, expected = float(r @ r), float(model.v.sum())
    scale = max(1.0, chi2 / max(expected - p, 1.0))
    cov = laplace(0.5 * (sol.J[0] + sol.J[1]), params.prior_sd, scale, model.C)
    sd = np.sqrt(np.diag(cov))
    per_image, offset = [], 0
    for ob in model.obs:
        k = ob.image.size
        per_image.append({"name": ob.name, "width": ob.image.shape[1],
                          "height": ob.image.shape[0], "seeds": [ob.seed,
                                                                 ob.seed + PAIR_OFFSET],
                          "chi2": float(r[offset:offset + k] @ r[offset:offset + k]),
                          "expected": float(model.v[offset:offset + k].sum()), "values": k})
        offset += k
    return {
        "schema": SCHEMA, "schema_version": SCHEMA_VERSION, "model": "microcylinder",
        "method": ("Levenberg-Marquardt on the decorrelated loss of two renders of "
                   "independent seeds an image, each seed's random numbers common to every "
                   "step, Jacobians by forward finite differences; intervals from the "
                   "Laplace approximation at the optimum in flat coordinates"),
        "converged": sol.converged, "reason": sol.reason,
        "warnings": warnings_of(params, sol.u, cov, scale=scale, converged=sol.converged,
                                reason=sol.reason),
        "parameters": summaries(params, sol.u, cov, start),
        "correlation": (cov / np.outer(sd, sd)).tolist(),
        "noise": {**noise.describe(), "mc_seeds": mc_seeds, "values": n,
                  "image_mc": {ob.name: float(ob.image_mc) for ob in model.obs},
                  "chi2": chi2, "chi2_expected": expected,
                  "chi2_ratio": chi2 / max(expected - p, 1.0), "scale": scale},
        "fit": {"steps": len(sol.history), "renders": model.renders, "seconds": seconds,
                "images": per_image,
                "history": [{"iteration": h["iteration"], "loss": h["loss"],
                             "accepted": h["accepted"], "start": bool(h.get("start")),
                             "values": dict(zip(params.names,
                                                params.to_natural(h["u"]).tolist()))}
                            for h in sol.history]},
        "plots": {}}
