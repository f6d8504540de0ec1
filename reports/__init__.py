"""reports: plots, renders, HTML reports and the ``microcyl`` command line."""

__all__ = []
