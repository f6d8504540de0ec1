"""Pieces shared by the command-line verbs: fabric options and the FABRIC argument (resolved by
:func:`analysis.sources.resolve`), the progress and message flags, angle pairs, output checks."""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from pathlib import Path

import brdf
import gonio
import gonio.io
from analysis import sources
from analysis.families import MICROCYLINDER, family, model_names
from analysis.folderlock import missing_folders, remove_empty_folders
from analysis.lazy import lazy_module
from analysis.likelihood import KINDS
from analysis.measured import curet_sample, default_data_dir
from analysis.params import DEFAULT_FREE, DEFAULT_TIES

__all__ = ["add_fabric_options", "fabric_options", "fabric_from_args", "add_fabric_argument",
           "fabric_argument", "source_from_args", "add_quiet_options", "progress",
           "check_output_suffix", "parse_angle_pair", "check_writable_dir",
           "add_fit_options", "fit_kwargs", "split_ties", "data_dir",
           "add_cluster_options", "add_model_arguments", "start_model", "check_tangent_samples", "reader_options", "read_table",
           "MAX_TANGENT_SAMPLES", "add_engine_option", "ENGINE_CHOICES",
           "DEFAULT_ENGINE", "curet_sample_arg", "curet_samples_text"]

#: The fit's driver, on use (its sampler loads emcee: :mod:`analysis.lazy`).
driver = lazy_module("analysis.fit.driver")

#: Largest --tangent-samples (the default is 32): the model's own cap, whoever asks.
MAX_TANGENT_SAMPLES = brdf.MAX_TANGENT_SAMPLES


def _on_off(value: str) -> bool:
    v = value.lower()
    if v in ("on", "true", "yes", "1"):
        return True
    if v in ("off", "false", "no", "0"):
        return False
    raise argparse.ArgumentTypeError(f"expected on or off, got {value!r}")


def add_fabric_options(parser: argparse.ArgumentParser, rotation: bool = True) -> None:
    """Add the model's variant flags (MODEL.md toggles) to a sub-command parser. Only the
    flags given change a fabric (:func:`fabric_options`): a fit's or a file's own options
    stay otherwise. ``rotation=False`` leaves ``--rotation`` to the verb (``measure``'s
    turns the stage)."""
    g = parser.add_argument_group("model variants (default: the source's own, else the "
                                  "model's)")
    g.add_argument("--masking", type=_on_off, default=None, metavar="on|off",
                   help="shadowing and masking M (model default on)")
    g.add_argument("--reweighting", type=_on_off, default=None, metavar="on|off",
                   help="reweighting by visible length P and Q (model default on)")
    g.add_argument("--tangent-samples", type=int, default=None, metavar="N",
                   help="samples per tangent curve (model default 32)")
    g.add_argument("--tangent-sampling", default=None,
                   choices=brdf.SAMPLING_METHODS, help="tangent curve rule (model default midpoint)")
    g.add_argument("--transmission", default=None, choices=brdf.TRANSMISSION_METHODS,
                   help="F_T variant (model default half_angle)")
    g.add_argument("--gap", default=None, choices=brdf.GAP_METHODS,
                   help="gap term c_gap of Q (model default incident)")
    if rotation:
        g.add_argument("--rotation", type=float, default=None, metavar="DEG",
                       help="fabric rotation about the normal, degrees (model default 0)")


def fabric_options(args: argparse.Namespace) -> dict:
    """The variant options given by :func:`add_fabric_options`'s flags (rotation in
    radians), each checked; the flags not given are left out."""
    opts = {}
    for name in ("masking", "reweighting", "tangent_samples", "tangent_sampling",
                 "transmission", "gap"):
        value = getattr(args, name, None)
        if value is not None:
            opts[name] = value
    if "tangent_samples" in opts:
        check_tangent_samples(opts["tangent_samples"])
    rot = getattr(args, "rotation", None) if getattr(args, "fabric_rotation", True) else None
    if rot is not None:
        if not math.isfinite(rot):
            raise ValueError(f"--rotation must be a finite angle in degrees; got {rot}")
        opts["rotation"] = math.radians(rot)
    return opts


def add_fabric_argument(parser: argparse.ArgumentParser, *, tables: bool = False,
                        extra: str = "") -> None:
    """Add the FABRIC argument: positional, or as ``--fabric`` (one of the two); what it
    accepts is :func:`analysis.sources.accepted`."""
    text = sources.accepted(tables) + extra
    parser.add_argument("fabric", nargs="?", default=None, metavar="FABRIC", help=text)
    parser.add_argument("--fabric", dest="fabric_option", default=None, metavar="FABRIC",
                        help="FABRIC given as an option")


def fabric_argument(args: argparse.Namespace) -> str:
    """The FABRIC given, positional or ``--fabric`` (exactly one)."""
    given = [v for v in (args.fabric, args.fabric_option) if v is not None]
    if not given:
        raise ValueError(f"FABRIC is required (positional or --fabric): {sources.accepted()}")
    if len(given) > 1:
        raise ValueError(f"FABRIC given twice ({' and '.join(map(repr, given))}): give it "
                         f"once, positional or as --fabric")
    return given[0]


def source_from_args(text: str, args: argparse.Namespace, what: str = "FABRIC",
                     tables: bool = False) -> sources.Source:
    """:func:`analysis.sources.resolve` of ``text`` with the variant flags given
    (:func:`fabric_options`) applied."""
    return sources.resolve(text, what=what, tables=tables, options=fabric_options(args))


def add_quiet_options(parser: argparse.ArgumentParser) -> None:
    """Add the flags of every long verb: ``--no-progress`` (no progress bar) and
    ``-q/--quiet`` (no progress bar and no messages on stderr; warnings and errors still)."""
    parser.add_argument("--no-progress", action="store_true",
                        help="no progress bar (shown on stderr otherwise, terminal or not)")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress bar and no messages on stderr (warnings and "
                             "errors still)")


#: The renderers ``--engine`` names (``render`` and ``report``).
ENGINE_CHOICES = ("auto", "builtin", "mitsuba")
#: ``--engine``'s default, the same for every verb that renders.
DEFAULT_ENGINE = "builtin"


class _DeprecatedAlias(argparse.Action):
    """An old spelling of an option, hidden from --help: sets the new option's value and
    says on stderr which name to use."""

    def __init__(self, option_strings, dest, new, **kw):
        self.new = new
        super().__init__(option_strings, dest, **kw)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"microcyl: {option_string} is deprecated; use {self.new}", file=sys.stderr)
        setattr(namespace, self.dest, values)


def add_engine_option(parser: argparse.ArgumentParser, what: str = "the render",
                      deprecated: tuple[str, ...] = ()) -> None:
    """``--engine auto|builtin|mitsuba`` (default :data:`DEFAULT_ENGINE`): one name and one
    default for every verb that renders; ``deprecated`` old spellings still work, hidden."""
    # no argparse choices: each verb refuses another name in its own one line
    parser.add_argument("--engine", default=DEFAULT_ENGINE, metavar="ENGINE",
                        help=f"the engine of {what}: builtin (direct light, NumPy), mitsuba "
                             f"(Mitsuba 3 path tracing) or auto (mitsuba where it runs in "
                             f"llvm_ad_rgb and the model is a microcylinder fabric, else "
                             f"builtin) ({DEFAULT_ENGINE})")
    for old in deprecated:
        parser.add_argument(old, dest="engine", new="--engine",
                            action=_DeprecatedAlias, help=argparse.SUPPRESS)


def curet_sample_arg(text: str) -> int:
    """``--sample``'s type: a CUReT sample number or a CUReT dataset's name
    (``curet_07_velvet``: :func:`analysis.measured.curet_sample`)."""
    try:
        return curet_sample(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def curet_samples_text(text: str | None) -> str | None:
    """``fit-batch --sample``: ``all`` or comma-separated numbers, the CUReT datasets' names
    (``curet_07_velvet``) turned into their numbers; anything else passed on as given, for
    :func:`analysis.batch.jobs.parse_samples` to refuse.

    Examples
    --------
    >>> curet_samples_text("2,curet_07_velvet")
    '2,7'
    """
    if text is None or text.strip().lower() == "all":
        return text
    out = []
    for item in text.split(","):
        try:
            out.append(str(curet_sample(item)) if item.strip() else item)
        except ValueError:
            out.append(item)
    return ",".join(out)


def progress(args: argparse.Namespace) -> bool:
    """Whether a progress bar is shown: neither ``--no-progress`` nor ``-q`` given."""
    return not (getattr(args, "no_progress", False) or getattr(args, "quiet", False))


def check_output_suffix(path, suffixes, option: str = "-o") -> Path:
    """``path`` when it ends in one of ``suffixes`` and its folder exists (before any
    work); a ValueError or OSError naming ``option`` otherwise."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise ValueError(f"{option} {str(path)!r}: must end in {', '.join(suffixes)}")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise OSError(f"{option} {str(path)!r}: output folder {str(parent)!r} does not exist")
    if path.is_dir():
        raise OSError(f"{option} {str(path)!r}: is a folder")
    return path


def add_fit_options(p: argparse.ArgumentParser) -> None:
    """Add the options of a fit (``microcyl fit`` and ``fit-batch``): spec and sampler."""
    p.add_argument("--free", default=None, metavar="NAMES",
                   help="comma-separated free parameters, or a TOML file (default "
                        f"{','.join(DEFAULT_FREE)}: the albedo stays at the preset's, on RGB "
                        "tables too, as freeing both threads' is slower and often "
                        "confounded (docs: guide/fitting, 'Parameters, free and tied'); "
                        "add albedo1 (albedo2) to fit the table's colour; "
                        "`microcyl fit --suggest` tells which the table informs)")
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


def fit_kwargs(args: argparse.Namespace) -> dict:
    """The keyword arguments of :func:`analysis.fit.fit` from :func:`add_fit_options`, each
    checked by name before any work (:meth:`analysis.fit.FitOptions.check`)."""
    kw = {"likelihood": args.likelihood, "nu": args.nu, "ensembles": args.ensembles,
          "walkers": args.walkers, "seed": args.seed, "max_steps": args.max_steps,
          "check_every": args.check_every, "time_limit": args.time_limit}
    driver.FitOptions(**kw).check()
    return kw


def split_ties(ties):
    """``--tie`` values (repeatable, each comma-separated; 'none' dropped), or None."""
    if ties is None:
        return None
    return [t for item in ties for t in item.split(",") if t.strip().lower() != "none"]


def reader_options(path, **options) -> dict:
    """The reader options given (not None) for ``path``, each checked against its format:
    ``--sample`` for a CUReT abrdf.dat, ``--step`` for an RGL .bsdf, ``--stride`` for a MERL
    .binary; another is refused by name (:func:`gonio.io.check_read_options`). The table's
    size is not estimated here: :func:`gonio.read` refuses a table whose reading would exceed
    the memory limit before parsing it, and a fit, which must know the size before other
    work, calls :func:`analysis.fit.workflow.check_fit_size` (each estimate counts a CSV's
    lines once)."""
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
    return given


def read_table(path, **options):
    """``gonio.read(path)`` with the reader options that apply (:func:`reader_options`)."""
    return gonio.read(path, **reader_options(path, **options))


def fabric_from_args(name: str, args: argparse.Namespace) -> brdf.Fabric:
    """The preset ``name`` (:func:`brdf.check_preset`) with the variant flags given."""
    return brdf.fabric(brdf.check_preset(name), **fabric_options(args))


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


def add_model_arguments(p) -> None:
    """``--model`` and ``--fabric`` of ``fit`` and ``fit-batch`` (checked by
    :func:`start_model`)."""
    p.add_argument("--model", default=MICROCYLINDER, choices=model_names(),
                   help="the model fitted (default microcylinder); a baseline model "
                        "starts from its parameters' typical values and takes no --fabric")
    p.add_argument("--fabric", default=None, metavar="PRESET",
                   help=f"preset giving fixed values and the start (required for the "
                        f"microcylinder, refused for another model): "
                        f"{', '.join(brdf.PRESETS)}")


def start_model(args):
    """The model a fit starts from: for a model with presets (the microcylinder) the preset
    ``--fabric`` with the variant flags, any other model at its typical values; one line for
    ``--fabric`` (or a variant flag) with a model without presets, or no ``--fabric`` for one
    with."""
    fam = family(args.model)
    if fam.presets:
        if args.fabric is None:
            raise ValueError(f"--fabric PRESET is required for --model {fam.name} (the "
                             f"preset gives the fixed values and the start): "
                             f"{', '.join(fam.presets)}")
        return fam.start(fam.check_preset(args.fabric), fabric_options(args))
    if args.fabric is not None:
        with_presets = " / ".join(m for m in model_names() if family(m).presets)
        raise ValueError(f"--fabric applies to --model {with_presets} only; --model "
                         f"{fam.name} starts from its own typical values (drop --fabric)")
    given = fabric_options(args)
    if given:
        raise ValueError(f"--model {fam.name} takes no fabric variant option "
                         f"({', '.join(sorted(given))}): they belong to the microcylinder")
    return fam.start()
