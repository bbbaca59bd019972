// The rule text editor: the rule block as IF ... THEN ... lines (one rule per line; RULE
// label : in front where the label is not the line's position), read by the server with
// the FCL parser and checks as you type, diagnostics in the gutter and below.  When the
// lines have no errors they replace the block's rules; while they have errors the model
// keeps the rules that checked last.
import { state, changed } from "./state.js";
import { $, fillDiagnostics } from "./ui.js";
import { CodeEditor } from "./code.js";
import { ruleLine, ruleOf } from "./rules-model.js";

let host = null; // {block(), blockIndex(), parse(text) -> result}
let editor = null;
let shownText = null; // the text as filled from the model (null: the user has typed)
let seq = 0;
export let lastResult = null;

export function setHost(h) {
  host = h;
}

/** The comments written after a rule on its line, as text to append to it (a "//" one
 * ends the line, so what follows it starts a new one). */
function afterText(r) {
  let text = "";
  for (const [place, c] of r.placed_comments || []) {
    if (place !== "after") continue;
    text += (text.split("\n").pop().trimStart().startsWith("//") ? "\n" : " ") + c;
  }
  return text;
}

/** The lines a rule takes: its comments before it, its line, the lines its comments after
 * it go on to. */
function linesOf(r) {
  let n = 1 + afterText(r).split("\n").length - 1;
  for (const c of r.comments || []) n += c.split("\n").length;
  return n;
}

/** The block's rules as lines; a rule's comments stand on the lines before it and after it
 * on its line, as in the file (the parser attaches them to it again). */
export function textOf(block) {
  const lines = [];
  block.rules.forEach((r, i) => {
    for (const c of r.comments || []) lines.push(...c.split("\n"));
    const rule = (r.label === String(i + 1) ? ruleLine(r) : `RULE ${r.label} : ${ruleLine(r)}`) + ";";
    lines.push(...(rule + afterText(r)).split("\n"));
  });
  return lines.join("\n");
}

/** The check's diagnostics about this block's rules, on the lines of those rules. */
function reportDiagnostics() {
  const lineOf = [];
  let line = 0;
  for (const r of host.block().rules) {
    for (const c of r.comments || []) line += c.split("\n").length;
    lineOf.push(line + 1);
    line += linesOf(r) - (r.comments || []).reduce((n, c) => n + c.split("\n").length, 0);
  }
  const out = [];
  for (const d of (state.report && state.report.diagnostics) || []) {
    const at = ruleOf(d.element);
    if (at && at.block === host.blockIndex() && lineOf[at.rule]) out.push({ ...d, line: lineOf[at.rule], column: null });
  }
  return out;
}

async function parse(text) {
  const mine = ++seq;
  shownText = null;
  let result;
  try {
    result = await host.parse(text);
  } catch (err) {
    fillDiagnostics($("#rule-diags"), [{ severity: "error", message: err.message }]);
    return;
  }
  if (mine !== seq) return;
  lastResult = result;
  editor.paint(result.diagnostics);
  fillDiagnostics($("#rule-diags"), result.diagnostics.map((d) => ({ ...d, element: null })), { onClick: (d) => d.line && editor.goToLine(d.line) });
  $("#rules-text").dataset.ok = String(result.ok);
  $("#rules-text").dataset.parsed = String(+($("#rules-text").dataset.parsed || 0) + 1);
  if (!result.ok) return;
  host.block().rules = result.rules;
  // the whole model is checked after a pause in typing: its parse would hold up the next line's
  changed("rules-text", { delay: 1000 });
}

export function render() {
  const text = textOf(host.block());
  if (shownText === null && editor.value && lastResult && !lastResult.ok) return; // keep the user's lines with their errors
  shownText = text;
  editor.diagnostics = reportDiagnostics();
  editor.value = text;
  fillDiagnostics($("#rule-diags"), editor.diagnostics, { onClick: (d) => d.line && editor.goToLine(d.line) });
}

/** A new check report: its diagnostics on the lines, when the text is the model's. */
export function report() {
  if (shownText === null) return;
  editor.paint(reportDiagnostics());
}

export function reset() {
  shownText = null;
  lastResult = null;
  if (editor) editor.value = "";
}

export function init() {
  editor = new CodeEditor($(".rules-code"), { onInput: parse });
}

export function focusLine(line) {
  editor.goToLine(line);
}

/** Go to the line of rule ``index`` (the comment lines before each rule counted). */
export function focusRule(index) {
  let line = 0;
  host.block().rules.forEach((r, i) => {
    if (i > index) return;
    if (i === index) {
      for (const c of r.comments || []) line += c.split("\n").length;
      line += 1;
    } else line += linesOf(r);
  });
  editor.goToLine(line);
}
