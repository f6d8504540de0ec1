"""gonio package of microcyl."""

__all__ = []
