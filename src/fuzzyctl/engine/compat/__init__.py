"""jFuzzyLogic 3.3 reproduced (the ``compat="jfuzzylogic"`` profile)."""
