"""Lowering: a model's function block -> a :class:`~fuzzyctl.engine.plan.Plan`, every
semantic decision the standard leaves open made once."""
