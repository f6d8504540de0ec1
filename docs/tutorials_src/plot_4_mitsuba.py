"""
The fabric in Mitsuba 3
=======================

:mod:`reports.mitsuba.plugin` is a Mitsuba 3 plugin: the BSDF ``microcylinder``, written in Dr.Jit, in
the ``scalar_rgb``, ``llvm_ad_rgb`` and ``cuda_ad_rgb`` variants. After ``register()``, a preset
is ``{"type": "microcylinder", "fabric": "velvet"}``, and every thread parameter (``eta1``,
``albedo1``, ``kd1``, ``gamma_s1``, ``gamma_v1`` in degrees, ``area1``, ``offsets1``, ...) and
option (``masking``, ``rotation`` in degrees, ...) is a key of the same dictionary. The warp
follows the surface's first tangent ``dp_du``.

This page needs Mitsuba's LLVM variant (``libllvm19`` and ``DRJIT_LIBLLVM_PATH``, see
:doc:`../getting_started`); where it does not run, the steps below are skipped with a note.
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from reports.mitsuba.render import have_mitsuba, variant_works

ok, why = variant_works("llvm_ad_rgb") if have_mitsuba() else (False, "no Mitsuba")
print("llvm_ad_rgb:", "runs" if ok else f"does not run here ({why}); the steps below are skipped")

# %%
# A scene by hand
# ---------------
# A cloth rectangle of silk_shot turned 30 degrees, a point lamp and a grey sky.
if ok:
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    from reports.mitsuba import plugin as microcyl_mitsuba
    microcyl_mitsuba.register()             # after set_variant, once per variant

    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "direct"},
        "sensor": {"type": "perspective", "fov": 45,
                   "to_world": mi.ScalarTransform4f().look_at(
                       origin=[0, -2.5, 2], target=[0, 0, 0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": 128, "height": 96},
                   "sampler": {"type": "independent", "sample_count": 16}},
        "cloth": {"type": "rectangle",
                  "bsdf": {"type": "microcylinder", "fabric": "silk_shot", "rotation": 30.0}},
        "lamp": {"type": "point", "position": [1, -1, 3],
                 "intensity": {"type": "rgb", "value": [20, 20, 20]}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.2, 0.2, 0.2]}},
    })
    before = np.asarray(mi.render(scene))

# %%
# Editing the fabric
# ------------------
# ``mi.traverse`` exposes each thread's numbers and the rotation; ``update()`` refuses an
# out-of-range value with its thread named, and the JIT variant reuses its compiled kernel.
if ok:
    params = mi.traverse(scene)
    params["cloth.bsdf.albedo2"] = mi.Color3f(0.05, 0.05, 0.3)
    params["cloth.bsdf.gamma_s1"] = 12.0     # degrees
    params.update()
    after = np.asarray(mi.render(scene))
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.9))
    for ax, image, title in zip(axes, (before, after), ("silk_shot", "edited")):
        ax.imshow(np.clip(image, 0, 1) ** (1 / 2.2))
        ax.set_title(title)
        ax.set_axis_off()

# %%
# microcyl's scenes in Mitsuba
# ----------------------------
# ``microcyl render cylinder velvet --engine mitsuba -o velvet.exr`` builds the same scene as
# the built-in renderer (camera, geometry, key light and sky) and path-traces it; a fit's folder
# or an exported dictionary is a FABRIC too.
if ok:
    from reports.cli import main

    out = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "tutorial_mitsuba"
    out.mkdir(parents=True, exist_ok=True)
    assert main(["render", "cylinder", "velvet", "--engine", "mitsuba", "--width", "256",
                 "--height", "144", "--spp", "8", "--quiet", "-o", str(out / "velvet.exr")]) == 0
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.imshow(plt.imread(out / "velvet.png"))
    ax.set_axis_off()
