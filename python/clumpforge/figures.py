"""Figures (matplotlib) of clumpforge results."""
