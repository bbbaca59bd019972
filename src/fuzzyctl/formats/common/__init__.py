"""What several formats share: numbers, names and diagnostics (:mod:`.basics`), arithmetic
expressions (:mod:`.expr`), the term shapes of MATLAB and fuzzylite (:mod:`.terms`), and
how a model is adapted to what FIS and FLL can say (:mod:`.adapt`)."""
