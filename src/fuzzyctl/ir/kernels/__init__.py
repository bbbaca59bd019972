"""Hand-written kernels the rendered evaluators call (each names its IR twin and has a
benchmark row)."""
