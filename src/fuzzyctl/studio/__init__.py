"""The studio: a browser configuration tool for fuzzy knowledge bases, after the Siemens
"Configuration Fuzzy Control" tool (manual chapters 4-6): edit inputs, outputs and rules,
analyse off line (3D/4D display, curve recorder with test signals or a simulated process,
explanations), monitor and download on line to ``fuzzyctl serve``.

``fuzzyctl studio [FILE]`` starts it (docs/studio.md); :func:`create_app` builds the
FastAPI application for a project directory.
"""

from fuzzyctl.studio.app import create_app

__all__ = ["create_app"]
