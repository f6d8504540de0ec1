"""
A Mitsuba 3 scene
=================

The ``microcylinder`` BSDF in a Mitsuba 3 scene written by hand: a ball covered in shot silk
(the warp along the sphere's tangent, turned 30 degrees about the normal; its colour shifts
with the angle, as shot silk's does) on a velvet floor, a square area lamp and a grey sky,
rendered with the ``direct`` integrator at 360 x 240 and 16 samples per pixel. It runs in
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
    T = mi.ScalarTransform4f
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "direct"},
        "sensor": {"type": "perspective", "fov": 38,
                   "to_world": T().look_at(origin=[0, -6, 2.5], target=[0, 0, -0.2],
                                           up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": 360, "height": 240},
                   "sampler": {"type": "independent", "sample_count": 16}},
        "ball": {"type": "sphere", "center": [0, 0, 0], "radius": 1.0,
                 "bsdf": {"type": "microcylinder", "fabric": "silk_shot", "rotation": 30.0}},
        "floor": {"type": "rectangle", "to_world": T().translate([0, 0, -1]).scale(4),
                  "bsdf": {"type": "microcylinder", "fabric": "velvet"}},
        "lamp": {"type": "rectangle",
                 "to_world": T().look_at(origin=[-3, -2, 4], target=[0, 0, 0],
                                         up=[0, 0, 1]).scale(0.8),
                 "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [12, 12, 12]}}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.25, 0.25, 0.25]}},
    })
    image = np.asarray(mi.render(scene))
    srgb = np.clip(image, 0, 1) ** (1 / 2.2)
    fig = plt.figure(figsize=(7.2, 4.8), dpi=100)    # two screen pixels an image pixel
    ax = fig.add_axes((0, 0, 1, 1))
    ax.imshow(srgb)
    ax.set_axis_off()
