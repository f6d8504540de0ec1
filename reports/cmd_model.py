"""Verbs about the model itself: ``fabrics``, ``eval``, ``report``."""

from __future__ import annotations


def register(sub):
    """Add this module's verbs to the ``microcyl`` sub-parsers."""
