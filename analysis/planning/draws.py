r"""Where the parameters may be: the draws a plan averages its criterion over.

A design is good for the parameters it will meet, which are not known before measuring. The
criterion of :mod:`analysis.planning.select` is averaged over K draws of the free parameters,
in the internal (logit) coordinates of :class:`analysis.params.ParamSpec`:

- **From a preset (or any fabric):** a local prior around the fabric's values, the first draw
  the fabric itself and the others

  .. math:: u_k = u_0 + \tau z_k, \qquad z_k \sim N(0, I),

  with :math:`\tau` = :data:`LOCAL_SD` (0.5 in the logit coordinates: a parameter in the middle
  of its range moves by about an eighth of the range, one near a bound by a factor of about
  1.6 in its distance to it). This is the *design prior* (what the planner believes before
  measuring: the fabric is roughly the preset); the *analysis prior* (the flat prior of the
  fit, information 1/3 per internal coordinate) is what the expected covariance includes,
  so that it predicts what ``microcyl fit`` will report. A draw outside the prior's support
  (an area sum above 1, a tied value out of its bounds) is drawn again.
- **From a fit folder:** K samples of the fit's posterior (the second half of every
  ensemble's stored chain, picked with the seed). Free parameters of the plan that the fit
  held fixed stay at the fit's value; the fit's free parameters that the plan holds fixed
  stay at their medians (the fabric of :func:`analysis.fit.medians.median_fabric`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from analysis.fit.checkpoint import CHECKPOINT_FILE, CONFIG_FILE, FitFolder, read_config
from analysis.params import ParamSpec

__all__ = ["prior_draws", "posterior_draws", "fit_folder_spec", "LOCAL_SD", "MAX_DRAWS"]

#: Standard deviation of the local design prior in the internal (logit) coordinates.
LOCAL_SD = 0.5
#: Most draws a plan may average over.
MAX_DRAWS = 256
#: Attempts at a draw inside the prior's support before the centre is taken instead.
_TRIES = 20


def check_draws(draws) -> int:
    """``draws`` as an int in 1..:data:`MAX_DRAWS`; a one-line ValueError otherwise."""
    if isinstance(draws, bool) or not isinstance(draws, (int, np.integer)) or not (
            1 <= draws <= MAX_DRAWS):
        raise ValueError(f"draws must be an integer in 1..{MAX_DRAWS}; got {draws!r}")
    return int(draws)


def prior_draws(spec: ParamSpec, draws: int, rng: np.random.Generator,
                sd: float = LOCAL_SD) -> np.ndarray:
    """K draws (K, ndim) of the local design prior about ``spec``'s start (module notes).

    Examples
    --------
    >>> spec = ParamSpec("kd1,gamma_s1", defaults={"kd1": 0.3, "gamma_s1": 8.0})
    >>> u = prior_draws(spec, 4, np.random.default_rng(0))
    >>> u.shape, bool(np.all(u[0] == spec.start()))
    ((4, 2), True)
    """
    draws = check_draws(draws)
    centre = spec.start()
    out = np.repeat(centre[None], draws, axis=0)
    for k in range(1, draws):
        for _ in range(_TRIES):
            u = centre + sd * rng.standard_normal(centre.size)
            if np.isfinite(spec.log_prior(u[None])[0]):
                out[k] = u
                break
    return out


def fit_folder_spec(folder) -> tuple[ParamSpec, list[str]]:
    """The ParamSpec a fit folder's ``fit_config.json`` describes (free, ties, bounds,
    priors, defaults, periods and folds), so that its stored internal coordinates mean what
    they meant, and its ties as ``--tie`` strings (``"a=b"``, ``"a=1-b"``).

    Raises
    ------
    ValueError
        A missing or corrupt file, named.
    """
    spec = read_config(Path(folder) / CONFIG_FILE)["config"]["spec"]
    params = spec["params"]
    ties = [f"{t}={s}" if kind == "equal" else f"{t}=1-{s}"
            for t, (s, kind) in spec.get("ties", {}).items()]
    return ParamSpec(spec["free"], defaults={n: p["default"] for n, p in params.items()},
                     ties=ties, bounds={n: (p["lo"], p["hi"]) for n, p in params.items()},
                     priors={n: p["prior"] for n, p in params.items()},
                     periods=spec.get("periods"), folds=spec.get("folds")), ties


def posterior_draws(folder, spec: ParamSpec, draws: int,
                    rng: np.random.Generator) -> np.ndarray:
    """K draws (K, ndim) of a fit's posterior in ``spec``'s internal coordinates (module
    notes).

    Raises
    ------
    ValueError
        The folder holds no checkpoint, or an unreadable one (named).
    """
    draws = check_draws(draws)
    folder = Path(folder)
    try:
        fit_spec = fit_folder_spec(folder)[0]
    except ValueError as exc:
        raise ValueError(f"{folder}: cannot read the fit's parameters: {exc}") from None
    ckpt = FitFolder(folder).read_checkpoint()    # the one reader of checkpoint.h5
    if ckpt is None:
        raise ValueError(f"{folder}: no {CHECKPOINT_FILE} (the fit's posterior samples): plan "
                         f"from a finished `microcyl fit` folder, or from a preset")
    chains = [e["chain"] for e in ckpt["ensembles"]]
    samples = np.concatenate([c[c.shape[0] // 2:].reshape(-1, c.shape[-1]) for c in chains])
    if samples.shape[-1] != fit_spec.ndim:
        raise ValueError(f"{folder}: the checkpoint's chains have {samples.shape[-1]} "
                         f"parameters, the configuration {fit_spec.ndim}")
    pick = rng.choice(samples.shape[0], size=draws, replace=samples.shape[0] < draws)
    values = fit_spec.values(samples[np.sort(pick)])
    natural = np.stack([values[n] for n in spec.free], axis=-1)
    lo = np.array([spec.params[n].lo for n in spec.free])
    hi = np.array([spec.params[n].hi for n in spec.free])
    return np.clip(spec.to_internal(np.clip(natural, lo, hi)), -10.0, 10.0)
