"""Renderers: the IR printed as Python, numpy, C99, Structured Text and PLCopen XML."""
