// Rules as the editors see them: a rule in the model's JSON form, read as cells of a table
// (one term per input and per output, each input term possibly negated) when it is that
// simple, else as text; helpers shared by the table, the matrix and the text editor.
import { fb, inputs, outputs } from "./state.js";

/** The IF part as cells ``{ins: {input: term}, neg: {input: true}}``, or null when a
 * table cannot show it (OR, parentheses, hedges, an input twice, a degree condition).  An
 * empty condition gives empty ``ins`` (a rule without an IF part). */
export function conditionCells(rule) {
  const ins = {};
  const neg = {};
  const inputNames = new Set(inputs().map((v) => v.name));
  const literal = (c) => (c.type === "not" && c.operand.type === "is" ? { ...c.operand, negated: !c.operand.negated } : c);
  const plain = (c) => c.type === "is" && !(c.hedges && c.hedges.length) && inputNames.has(c.variable) && !(c.variable in ins);
  const cond = rule.condition;
  const parts = !cond ? [] : cond.type === "and" ? cond.operands : [cond];
  for (const raw of parts) {
    const c = literal(raw);
    if (!plain(c)) return null;
    ins[c.variable] = c.term;
    if (c.negated) neg[c.variable] = true;
  }
  return { ins, neg };
}

/** The THEN part as cells ``{outs: {output: term}}``, or null (a WITH weight, a hedge,
 * an output twice, a bare variable). */
export function conclusionCells(rule) {
  const outs = {};
  const outputNames = new Set(outputs().map((v) => v.name));
  for (const c of rule.conclusions) {
    if (c.term === null || (c.weight !== null && c.weight !== undefined) || (c.hedges && c.hedges.length) || !outputNames.has(c.variable) || c.variable in outs) return null;
    outs[c.variable] = c.term;
  }
  return { outs };
}

/** A rule as cells ``{ins, neg, outs}``, or null when either part needs text or the rule
 * has a rule weight (MATLAB / fuzzylite). */
export function cells(rule) {
  if (rule.weight !== null && rule.weight !== undefined) return null;
  const c = conditionCells(rule);
  const o = conclusionCells(rule);
  return c && o ? { ...c, ...o } : null;
}

/** Write IF cells back into ``rule`` (inputs in declaration order). */
export function setCondition(rule, view) {
  const parts = inputs()
    .filter((v) => view.ins[v.name])
    .map((v) => ({ type: "is", variable: v.name, term: view.ins[v.name], negated: !!(view.neg && view.neg[v.name]), hedges: [] }));
  rule.condition = parts.length === 0 ? null : parts.length === 1 ? parts[0] : { type: "and", operands: parts };
}

/** Write THEN cells back into ``rule`` (outputs in declaration order). */
export function setConclusions(rule, view) {
  rule.conclusions = outputs()
    .filter((v) => view.outs[v.name])
    .map((v) => ({ variable: v.name, term: view.outs[v.name], weight: null, hedges: [] }));
}

/** Write table cells back into ``rule``. */
export function fromCells(rule, view) {
  setCondition(rule, view);
  setConclusions(rule, view);
}

/** A rule is part of the knowledge base once it has a THEN part; without an IF part it acts
 * with degree 1 (S7 manual 1.5: "as if the conditions of the IF part were fully
 * fulfilled").  An IF part alone has no influence. */
export function complete(rule) {
  return rule.conclusions.length > 0;
}

/** The name FCL gives the always-1 input of the rules without an IF part (fcl/no_if.py:
 * ``ALWAYS``, or ``ALWAYS_2``... when a name of the function block takes it). */
export function alwaysName() {
  const b = fb();
  const taken = new Set([b.name || "", ...b.variables.map((v) => v.name), ...b.rule_blocks.map((r) => r.name || "")].map((n) => n.toUpperCase()));
  for (const blk of [...b.fuzzify, ...b.defuzzify]) for (const t of blk.terms) taken.add(t.name.toUpperCase());
  let name = "ALWAYS";
  for (let n = 2; taken.has(name); n++) name = `ALWAYS_${n}`;
  return name;
}

function paramText(p) {
  return p && typeof p === "object" ? p.name : String(p);
}

export function conditionText(c, parent = 0) {
  if (!c) return "";
  if (c.type === "is") return [c.variable, "IS", ...(c.negated ? ["NOT"] : []), ...(c.hedges || []), c.term].join(" ");
  if (c.type === "degree") return c.variable;
  if (c.type === "not") {
    const inner = c.operand;
    return `NOT ${inner.type === "and" || inner.type === "or" || inner.type === "not" ? `(${conditionText(inner)})` : conditionText(inner, 3)}`;
  }
  const own = c.type === "and" ? 2 : 1;
  const text = c.operands
    .map((o) => {
      const t = conditionText(o, own);
      const other = o.type === "and" ? 2 : o.type === "or" ? 1 : 9;
      return other <= own ? `(${t})` : t;
    })
    .join(c.type === "and" ? " AND " : " OR ");
  return text;
}

export function conclusionText(c) {
  let text = c.variable;
  if (c.term !== null && c.term !== undefined) text += " IS " + [...(c.hedges || []), c.term].join(" ");
  if (c.weight !== null && c.weight !== undefined) text += ` WITH ${paramText(c.weight)}`;
  return text;
}

export function conclusionsText(rule) {
  return rule.conclusions.map(conclusionText).join(", ");
}

/** ``IF ... THEN ...`` to read; a rule without an IF part says what it does. */
export function ruleText(rule) {
  return `${rule.condition ? `IF ${conditionText(rule.condition)}` : "(no IF part: degree 1)"} THEN ${conclusionsText(rule)}`;
}

/** ``IF ... THEN ...`` as the FCL text writes it (a rule without an IF part: ``IF ALWAYS
 * THEN``), for the text editors: the parser reads it back. */
export function ruleLine(rule) {
  return `IF ${rule.condition ? conditionText(rule.condition) : alwaysName()} THEN ${conclusionsText(rule)}`;
}

export function nextLabel(block) {
  const numbers = block.rules.map((r) => parseInt(r.label, 10)).filter(Number.isFinite);
  return String((numbers.length ? Math.max(...numbers) : 0) + 1);
}

export function termOptions(name) {
  const b = fb();
  const blk = b.fuzzify.find((f) => f.variable === name) || b.defuzzify.find((d) => d.variable === name);
  return blk ? blk.terms.map((t) => t.name) : [];
}

export function blankRule(block) {
  return { label: nextLabel(block), condition: null, conclusions: [], weight: null };
}

/** The rule (block index, rule index) of a diagnostic's element, or null. */
export function ruleOf(element) {
  const m = /^rule:(\d+):(\d+)$/.exec(element || "");
  return m ? { block: +m[1], rule: +m[2] } : null;
}
