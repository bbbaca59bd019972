"""PLC fuzzy function blocks as the PLCs run them, parameter for parameter.

* :mod:`fuzzyctl.blocks.siemens`: Siemens S7 FUZZY (FB30) with FUZZY_AI / FUZZY_AO.
* :mod:`fuzzyctl.blocks.schneider`: Schneider/Telemecanique XFUZ (OFB-FUZZY).
* :mod:`fuzzyctl.blocks.task`: a cyclic task that calls blocks at a fixed period.

docs/blocks.md has the parameter tables and the readings of the manuals."""
