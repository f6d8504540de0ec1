"""Pieces shared by the command-line verbs: fabric options, angle pairs, atomic writes."""

from __future__ import annotations

import argparse
import math
import os
import tempfile
from pathlib import Path

import brdf
from analysis.likelihood import KINDS
from analysis.measured import default_data_dir
from analysis.params import DEFAULT_FREE, DEFAULT_TIES

__all__ = ["add_fabric_options", "fabric_from_args", "parse_angle_pair", "check_writable_dir",
           "add_fit_options", "fit_kwargs", "split_ties", "data_dir",
           "add_cluster_options"]


def _on_off(value: str) -> bool:
    v = value.lower()
    if v in ("on", "true", "yes", "1"):
        return True
    if v in ("off", "false", "no", "0"):
        return False
    raise argparse.ArgumentTypeError(f"expected on or off, got {value!r}")


def add_fabric_options(parser: argparse.ArgumentParser) -> None:
    """Add the model's variant flags (MODEL.md toggles) to a sub-command parser."""
    g = parser.add_argument_group("model variants")
    g.add_argument("--masking", type=_on_off, default=True, metavar="on|off",
                   help="shadowing and masking M (default on)")
    g.add_argument("--reweighting", type=_on_off, default=True, metavar="on|off",
                   help="reweighting by visible length P and Q (default on)")
    g.add_argument("--tangent-samples", type=int, default=32, metavar="N",
                   help="samples per tangent curve (default 32)")
    g.add_argument("--tangent-sampling", default="midpoint",
                   choices=brdf.SAMPLING_METHODS, help="tangent curve rule (default midpoint)")
    g.add_argument("--transmission", default="half_angle", choices=brdf.TRANSMISSION_METHODS,
                   help="F_T variant (default half_angle)")
    g.add_argument("--gap", default="incident", choices=brdf.GAP_METHODS,
                   help="gap term c_gap of Q (default incident)")
    g.add_argument("--rotation", type=float, default=0.0, metavar="DEG",
                   help="fabric rotation about the normal, degrees (default 0)")


def add_fit_options(p: argparse.ArgumentParser) -> None:
    """Add the options of a fit (``microcyl fit`` and ``fit-batch``): spec and sampler."""
    p.add_argument("--free", default=None, metavar="NAMES",
                   help="comma-separated free parameters, or a TOML file (default "
                        f"{','.join(DEFAULT_FREE)})")
    p.add_argument("--spec", default=None, metavar="TOML",
                   help="TOML file with free, tie, [bounds], [prior], [start]")
    p.add_argument("--tie", action="append", default=None, metavar="A=B",
                   help="tie A to B (A=B or A=1-B); repeatable; 'none' for no tie (default "
                        f"{','.join(DEFAULT_TIES)} when --free is not given)")
    p.add_argument("--likelihood", choices=KINDS, default="gaussian")
    p.add_argument("--nu", type=float, default=4.0, help="Student-t degrees of freedom")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--max-steps", type=int, default=20000, metavar="N",
                   help="step limit per ensemble (default 20000)")
    p.add_argument("--ensembles", type=int, default=4, metavar="K")
    p.add_argument("--walkers", type=int, default=None, metavar="W",
                   help="walkers per ensemble (default 2 x ndim + 2)")
    p.add_argument("--check-every", type=int, default=50, metavar="N",
                   help="steps between convergence checks (default 50)")
    p.add_argument("--time-limit", type=float, default=None, metavar="SECONDS")


def add_cluster_options(p: argparse.ArgumentParser) -> None:
    """Add ``--workers N`` / ``--scheduler ADDRESS`` (the Dask cluster of a batch)."""
    g = p.add_mutually_exclusive_group()
    g.add_argument("--workers", type=int, default=None, metavar="N",
                   help="local Dask worker processes (default: one per core)")
    g.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on an existing Dask scheduler, e.g. tcp://10.0.0.5:8786")


def fit_kwargs(args: argparse.Namespace) -> dict:
    """The keyword arguments of :func:`analysis.fit.fit` from :func:`add_fit_options`."""
    return {"likelihood": args.likelihood, "nu": args.nu, "ensembles": args.ensembles,
            "walkers": args.walkers, "seed": args.seed, "max_steps": args.max_steps,
            "check_every": args.check_every, "time_limit": args.time_limit}


def split_ties(ties):
    """``--tie`` values (repeatable, each comma-separated; 'none' dropped), or None."""
    if ties is None:
        return None
    return [t for item in ties for t in item.split(",") if t.strip().lower() != "none"]


def fabric_from_args(name: str, args: argparse.Namespace) -> brdf.Fabric:
    """The preset ``name`` with the variant flags of ``add_fabric_options``."""
    return brdf.fabric(name, masking=args.masking, reweighting=args.reweighting,
                       tangent_samples=args.tangent_samples,
                       tangent_sampling=args.tangent_sampling,
                       transmission=args.transmission, gap=args.gap,
                       rotation=math.radians(args.rotation))


def parse_angle_pair(text: str) -> tuple[float, float]:
    """Parse ``THETA,PHI`` in degrees (argparse type)."""
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        theta, phi = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected THETA,PHI in degrees (e.g. 30,0), got {text!r}") from None
    if not (math.isfinite(theta) and math.isfinite(phi)):
        raise argparse.ArgumentTypeError(f"angles must be finite, got {text!r}")
    return theta, phi


def data_dir(arg=None) -> Path:
    """The measured-data folder of a verb: ``--data`` when given, else ``$MICROCYL_DATA``,
    else ``../shared/data`` from the current folder when it exists, else the one beside the
    source tree (:func:`analysis.measured.default_data_dir`)."""
    if arg:
        return Path(arg)
    if os.environ.get("MICROCYL_DATA"):
        return Path(os.environ["MICROCYL_DATA"])
    here = Path.cwd().parent / "shared" / "data"
    return here.resolve() if here.is_dir() else default_data_dir()


def check_writable_dir(path: Path) -> Path:
    """Create ``path`` if needed and check that files can be written in it.

    Raises
    ------
    OSError
        If the folder cannot be created or written, naming it.
    """
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path, prefix=".write-test-"):
            pass
    except OSError as exc:
        raise OSError(f"output folder {str(path)!r} is not writable: {exc.strerror or exc}") \
            from None
    return path
