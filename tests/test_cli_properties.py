"""Property tests (hypothesis) of the command line's parsers and up-front checks: random valid
and invalid argument lists for the verbs of ``reports.cli.build_parser``. The rule: argparse
refuses with SystemExit 2 and one line, or the verb's checks (everything a verb does before
its work) pass, or they raise ValueError/TypeError/OSError naming the option or parameter.
No other exception escapes, and no check starts the work."""

import contextlib
import io
import math
import re

import hypothesis.strategies as st
import pytest
from hypothesis import HealthCheck, given, settings

import brdf
from analysis.paramnames import PARAM_NAMES
from reports.cli import options as cliutil
from reports.cli import fit as cmd_fit
from analysis.measurejob import measure_estimate
from reports.cli import model as cmd_model
from reports.cli import build_parser
from reports.cli.instrument import instrument_from_args

PARSER = build_parser()
SETTINGS = settings(max_examples=700, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])
ALLOWED = (ValueError, TypeError, OSError)
NAMED = re.compile(r"--[a-z]|\btie\b|free|parameter|fabric|rotation|tangent|step|spec|"
                   r"stride|sample|bounds|prior|start|seed|walkers|ensembles")

NUMBERS = st.one_of(
    st.integers(-10 ** 13, 10 ** 13).map(str),
    st.sampled_from(["0", "1", "2", "3", "-1", "1e12", "1e308", "-1e308", "nan", "inf",
                     "-inf", "0.5", "90", "200", "1000000", "100000"]),
    st.floats(-1e6, 1e6).map(repr))
JUNK = st.text(alphabet="abcdefz019_=,.-: ", max_size=10)
ANGLES = st.one_of(st.builds(lambda a, b: f"{a},{b}", NUMBERS, NUMBERS), JUNK)
NAMES = st.sampled_from(PARAM_NAMES + ("albedo1", "albedo2"))
FREE = st.one_of(st.lists(NAMES, min_size=1, max_size=4).map(",".join), JUNK,
                 st.just("none"))
TIES = st.one_of(st.builds(lambda a, c, b: f"{a}={c}{b}", NAMES, st.sampled_from(["", "1-"]),
                           NAMES), JUNK, st.just("none"))
VALUE = st.one_of(NUMBERS, JUNK)
TABLES = st.sampled_from(["t.csv", "t.exr", "felt.bsdf", "abrdf.dat", "m.binary", "x.txt"])
FABRICS = st.sampled_from(list(brdf.PRESETS) + ["denim", ""])
ON_OFF = st.sampled_from(["on", "off", "maybe", "1", "yes"])

FABRIC_OPTS = {"--masking": ON_OFF, "--reweighting": ON_OFF, "--tangent-samples": NUMBERS,
               "--tangent-sampling": st.sampled_from(["midpoint", "control_points", "x"]),
               "--rotation": NUMBERS}
FIT_OPTS = {"--free": FREE, "--tie": TIES, "--seed": NUMBERS, "--max-steps": NUMBERS,
            "--ensembles": NUMBERS, "--walkers": NUMBERS, "--check-every": NUMBERS,
            "--time-limit": NUMBERS, "--nu": NUMBERS, "--sample": NUMBERS,
            "--likelihood": st.sampled_from(["gaussian", "relative", "student-t", "x"]),
            **FABRIC_OPTS}
MEASURE_OPTS = {"--geometry": st.one_of(
                    st.builds(lambda k, a: f"{k}:{a}", st.sampled_from(
                        ["full", "rus", "merl", "plane:warp", "full:10:10:5"]), NUMBERS), JUNK),
                "--snr": NUMBERS, "--floor": NUMBERS, "--cone-source": NUMBERS,
                "--cone-detector": NUMBERS, "--cone-rings": NUMBERS,
                "--cone-azimuths": NUMBERS, "--max-theta": NUMBERS,
                "--min-separation": NUMBERS, "--seed": NUMBERS, "--rotation": NUMBERS,
                "--tangent-samples": NUMBERS,
                "--masking": st.sampled_from(["on", "off", "x"])}
READ_OPTS = {"--sample": NUMBERS, "--step": NUMBERS, "--stride": NUMBERS}


def _options(table: dict):
    pairs = st.lists(st.sampled_from(sorted(table)).flatmap(
        lambda k: table[k].map(lambda v: [k, v])), max_size=5)
    return pairs.map(lambda ps: [x for p in ps for x in p])


def _parse(argv):
    """The Namespace, or None after checking argparse's refusal: status 2, one line."""
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            return PARSER.parse_args(argv)
    except SystemExit as exc:
        assert exc.code == 2, (argv, exc.code)
        lines = err.getvalue().strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("microcyl"), (argv, lines)
        return None


def _checked(argv, checks):
    """Parse ``argv``; run ``checks(ns)``; only the allowed exceptions, naming something."""
    ns = _parse(argv)
    if ns is None:
        return
    try:
        checks(ns)
    except ALLOWED as exc:
        msg = str(exc)
        assert msg and "\n" not in msg.strip() and NAMED.search(msg), (argv, msg)


def _fit_checks(ns):
    """What ``microcyl fit`` checks before reading the table (cmd_fit.run's first lines)."""
    if ns.fabric not in brdf.PRESETS:
        raise ValueError(f"unknown fabric {ns.fabric!r}")
    cliutil.fit_kwargs(ns)
    fab = cliutil.fabric_from_args(ns.fabric, ns)
    cmd_fit._spec_from_args(ns, fab)
    cliutil.reader_options(ns.table, sample=ns.sample)


@SETTINGS
@given(TABLES, FABRICS, _options(FIT_OPTS))
def test_fit_arguments(table, fabric, opts):
    _checked(["fit", table, "--fabric", fabric, "-o", "out", *opts], _fit_checks)


def _measure_checks(ns):
    cliutil.fabric_options(ns)
    if not math.isfinite(ns.rotation):
        raise ValueError("--rotation must be finite")
    if ns.seed is not None and ns.seed < 0:
        raise ValueError("--seed must be >= 0")
    inst = instrument_from_args(ns)
    fab = cliutil.source_from_args(cliutil.fabric_argument(ns), ns).brdf
    measure_estimate(ns.geometry, inst, fab)


@SETTINGS
@given(FABRICS, _options(MEASURE_OPTS))
def test_measure_arguments(fabric, opts):
    _checked(["measure", fabric, "-o", "m.exr", *opts], _measure_checks)


@SETTINGS
@given(st.sampled_from(["info", "convert"]), TABLES, _options(READ_OPTS))
def test_table_reader_arguments(verb, table, opts):
    argv = [verb, table, *(["o.exr"] if verb == "convert" else []), *opts]
    _checked(argv, lambda ns: cliutil.reader_options(
        getattr(ns, "input", None) or ns.file, sample=ns.sample, step=ns.step,
        stride=ns.stride))


@settings(max_examples=500, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(FABRICS, ANGLES, ANGLES, _options(FABRIC_OPTS))
def test_eval_runs_or_names_what_is_wrong(fabric, wi, wo, opts):
    """``microcyl eval`` is cheap (one pair): run it whole."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        _checked(["eval", fabric, "--wi", wi, "--wo", wo, *opts], cmd_model.run_eval)


@SETTINGS
@given(st.sampled_from(["render", "fit-batch", "report", "energy", "sanity"]),
       st.lists(st.one_of(st.sampled_from(
           ["--workers", "--spp", "--width", "--exposure", "--seed", "--fabric", "--quality",
            "--ensembles", "--tie", "-o"]), VALUE), max_size=6))
def test_other_verbs_parse_or_refuse_in_one_line(verb, rest):
    _parse([verb, *rest])


@pytest.mark.parametrize("argv, option", [
    (["fit", "t.csv", "--fabric", "velvet", "-o", "o", "--seed", "-1"], "--seed"),
    (["fit", "t.csv", "--fabric", "velvet", "-o", "o", "--walkers", "3"], "--walkers"),
    (["fit", "t.csv", "--fabric", "velvet", "-o", "o", "--time-limit", "nan"], "--time-limit"),
    (["fit", "t.csv", "--fabric", "velvet", "-o", "o", "--ensembles", "100000"], "--ensembles"),
    (["fit", "t.csv", "--fabric", "velvet", "-o", "o", "--sample", "5"], "--sample"),
    (["fit", "t.csv", "--fabric", "velvet", "-o", "o", "--free", "eta1,eta2", "--tie",
      "eta2=eta1"], "tie eta2=eta1"),
])
def test_known_bad_fit_arguments_name_their_option(argv, option):
    ns = _parse(argv)
    try:
        _fit_checks(ns)
        if ns.walkers is not None:      # the driver checks walkers against the free set
            from analysis.fit.driver import FitOptions
            FitOptions(walkers=ns.walkers).resolve(8)
    except ValueError as exc:
        assert option in str(exc)
    else:
        pytest.fail(f"{argv} accepted")
