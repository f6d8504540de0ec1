"""analysis package of microcyl."""

__all__ = []
