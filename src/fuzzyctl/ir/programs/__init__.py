"""Programs built from a plan: the PLC block, the evaluator of ``compile()``, the rule table."""
