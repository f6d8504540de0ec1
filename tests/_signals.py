"""Signals for the CLI subprocesses that tests interrupt."""

import signal


def default_sigint():
    """``preexec_fn`` for a CLI subprocess that a test interrupts: SIGINT at its default, as
    a terminal gives it. (A suite run as a background job inherits SIGINT ignored, and an
    ignored SIGINT stays ignored across exec, so Ctrl-C would never reach the command.)"""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
