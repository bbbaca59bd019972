"""Imports every command module so that each registers its commands on the app."""
from fuzzyctl.cli import blocks  # noqa: F401  (fuzzyctl blocks ...)
from fuzzyctl.cli import lang  # noqa: F401  (check, fmt)
