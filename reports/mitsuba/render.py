r"""Render microcyl's scenes in Mitsuba 3: the ``mitsuba`` engine of ``microcyl render``.

:func:`render_mitsuba` renders a :class:`reports.render.scenes.Scene` (or its name) with the cloth as
the ``microcylinder`` BSDF (:mod:`reports.mitsuba.plugin`) in a scene built from the same camera,
geometry, key light and sky (:mod:`reports.mitsuba.scene`), with Mitsuba's ``path``
integrator: every bounce up to ``max_depth`` (8 by default; 2 is direct light alone, what the
built-in renderer computes), next-event estimation of the key light and of the sky (in two
scenes, one per light, whose images are summed), and MIS of the BSDF's own draws
(``Fabric.sample``'s).

Variants: :func:`pick_variant` takes ``llvm_ad_rgb`` when Dr.Jit finds a usable LLVM, else
``scalar_rgb``. Whether LLVM works is asked of a subprocess (:func:`variant_works`): an
unusable libLLVM (on Debian LLVM 14 and 15, "Cannot select fmaximum") aborts the process that
loads it. ``scalar_rgb`` traces one ray at a time through the Python BSDF: use it for small
images (64 x 36 at 4 spp, velvet: 4 s with start-up on 2 cores; llvm_ad_rgb renders 1280 x 720
at 16 spp in 8 s once LLVM has compiled the kernel, 20-45 s the first time for a fabric,
scene, size and spp, then cached by Dr.Jit in ~/.drjit).

Mitsuba is optional: this module imports it on use.
"""

from __future__ import annotations

import contextlib
import functools
import importlib.util
import os
import subprocess
import sys

import numpy as np

from brdf.fabric import Fabric
from gonio.progress import heartbeat, progress_bar
from reports.mitsuba import plugin
from reports.mitsuba.plugin import RGB_VARIANTS
from reports.render.checks import check_size, resolve_fabric, scene_of

__all__ = ["render_mitsuba", "auto_engine", "pick_variant", "variant_works", "have_mitsuba",
           "MISSING", "PASS_SAMPLES"]

#: The error of a Mitsuba render without Mitsuba installed.
MISSING = "--engine mitsuba needs mitsuba (pip install mitsuba)"
#: Most samples (pixels x spp) in one ``mi.render`` call; more are rendered in passes.
PASS_SAMPLES = 1 << 24

_PROBE = ("import mitsuba as mi, drjit as dr; mi.set_variant({v!r}); "
          "x = dr.maximum(mi.Float([1, 2]), mi.Float([1.5, 0])); print(float(dr.sum(x)[0]))")


def have_mitsuba() -> bool:
    """Whether ``import mitsuba`` would find Mitsuba (without importing it)."""
    return importlib.util.find_spec("mitsuba") is not None


@functools.lru_cache(maxsize=None)
def variant_works(variant: str) -> tuple[bool, str]:
    """Whether Mitsuba's ``variant`` runs here, asked of a subprocess, and why not.

    Returns
    -------
    (bool, str)
        True and "" when a small Dr.Jit computation in that variant gives the right answer;
        else False and the subprocess's LLVM (or last) error line.
    """
    if not have_mitsuba():
        return False, "mitsuba is not installed"
    if variant == "scalar_rgb":
        return True, ""
    try:
        p = subprocess.run([sys.executable, "-c", _PROBE.format(v=variant)],
                           capture_output=True, text=True, timeout=120, env=dict(os.environ))
    except subprocess.TimeoutExpired:
        return False, "the probe timed out"
    if p.returncode == 0 and p.stdout.strip() == "3.5":
        return True, ""
    lines = p.stderr.strip().splitlines() or [f"exit status {p.returncode}"]
    return False, next((ln for ln in lines if "LLVM" in ln or "CUDA" in ln), lines[-1])


def auto_engine(fabric) -> str:
    """The engine ``--engine auto`` means for ``fabric`` (every verb that renders):
    ``mitsuba`` where Mitsuba is installed, ``llvm_ad_rgb`` runs and ``fabric`` is a
    :class:`brdf.fabric.Fabric`, else ``builtin``."""
    usable = (isinstance(fabric, Fabric) and have_mitsuba()
              and variant_works("llvm_ad_rgb")[0])
    return "mitsuba" if usable else "builtin"


def pick_variant(variant: str | None = None) -> str:
    """The Mitsuba variant to render in: ``variant`` checked, or the fastest that works.

    Parameters
    ----------
    variant : str, optional
        One of :data:`reports.mitsuba.RGB_VARIANTS`; default ``llvm_ad_rgb`` where it works,
        else ``scalar_rgb``.

    Raises
    ------
    ImportError
        Mitsuba is not installed (:data:`MISSING`).
    ValueError
        An unknown variant, or one that does not run here (the reason given).
    """
    if not have_mitsuba():
        raise ImportError(MISSING)
    if variant is None:
        return "llvm_ad_rgb" if variant_works("llvm_ad_rgb")[0] else "scalar_rgb"
    if variant not in RGB_VARIANTS:
        raise ValueError(f"--variant {variant!r} is unknown; choose one of "
                         f"{', '.join(RGB_VARIANTS)}")
    ok, why = variant_works(variant)
    if not ok:
        raise ValueError(f"--variant {variant} does not run here ({why}); scalar_rgb always "
                         f"does, llvm_ad_rgb needs libLLVM (set DRJIT_LIBLLVM_PATH)")
    return variant


def _check(fabric, max_depth, threads):
    if not isinstance(fabric, Fabric):
        raise ValueError(f"fabric={fabric!r}: the Mitsuba engine renders a brdf.Fabric (the "
                         f"microcylinder plugin's parameters), not any BRDF")
    if isinstance(max_depth, bool) or not isinstance(max_depth, (int, np.integer)) \
            or not (max_depth == -1 or 1 <= max_depth <= 1024):
        raise ValueError(f"max_depth={max_depth!r} must be -1 (unbounded) or 1 to 1024")
    if threads is not None and (isinstance(threads, bool) or not isinstance(threads, int)
                                or threads < 1):
        raise ValueError(f"workers={threads!r} must be a positive integer")


def render_mitsuba(scene, fabric, width=1280, height=720, spp=16, *, seed=0, max_depth=8,
                   variant=None, workers=None, progress=True, mask=False):
    """Render a microcyl scene in Mitsuba 3 with cloth of ``fabric``.

    Parameters
    ----------
    scene : str or reports.render.scenes.Scene
        A name of :data:`reports.render.scenes.SCENES` or a Scene.
    fabric : str or brdf.Fabric
        A preset name or a Fabric (the ``microcylinder`` BSDF takes its every parameter).
    width, height : int
        Pixels, at most 1280 x 720 (:func:`reports.render.engine.check_size`).
    spp : int
        Samples per pixel, 1 to 4096; rendered in passes of at most :data:`PASS_SAMPLES`
        samples, each with its own seed.
    seed : int
        The sampler's seed (non-negative).
    max_depth : int
        Longest path: 8 by default, 2 for direct light only, -1 unbounded.
    variant : str, optional
        Mitsuba variant (:func:`pick_variant`).
    workers : int, optional
        Dr.Jit's threads (JIT variants); default all cores.
    progress : bool
        A tqdm bar over the passes.
    mask : bool
        Also return the cloth's coverage (:func:`reports.render.engine.cloth_coverage`, traced by
        the built-in renderer's geometry), for :func:`reports.render.exposure.auto_exposure`.

    Returns
    -------
    (height, width, 3) float32 ndarray
        Linear RGB radiance, W / (m^2 sr) for intensities in W/sr (as :func:`reports.render.engine.
        render`).
    (height, width) float32 ndarray
        With ``mask=True``, a second value: the fraction of each pixel's samples whose first
        hit is cloth.

    Notes
    -----
    A scene with a sky is rendered as two Mitsuba scenes, one with the key light alone and
    one with the sky alone, each at ``spp`` samples a pixel, and the two images summed (light
    transport is linear in the emitters): Mitsuba's path integrator sends each shadow ray to
    one emitter picked at random, and a lit floor whose rays find the sky half of the time
    flickers between twice its key light and its sky light.  Each path thus samples both
    lights; a render costs about twice one scene's at the same ``spp``.

    Raises
    ------
    ImportError
        Mitsuba is not installed.
    ValueError
        An unknown scene or fabric, a bad size, spp, seed, depth or variant, before rendering.
    """
    # lazy: the engine's imageio pulls in colour-science (~2 s), which `microcyl --help` skips
    from reports.render.engine import cloth_coverage

    check_size(width, height, spp)
    scene = scene_of(scene, None, None)
    fabric = resolve_fabric(fabric)
    _check(fabric, max_depth, workers)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed={seed!r} must be a non-negative integer")
    variant = pick_variant(variant)
    mi = _start_mitsuba(variant, workers)
    per_pass = max(1, min(spp, PASS_SAMPLES // (width * height)))
    passes = [per_pass] * (spp // per_pass) + ([spp % per_pass] if spp % per_pass else [])
    mscenes = _load_scenes(mi, scene, fabric, width, height, per_pass, max_depth)
    image = _render_passes(mi, mscenes, passes, seed, (height, width), progress,
                           desc=f"render {scene.name or 'scene'} (mitsuba {variant})")
    if mask:
        return image, cloth_coverage(scene, width, height, spp=min(spp, 4), seed=seed)
    return image


def _start_mitsuba(variant, workers):
    """Set ``variant``, register the plugin, set Dr.Jit's threads; return the mitsuba module."""
    mi, dr, _, _ = plugin.mitsuba_modules()
    mi.set_variant(variant)
    plugin.register()
    if workers is not None and variant != "scalar_rgb":
        dr.set_thread_count(workers)
    return mi


def _load_scenes(mi, scene, fabric, width, height, per_pass, max_depth) -> list:
    """The Mitsuba scenes of ``scene``: one per light (key, sky), or one of its only light."""
    mitsuba_scene = plugin.mitsuba_modules()[3]

    # one scene per light (key, sky), their images summed: every path samples both lights
    # (one scene of both would send each shadow ray to one of them, chosen at random)
    lights = ("key", "sky") if scene.environment is not None else ("both",)
    return [mi.load_dict(mitsuba_scene.scene_dict(scene, fabric, width, height, per_pass,
                                                  seed=0, max_depth=max_depth,
                                                  lights=which)) for which in lights]


def _render_passes(mi, mscenes, passes, seed, shape, progress, desc) -> np.ndarray:
    """The mean over ``passes`` (samples per pass) of every scene's images summed, float32
    (height, width, 3); each pass of each scene with its own seed."""
    total = np.zeros((*shape, 3))
    with progress_bar(len(passes) * len(mscenes), unit="pass", enabled=progress,
                      desc=desc) as bar:
        for j, mscene in enumerate(mscenes):
            for k, n in enumerate(passes):
                # the first pass compiles the kernel (up to minutes, with no update): a
                # line every 10 s on a pipe says it is still running
                beat = (heartbeat(bar, "the first pass compiles the kernel") if k == 0
                        else contextlib.nullcontext())
                with beat:
                    img = mi.render(mscene, seed=(int(seed) * 1000003 + 1009 * j + k) % 2**32,
                                    spp=n)
                total += np.asarray(img, dtype=np.float64)[..., :3] * n
                bar.update()
    return (total / sum(passes)).astype(np.float32)
