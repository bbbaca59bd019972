// The analysis' findings in the check panel (gaps, conflicts, dead / duplicate / subsumed
// rules, unused terms, monotonicity against declared signs), each clickable to its rule or
// variable; and the gap boxes the rule matrix and the 3D display draw (docs/studio.md,
// "Findings").  Asked from /api/findings after each check, which stays as fast as before.
import { post } from "./api.js";
import { state, on, emit, body, num } from "./state.js";
import { $, el, fillDiagnostics } from "./ui.js";

export const found = { data: null };
let seq = 0;
let timer = null;

let checking = false;

// after the check has settled: the analysis never holds up the check of the next edit
function schedule() {
  clearTimeout(timer);
  timer = setTimeout(() => (checking ? schedule() : refresh()), 400);
}

/** The rule indices the server sees: a rule without a THEN part is not sent (state.body). */
function ruleIndexMap() {
  const b = state.doc && state.doc.blocks[state.block];
  if (!b) return [];
  return b.rule_blocks.map((rb) => rb.rules.map((r, j) => [r, j]).filter(([r]) => r.conclusions.length).map(([, j]) => j));
}

async function refresh() {
  const mine = ++seq;
  if (!state.doc) {
    found.data = null;
  } else if (state.report && state.report.ok === false) {
    found.data = { ok: false, error: "no analysis while the check finds errors", findings: [], gaps: [] };
  } else {
    const map = ruleIndexMap();
    const monotone = ($("#findings-monotone").value || "").split(/\s+/).filter(Boolean);
    try {
      // the lines of the text the check panel's diagnostics refer to (the file as opened)
      const answer = await post("/api/findings", body({ monotone, text: (state.report && state.report.text) || null }));
      if (mine !== seq) return;
      for (const d of answer.findings) {
        const m = /^rule:(\d+):(\d+)$/.exec(d.element || "");
        if (m && map[+m[1]]) d.element = `rule:${m[1]}:${map[+m[1]][+m[2]]}`;
      }
      found.data = answer;
    } catch (err) {
      if (mine !== seq) return;
      found.data = { ok: false, error: err.message, findings: [], gaps: [] };
    }
  }
  render();
  emit("findings", found.data);
  document.body.dataset.findings = String(+(document.body.dataset.findings || 0) + 1);
}

function boxText(box) {
  return Object.entries(box).map(([k, [lo, hi]]) => (lo === hi ? `${k} = ${num(lo)}` : `${k} in [${num(lo)}, ${num(hi)}]`)).join(", ");
}

function render() {
  const d = found.data;
  const summary = $("#findings-summary");
  if (!d) {
    summary.textContent = "";
    $("#findings-list").replaceChildren();
    return;
  }
  if (!d.ok) {
    summary.textContent = d.error || "";
    $("#findings-list").replaceChildren();
    return;
  }
  const gaps = d.gaps.length;
  summary.textContent = d.findings.length
    ? `${d.findings.length} finding(s)${gaps ? `; gaps: ${gaps} box(es), ${num(d.gap_fraction * 100)} % of the input space` : ""}`
    : `no findings: every input point fires a rule (coverage index ${num(d.coverage_index)})`;
  const items = d.findings.map((f) => ({ ...f }));
  // each gap box as its own entry under the gap finding: where to look on the matrix / 3D
  const gapItems = d.gaps.map((g) => ({ severity: "note", code: "analyze-gap-box", message: `gap of ${g.output}: ${boxText(g.box)}`, line: null, element: `var:${g.output}` }));
  const at = items.findIndex((f) => f.code === "analyze-gap");
  items.splice(at < 0 ? 0 : at + 1, 0, ...gapItems);
  fillDiagnostics($("#findings-list"), items);
  for (const [i, li] of [...$("#findings-list").children].entries()) li.dataset.code = items[i].code || "";
}

/** Matrix cells ("row\u0000col" -> gap texts) a rule could cover a gap of ``output`` from:
 * the terms of the row and column inputs (and of the held inputs) that reach above 0 in the
 * gap box. */
export function gapCells(output, row, col, fixed) {
  const cells = new Map();
  for (const g of (found.data && found.data.gaps) || []) {
    if (g.output !== output) continue;
    const held = Object.entries(fixed || {}).filter(([, t]) => t);
    if (held.some(([name, t]) => g.terms[name] && !g.terms[name].includes(t))) continue;
    for (const a of g.terms[row] || []) {
      for (const b of col ? g.terms[col] || [] : [""]) {
        const key = `${a}\u0000${b}`;
        cells.set(key, [...(cells.get(key) || []), boxText(g.box)]);
      }
    }
  }
  return cells;
}

/** Gaps of ``output`` with no cell on the matrix: an input of the row or column has no term
 * above 0 there (a hole between its terms, or a line where they meet at 0). */
export function gapsBetweenTerms(output, row, col) {
  return ((found.data && found.data.gaps) || []).filter((g) => g.output === output && [row, col].some((n) => n && g.terms[n] && !g.terms[n].length)).map((g) => boxText(g.box));
}

/** The gap boxes of ``output`` that cut the 3D display's plane (the other inputs at
 * ``fixed``): [{x: [lo, hi], y: [lo, hi], text}]. */
export function gapBoxes(output, x, y, fixed) {
  const out = [];
  for (const g of (found.data && found.data.gaps) || []) {
    if (g.output !== output || !g.box[x] || !g.box[y]) continue;
    const inside = Object.entries(fixed || {}).every(([name, v]) => name === x || name === y || !g.box[name] || (v >= g.box[name][0] && v <= g.box[name][1]));
    if (inside) out.push({ x: g.box[x], y: g.box[y], text: boxText(g.box) });
  }
  return out;
}

export function init() {
  on("report", schedule);
  on("checking", (busy) => (checking = busy));
  on("loaded", () => {
    found.data = null;
    render();
  });
  $("#findings-monotone").addEventListener("change", schedule);
}
