// Rule-effectiveness bars (manual 6.7) as the Siemens block computes them (manual 1.4):
// when the accumulation adds the degrees of the rules concluding one output term (ACCU
// NSUM or SUM: "the influences on a particular linguistic value of the output variable
// resulting from various rules are added together"; BSUM adds up to 1), the bars of those
// rules are stacked on the term's singleton, so the height of a stack is the weight the
// term gets in the centre of gravity.  Under MAX (and the other norms) the largest counts:
// the bars overlay.

const ADDING = new Set(["NSUM", "SUM", "BSUM"]);

/** The accumulation of ``output`` in function block ``b`` (model JSON): its DEFUZZIFY
 * block's ACCU (fuzzylite), else the ACCU of the first rule block concluding on it, else
 * MAX (IEC default). */
export function accumulation(b, output) {
  const d = b.defuzzify.find((x) => x.variable === output);
  if (d && d.accu) return d.accu;
  const rb = b.rule_blocks.find((r) => r.rules.some((rule) => rule.conclusions.some((c) => c.variable === output)));
  return (rb && rb.accu) || "MAX";
}

/** Whether the bars of ``output`` stack (the degrees add). */
export function stacks(b, output) {
  return ADDING.has(accumulation(b, output));
}

/** The base of each bar: 0 when they overlay, else the sum of the bars drawn before it at
 * the same abscissa. */
export function bases(xs, ys, stacked) {
  const top = new Map();
  return xs.map((x, i) => {
    if (!stacked) return 0;
    const base = top.get(x) || 0;
    top.set(x, base + ys[i]);
    return base;
  });
}
