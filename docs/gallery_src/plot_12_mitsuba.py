"""
A Mitsuba 3 scene
=================

The ``microcylinder`` BSDF in a Mitsuba 3 scene written by hand: a cloth rectangle turned
30 degrees, a point lamp and a grey sky, rendered with the ``direct`` integrator. It runs in
``llvm_ad_rgb`` where Dr.Jit finds a usable LLVM (``DRJIT_LIBLLVM_PATH``, see
:doc:`../getting_started`) and is skipped with a note otherwise.
"""
import matplotlib.pyplot as plt
import numpy as np

from reports.mitsuba.render import have_mitsuba, variant_works

ok, why = variant_works("llvm_ad_rgb") if have_mitsuba() else (False, "no Mitsuba")
print("llvm_ad_rgb:", "runs" if ok else f"does not run here ({why})")

# %%
if not ok:
    print("Mitsuba's LLVM variant is not available here; the scene is skipped "
          "(scalar_rgb would render it one ray at a time).")
else:
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    from reports.mitsuba import plugin as microcyl_mitsuba
    microcyl_mitsuba.register()
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "direct"},
        "sensor": {"type": "perspective", "fov": 45,
                   "to_world": mi.ScalarTransform4f().look_at(
                       origin=[0, -2.5, 2], target=[0, 0, 0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": 160, "height": 120},
                   "sampler": {"type": "independent", "sample_count": 16}},
        "cloth": {"type": "rectangle",
                  "bsdf": {"type": "microcylinder", "fabric": "silk_shot", "rotation": 30.0}},
        "lamp": {"type": "point", "position": [1, -1, 3],
                 "intensity": {"type": "rgb", "value": [20, 20, 20]}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.2, 0.2, 0.2]}},
    })
    image = np.asarray(mi.render(scene))
    srgb = np.clip(image, 0, 1) ** (1 / 2.2)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.imshow(srgb)
    ax.set_axis_off()
