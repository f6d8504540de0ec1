"""Pieces shared by the command-line verbs: fabric options and sources, angle pairs, atomic
writes."""

from __future__ import annotations

import argparse
import math
import os
import tempfile
from pathlib import Path

import brdf
import gonio
import gonio.io
import gonio.tablesize
import gonio.rgl
from gonio.statefields import load_json
from analysis.folderlock import missing_folders, remove_empty_folders
from analysis.likelihood import KINDS
from analysis.measured import default_data_dir
from analysis.params import DEFAULT_FREE, DEFAULT_TIES

__all__ = ["add_fabric_options", "fabric_from_args", "fabric_source", "parse_angle_pair", "check_writable_dir",
           "add_fit_options", "fit_kwargs", "split_ties", "data_dir",
           "add_cluster_options", "check_tangent_samples", "reader_options", "read_table",
           "table_estimate",
           "MAX_TANGENT_SAMPLES", "MAX_ENSEMBLES"]

#: Largest --tangent-samples (the default is 32): the model's own cap, whoever asks.
MAX_TANGENT_SAMPLES = brdf.MAX_TANGENT_SAMPLES
#: Largest --ensembles: R-hat needs a few; each is a group of the one checkpoint.
MAX_ENSEMBLES = 64


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
                        f"{','.join(DEFAULT_FREE)}: the albedo stays at the preset's, on RGB "
                        "tables too, as freeing both threads' is slower and often "
                        "confounded (README); add albedo1 (albedo2) to fit the table's "
                        "colour; `microcyl fit --suggest` tells which the table informs)")
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


def check_tangent_samples(n) -> None:
    """``--tangent-samples``: an integer in [1, MAX_TANGENT_SAMPLES]."""
    if not 1 <= n <= MAX_TANGENT_SAMPLES:
        raise ValueError(f"--tangent-samples must be an integer in 1..{MAX_TANGENT_SAMPLES}; "
                         f"got {n}")


def check_fit_options(args: argparse.Namespace) -> None:
    """The options of :func:`add_fit_options`, each checked by name before any work."""
    checks = [
        (args.seed >= 0, "--seed", args.seed, "a non-negative integer"),
        (2 <= args.ensembles <= MAX_ENSEMBLES, "--ensembles", args.ensembles,
         f"an integer in 2..{MAX_ENSEMBLES} (R-hat is computed across them)"),
        (args.walkers is None or args.walkers >= 2, "--walkers", args.walkers,
         "an even integer >= 2 x the number of free parameters"),
        (args.max_steps >= 1, "--max-steps", args.max_steps, "a positive integer"),
        (args.check_every >= 1, "--check-every", args.check_every, "a positive integer"),
        (args.time_limit is None or (math.isfinite(args.time_limit) and args.time_limit > 0),
         "--time-limit", args.time_limit, "a positive finite number of seconds"),
        (math.isfinite(args.nu) and args.nu > 0, "--nu", args.nu,
         "a positive finite number of degrees of freedom"),
    ]
    for ok, option, value, allowed in checks:
        if not ok:
            raise ValueError(f"{option} must be {allowed}; got {value}")


def fit_kwargs(args: argparse.Namespace) -> dict:
    """The keyword arguments of :func:`analysis.fit.fit` from :func:`add_fit_options`
    (checked first: :func:`check_fit_options`)."""
    check_fit_options(args)
    return {"likelihood": args.likelihood, "nu": args.nu, "ensembles": args.ensembles,
            "walkers": args.walkers, "seed": args.seed, "max_steps": args.max_steps,
            "check_every": args.check_every, "time_limit": args.time_limit}


def split_ties(ties):
    """``--tie`` values (repeatable, each comma-separated; 'none' dropped), or None."""
    if ties is None:
        return None
    return [t for item in ties for t in item.split(",") if t.strip().lower() != "none"]


def reader_options(path, **options) -> dict:
    """The reader options given (not None) for ``path``, each checked against its format:
    ``--sample`` for a CUReT abrdf.dat, ``--step`` for an RGL .bsdf, ``--stride`` for a MERL
    .binary; another is refused by name (:func:`gonio.io.check_read_options`). A table whose
    reading would exceed the memory limit, estimated from the file's size and header (its
    line count, an OpenEXR or RGL header, the MERL stride: :func:`gonio.tablesize.check_table`),
    is refused with its estimate, before anything is parsed."""
    path = Path(path)
    given = {k: v for k, v in options.items() if v is not None}
    if given:
        gonio.io.check_read_options(path, given, as_flags=True)
    if "stride" in given and given["stride"] < 1:
        raise ValueError(f"--stride must be a positive integer; got {given['stride']}")
    if "sample" in given and not 1 <= given["sample"] <= 61:
        raise ValueError(f"--sample must be a CUReT sample number in 1..61; got "
                         f"{given['sample']}")
    if "step" in given:
        step = given["step"]
        if not (math.isfinite(step) and 0 < step <= 90):
            raise ValueError(f"--step must be in (0, 90] degrees; got {step}")
    table_estimate(path, **given)
    return given


def table_estimate(path, **options):
    """The size of the table ``path`` (:class:`gonio.tablesize.Estimate`), refused when its
    reading would exceed the memory limit (:func:`gonio.tablesize.check_table`); None when
    it cannot be told (the reader then says what is wrong)."""
    path = Path(path)
    kind = gonio.io.table_kind(path, quiet=True)
    if kind is None or not path.is_file():
        return None
    return gonio.tablesize.check_table(path, kind, **options)


def read_table(path, **options):
    """``gonio.read(path)`` with the reader options that apply (:func:`reader_options`)."""
    return gonio.read(path, **reader_options(path, **options))


def fabric_from_args(name: str, args: argparse.Namespace) -> brdf.Fabric:
    """The preset ``name`` with the variant flags of ``add_fabric_options``."""
    check_tangent_samples(args.tangent_samples)
    return brdf.fabric(name, masking=args.masking, reweighting=args.reweighting,
                       tangent_samples=args.tangent_samples,
                       tangent_sampling=args.tangent_sampling,
                       transmission=args.transmission, gap=args.gap,
                       rotation=math.radians(args.rotation))


def fabric_source(text: str, what: str = "FABRIC") -> brdf.Fabric:
    """The fabric that a FABRIC argument names: a preset, a fit, or an exported dictionary.

    Parameters
    ----------
    text : str
        A name in :data:`brdf.PRESETS`; a `microcyl fit` output folder (its posterior
        medians, :func:`analysis.fit.median_fabric`: the fabric that ``microcyl export``
        writes, without the fit's overall ``scale``, which only calibrates relative tables);
        or a ``.json`` file of the Mitsuba plugin's dictionary (``microcyl export``'s, or one
        written by hand: :func:`reports.mitsuba.fabric_from_dict`).
    what : str
        The argument's name in error messages.

    Raises
    ------
    ValueError
        One line naming the argument and the value: an unknown preset and no such file or
        folder, a folder that is no fit, an unreadable or invalid dictionary.

    Examples
    --------
    >>> fabric_source("velvet").name
    'velvet'
    """
    if text in brdf.PRESETS:
        return brdf.fabric(text)
    path = Path(text)
    if path.is_dir():
        from analysis.fit.medians import median_fabric
        try:
            return median_fabric(path).fabric
        except ValueError as exc:
            raise ValueError(f"{what} {text!r}: not a fit folder: {exc}") from None
    if path.is_file() and path.suffix.lower() == ".json":
        from reports.mitsuba import fabric_from_dict    # needs no Mitsuba
        try:
            doc = load_json(path, "fabric dictionary")   # invalid or nested: one line
        except ValueError as exc:
            raise ValueError(f"{what} {text!r}: unreadable JSON "
                             f"({str(exc).removeprefix(f'{path}: ')})") from None
        if not isinstance(doc, dict) or doc.get("type", "microcylinder") != "microcylinder":
            kind = doc.get("type") if isinstance(doc, dict) else type(doc).__name__
            raise ValueError(f"{what} {text!r}: must hold a microcylinder plugin dictionary "
                             f"(a JSON object of type 'microcylinder'); got {kind!r}")
        try:
            return fabric_from_dict(doc)
        except (ValueError, TypeError) as exc:
            raise ValueError(f"{what} {text!r}: {exc}") from None
    raise ValueError(f"{what} {text!r}: not a preset ({', '.join(brdf.PRESETS)}), a fit "
                     f"folder or a .json dictionary of `microcyl export`")


def parse_angle_pair(text: str) -> tuple[float, float]:
    """Parse ``THETA,PHI`` in degrees (argparse type): theta in [0, 90], phi in [-360, 360]."""
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
    if not (0 <= theta <= 90 and -360 <= phi <= 360):
        raise argparse.ArgumentTypeError(
            f"THETA must be in [0, 90] degrees (from the normal, the upper hemisphere) and PHI "
            f"in [-360, 360]; got {text!r}")
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
    """Check that ``path`` can be created (when missing) and written in, leaving nothing
    behind: a folder created for the check is removed again, so a run refused later leaves
    no new folder (its writer creates it when it starts).

    Raises
    ------
    OSError
        If the folder cannot be created or written, naming it.
    """
    path = Path(path)
    created = missing_folders(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path, prefix=".write-test-"):
            pass
    except OSError as exc:
        raise OSError(f"output folder {str(path)!r} is not writable: {exc.strerror or exc}") \
            from None
    finally:
        remove_empty_folders(created)
    return path
