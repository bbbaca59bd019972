"""Registries: one entry per kind, the one place that says what a kind is.

A new kind is one entry here; every consumer (the readers and writers of each format, the
engine's evaluators and lowering, the code generators, the tuner, the conformance statement,
the studio) reads the entry instead of keeping its own table or comparing kind names.

* :mod:`fuzzyctl.kinds.shapes` - parametric membership-function shapes;
* ``methods`` - defuzzification methods;
* ``norms`` - AND/OR operators, activation and accumulation methods (their formulas are the
  operators table, :mod:`fuzzyctl.engine.semantics.operators`);
* ``targets`` - code-generation targets (a capabilities record each).

This package sits at the bottom of the stack, next to :mod:`fuzzyctl.model`: it imports
the standard library and numpy, nothing else of fuzzyctl.
"""
