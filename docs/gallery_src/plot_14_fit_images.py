"""
Cloth parameters from photographs
=================================

A hidden fabric (linen_plain with thread 1's ``kd1`` and ``gamma_s1`` moved) photographed, in
a manner of speaking: the cylinder under three key lights, 64 x 36 pixels with camera noise
(:func:`reports.render.truthset.write_truth_images`). :func:`analysis.imagefit.fit_images`
renders the same scenes with the built-in renderer, the renderer passed in as a callable, and
fits both parameters; ``microcyl fit-images`` does the same from the files and writes the same
figure as ``images.png``.
"""
import os
from pathlib import Path

import brdf
from analysis.imagefit import NoiseModel, Observation, fit_images
from reports.plots.imagefit import images_figure
from reports.render.files import render_image
from reports.render.imageio import read_exr
from reports.render.scenefile import read_scene_file, scene_file_path
from reports.render.truthset import write_truth_images

work = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "fit_images"
work.mkdir(parents=True, exist_ok=True)
hidden = brdf.fabric("linen_plain").with_values({"kd1": 0.45, "gamma_s1": 8.0})
paths = write_truth_images(work, hidden, width=64, height=36, spp=8, scenes=("cylinder",))


def render(scene, fabric, seed):
    """The built-in renderer at 4 samples a pixel, the scene's size."""
    return render_image(scene, fabric, width=64, height=36, spp=4, seed=seed, workers=1)


panels = []      # what fit_images hands its plots callable: image, fitted render, residual
# The images are renders at 8 samples a pixel and the fit's at 4: the images' own Monte Carlo
# noise, half a fit render's, is in the noise model (image_mc; --rendered on the command line)
obs = [Observation(p.name, read_exr(p), read_scene_file(scene_file_path(p)).scene, 1 + k,
                   image_mc=4 / 8) for k, p in enumerate(paths)]
doc = fit_images(obs, brdf.fabric("linen_plain"), "kd1,gamma_s1", work / "fit", render=render,
                 noise=NoiseModel(shot=1e-4, read=0.002), mc_seeds=3,
                 plots=lambda doc, got, out: panels.extend(got) or {})
{name: (round(p["median"], 4), round(p["lo95"], 4), round(p["hi95"], 4))
 for name, p in doc["parameters"].items()}

# %%
# The truth is kd1 = 0.45 and gamma_s1 = 8 degrees; the start was 0.3 and 12. Each row: the
# image, the render at the fitted parameters, and the residual in units of the noise model's
# standard deviation.
fig = images_figure(panels)
