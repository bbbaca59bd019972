"""IR builders: rules, term formulas, piecewise-linear and smooth defuzzification, written once."""
