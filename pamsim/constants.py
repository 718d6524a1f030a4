"""Unit conversions used at the edges of the model (SI inside)."""

PA_PER_BAR = 1.0e5
"""Pascals in one bar; the paper's polynomials take gauge pressure in bar."""
