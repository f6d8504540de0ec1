"""brdf package of microcyl."""

__all__ = []
