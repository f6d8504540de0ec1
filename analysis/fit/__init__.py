r"""Bayesian fit of the microcylinder model to a BRDF table: point estimate, then emcee.

Pipeline (:func:`fit`, module by module):

1. :mod:`~analysis.fit.posterior` -- the forward model at the table's pairs
   (:class:`FabricModel`) and the log-posterior (:class:`LogPosterior`), batched over
   parameter sets; the table is masked by :class:`analysis.likelihood.Likelihood` and must keep
   more valid values than free parameters.
2. :mod:`~analysis.fit.optimize` -- L-BFGS-B from several starts with batched finite-difference
   gradients, then the Laplace approximation (batched Hessian), which sizes the starting ball.
3. :mod:`~analysis.fit.sampler` -- ``ensembles`` independent emcee ensembles
   (:mod:`~analysis.fit.ensemble`), stepped in lock-step threads whose log-probability calls
   are stacked into one batch (:mod:`~analysis.fit.lockstep`). Their moves
   (:mod:`~analysis.fit.moves`, emcee's public Move interface): DE and DE snooker, and an
   independence Metropolis-Hastings move from the Laplace approximation, refit at doubling
   steps to each ensemble's own chain as a mixture of Student-t components in warped
   coordinates (:mod:`~analysis.fit.proposal`).
4. :mod:`~analysis.fit.convergence` -- every ``check_every`` steps: converged when every
   parameter has (N - burn) / tau > 50, tau changed < 5% since the last check and split R-hat
   < 1.01; otherwise the fit stops at ``max_steps`` or ``time_limit`` and says so.
5. :mod:`~analysis.fit.checkpoint` -- at every check the chains, random states and proposals
   are written whole to ``checkpoint.h5`` (atomically); the same call resumes from it, a
   finished fit is summarized again without sampling, a killed one loses at most one check
   interval, and Ctrl-C checkpoints the steps done before it raises :class:`FitInterrupted`.
6. :mod:`~analysis.fit.adequacy` and :mod:`~analysis.fit.trust` -- every fit is checked:
   ``adequacy`` (posterior predictive tests: is the model adequate to the data?) and
   ``warnings`` (parameters at a bound, not informed, correlated, implausible; misfit).
7. :mod:`~analysis.fit.results` and :mod:`~analysis.fit.quality` -- :class:`FitResult`,
   ``results.json`` (versioned schema) and ``results.csv``; residuals and the albedo colour
   difference (none for a grey table). :func:`fit_fabric` (:mod:`~analysis.fit.workflow`)
   is the whole of ``microcyl fit``: fit, quality, PSIS-LOO, plots, files.
8. :mod:`~analysis.fit.loo` -- PSIS-LOO (ArviZ) over thinned posterior draws: ``loo`` in
   ``results.json``, the pointwise values in ``loo.npz``, the LOO-PIT;
   :mod:`~analysis.fit.compare` ranks fits of one table by it (``microcyl compare``).

Threading rule
--------------
Only the thread that calls :func:`fit` opens files, and only between runs of the ensembles,
when no ensemble thread is stepping. Ensemble threads compute: they evaluate the model (through
the lock-step batch) and append to their own in-memory chain. The progress bar and the
convergence checks read the chains' step counts and samples from memory, never from a file.
BLAS is limited to one thread inside the fit (the fit's threads already fill the cores).

Examples
--------
>>> import brdf
>>> from analysis.fit import FabricModel, fit
>>> from analysis.params import ParamSpec, defaults_from_fabric
>>> from gonio.table import Table
>>> fab = brdf.fabric("silk_crepe_de_chine")
>>> rng = np.random.default_rng(0)
>>> wi = brdf.directions.from_angles(rng.uniform(0, 1.2, 80), rng.uniform(-3, 3, 80))
>>> wo = brdf.directions.from_angles(rng.uniform(0, 1.2, 80), rng.uniform(-3, 3, 80))
>>> f = fab.eval(wi, wo)
>>> table = Table(wi, wo, f * (1 + 0.05 * rng.normal(size=f.shape)), sigma=0.05 * f + 1e-4)
>>> spec = ParamSpec("gamma_s1", defaults=defaults_from_fabric(fab))
>>> r = fit(table, spec, FabricModel(fab, wi, wo), max_steps=100, progress=False)
>>> bool(r.summary["gamma_s1"]["lo95"] < 5.0 < r.summary["gamma_s1"]["hi95"])
True
"""

import numpy as np  # noqa: F401  (the Examples use it)

from analysis.fit.adequacy import adequacy   # eager: the name is also its module's
from analysis.lazy import lazy_getattr

#: Names loaded on first use, with their modules (:mod:`analysis.lazy`): the sampler
#: loads emcee and scipy.stats (about 0.5 s), which a verb reading a fit folder does not need.
_LAZY = {name: f"analysis.fit.{module}" for module, names in {
    "checkpoint": ("CHECKPOINT_FILE", "CONFIG_FILE", "FitFolder"),
    "compare": ("compare_fits",), "convergence": ("Criteria", "Diagnosis"),
    "driver": ("FitOptions", "fit"), "ensemble": ("Chain", "EnsembleRunner"),
    "lockstep": ("LockStep",), "loo": ("LOO_FILE", "Loo", "load_loo", "psis_loo"),
    "medians": ("FitModel", "MedianFabric", "median_fabric"), "moves": ("EnsembleMoves",),
    "optimize": ("point_estimate",),
    "posterior": ("BaselineForward", "FabricModel", "LogPosterior", "forward_model"),
    "proposal": ("LaplaceMove",), "quality": ("albedo_colours", "albedo_delta_e", "fit_quality"),
    "results": ("SCHEMA_VERSION", "FitResult", "write_results"),
    "sampler": ("FitInterrupted",), "trust": ("fit_warnings",),
    "workflow": ("fit_fabric", "fit_spec"),
}.items() for name in names}
__getattr__ = lazy_getattr(__name__, _LAZY, globals())

__all__ = ["fit", "fit_fabric", "fit_spec", "FitOptions", "FitResult", "FitInterrupted",
           "write_results",
           "FabricModel", "BaselineForward", "forward_model", "LogPosterior", "point_estimate", "LockStep", "Chain",
           "EnsembleRunner", "EnsembleMoves", "LaplaceMove", "Criteria", "Diagnosis",
           "FitFolder", "fit_quality", "albedo_colours", "albedo_delta_e", "CONFIG_FILE",
           "CHECKPOINT_FILE", "SCHEMA_VERSION", "MedianFabric", "median_fabric", "FitModel",
           "Loo", "psis_loo", "load_loo", "LOO_FILE", "compare_fits", "adequacy",
           "fit_warnings"]
