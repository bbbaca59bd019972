"""The readable reference: the scalar interpreter and the exact defuzzifiers every generated
evaluator is tested against."""
