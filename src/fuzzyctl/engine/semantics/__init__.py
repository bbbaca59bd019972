"""What the words of IEC 61131-7 (and fuzzylite's and MATLAB's additions) mean: membership
formulas, operators, function-term expressions, the C library's functions as Java and C compute them."""
