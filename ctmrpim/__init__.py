"""Adaptive CTM-RPIM: Cartesian transformation method integration, radial point interpolation
shape functions and alpha-shape boundary tracking (see the paper in the project's reference)."""

__version__ = "0.1.0"
