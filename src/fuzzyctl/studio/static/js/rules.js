// The rule editor (manual 6.5): one column per rule, one row per input (IF, joined by
// AND) and per output (THEN), a term picker in every cell; append, insert blank, delete,
// compress.  Rules the table cannot show (OR, NOT, WITH, hedges) are kept and shown as text.
// A column with a THEN part only is a rule without an IF part (degree 1, manual 1.5).
import { state, on, fb, inputs, outputs, changed, status } from "./state.js";
import { $, el, fillDiagnostics } from "./ui.js";

let rb = 0; // rule block index
let selectedRule = null;

/** A rule as table cells {input: term}, {output: term}, or null when the table cannot
 * show it. */
export function cells(rule) {
  const ins = {};
  const outs = {};
  const inputNames = new Set(inputs().map((v) => v.name));
  const outputNames = new Set(outputs().map((v) => v.name));
  const plain = (c) => c.type === "is" && !c.negated && !(c.hedges && c.hedges.length) && inputNames.has(c.variable) && !(c.variable in ins);
  const cond = rule.condition;
  const parts = !cond ? [] : cond.type === "and" ? cond.operands : [cond];
  for (const c of parts) {
    if (!plain(c)) return null;
    ins[c.variable] = c.term;
  }
  for (const c of rule.conclusions) {
    if (c.term === null || c.weight !== null || (c.hedges && c.hedges.length) || !outputNames.has(c.variable) || c.variable in outs) return null;
    outs[c.variable] = c.term;
  }
  if (rule.weight !== null && rule.weight !== undefined) return null;
  return { ins, outs };
}

function fromCells(rule, ins, outs) {
  const parts = inputs().filter((v) => ins[v.name]).map((v) => ({ type: "is", variable: v.name, term: ins[v.name], negated: false, hedges: [] }));
  rule.condition = parts.length === 0 ? null : parts.length === 1 ? parts[0] : { type: "and", operands: parts };
  rule.conclusions = outputs().filter((v) => outs[v.name]).map((v) => ({ variable: v.name, term: outs[v.name], weight: null, hedges: [] }));
}

/** A rule is part of the knowledge base once it has a THEN part; without an IF part it acts
 * with degree 1 (manual 1.5: "a rule without an IF part still has an influence ... as if the
 * conditions of the IF part were fully fulfilled").  An IF part alone has no influence. */
export function complete(rule) {
  return rule.conclusions.length > 0;
}

export function conditionText(c) {
  if (!c) return "";
  if (c.type === "is") return `${c.variable} IS ${c.negated ? "NOT " : ""}${(c.hedges || []).join(" ")}${c.hedges && c.hedges.length ? " " : ""}${c.term}`;
  if (c.type === "degree") return c.variable;
  if (c.type === "not") return `NOT (${conditionText(c.operand)})`;
  const joined = c.operands.map((o) => (o.type === "and" || o.type === "or" ? `(${conditionText(o)})` : conditionText(o)));
  return joined.join(c.type === "and" ? " AND " : " OR ");
}

export function ruleText(rule) {
  const then = rule.conclusions.map((c) => `${c.variable}${c.term ? " IS " + c.term : ""}${c.weight !== null && c.weight !== undefined ? " WITH " + (typeof c.weight === "object" ? c.weight.name : c.weight) : ""}`).join(", ");
  return `${rule.condition ? `IF ${conditionText(rule.condition)}` : "(no IF part: degree 1)"} THEN ${then}`;
}

function nextLabel(block) {
  const numbers = block.rules.map((r) => parseInt(r.label, 10)).filter(Number.isFinite);
  return String((numbers.length ? Math.max(...numbers) : 0) + 1);
}

function termOptions(name) {
  const b = fb();
  const blk = b.fuzzify.find((f) => f.variable === name) || b.defuzzify.find((d) => d.variable === name);
  return blk ? blk.terms.map((t) => t.name) : [];
}

function render() {
  const b = fb();
  const table = $("#rule-table");
  table.replaceChildren();
  if (!b) return;
  if (!b.rule_blocks.length) b.rule_blocks.push({ name: "rules", rules: [], and_op: "MIN", or_op: null, act: null, accu: "MAX", enabled: true, rule_activation: null });
  if (rb >= b.rule_blocks.length) rb = 0;
  $("#rb-select").replaceChildren(...b.rule_blocks.map((r, i) => el("option", { value: i, selected: i === rb }, r.name || `block ${i + 1}`)));
  const block = b.rule_blocks[rb];
  $("#rb-and").value = block.and_op || "";
  $("#rb-accu").value = block.accu || "";
  const head = el("tr", {}, el("th", { scope: "col" }, "Rule"));
  block.rules.forEach((r, j) => {
    const th = el("th", { scope: "col", class: `rule-head${j === selectedRule ? " selected" : ""}${complete(r) ? "" : " incomplete"}`, tabindex: "0", "data-rule": j, title: complete(r) ? ruleText(r) : "incomplete: needs a THEN part" }, r.label);
    th.addEventListener("click", () => select(j));
    th.addEventListener("keydown", (e) => e.key === "Enter" && select(j));
    head.append(th);
  });
  const thead = el("thead", {}, head);
  const tbody = el("tbody");
  const views = block.rules.map(cells);
  const rowsFor = (vars, side) => {
    vars.forEach((v, vi) => {
      const tr = el("tr", { class: vi === 0 ? `first ${side}` : side }, el("th", { scope: "row" }, `${vi === 0 ? (side === "if" ? "IF " : "THEN ") : ""}${v.name}`));
      block.rules.forEach((r, j) => {
        const view = views[j];
        if (!view) {
          if (side === "if" && vi === 0) tr.append(el("td", { rowspan: inputs().length + outputs().length, class: "text-rule", title: "edit this rule in the FCL text" }, ruleText(r)));
          return;
        }
        const value = side === "if" ? view.ins[v.name] || "" : view.outs[v.name] || "";
        const picker = el("select", { "aria-label": `rule ${r.label} ${v.name}`, "data-rule": j, "data-var": v.name }, el("option", { value: "" }, "-blank-"), ...termOptions(v.name).map((t) => el("option", { value: t, selected: t === value }, t)));
        picker.addEventListener("focus", () => {
          selectedRule = j;
          markSelected();
        });
        picker.addEventListener("change", () => {
          const current = cells(block.rules[j]);
          const target = side === "if" ? current.ins : current.outs;
          if (picker.value) target[v.name] = picker.value;
          else delete target[v.name];
          fromCells(block.rules[j], current.ins, current.outs);
          changed("rules");
        });
        tr.append(el("td", { class: j === selectedRule ? "selected" : null }, picker));
      });
      tbody.append(tr);
    });
  };
  rowsFor(inputs(), "if");
  rowsFor(outputs(), "then");
  table.append(thead, tbody);
  const diags = state.report ? state.report.diagnostics.filter((d) => d.element && (d.element === `ruleblock:${rb}` || d.element.startsWith(`rule:${rb}:`))) : [];
  fillDiagnostics($("#rule-diags"), diags);
  const incomplete = block.rules.filter((r) => !complete(r)).length;
  if (incomplete) $("#rule-diags").prepend(el("li", { class: "note" }, `${incomplete} incomplete rule(s) (no THEN part): not part of the knowledge base until complete, not saved.`));
  noIfNote(block);
}

/** Rules with a THEN part only (manual 1.5): say what they do and how FCL holds them. */
function noIfNote(block) {
  const labels = block.rules.filter((r) => !r.condition && r.conclusions.length).map((r) => r.label);
  if (!labels.length) return;
  $("#rule-diags").prepend(el("li", { class: "note", "data-no-if": labels.join(",") }, `rule(s) ${labels.join(", ")}: no IF part, acting with degree 1 (manual 1.5); saved in FCL as "IF ALWAYS THEN", ALWAYS an unconnected input := 1.0.`));
}

function markSelected() {
  for (const node of document.querySelectorAll("#rule-table .selected")) node.classList.remove("selected");
  for (const node of document.querySelectorAll(`#rule-table [data-rule="${selectedRule}"]`)) (node.tagName === "TH" ? node : node.parentElement).classList.add("selected");
}

function select(j) {
  selectedRule = j;
  markSelected();
  const first = document.querySelector(`#rule-table select[data-rule="${j}"]`);
  if (first) first.focus();
}

function blankRule(block) {
  return { label: nextLabel(block), condition: null, conclusions: [], weight: null };
}

export function init() {
  on("model", (what) => !$("#view-rules").hidden && what !== "rules" && render());
  on("report", () => !$("#view-rules").hidden && render());
  on("loaded", () => {
    rb = 0;
    selectedRule = null;
  });
  $("#rb-select").addEventListener("change", (e) => {
    rb = +e.target.value;
    selectedRule = null;
    render();
  });
  $("#rb-and").addEventListener("change", (e) => {
    fb().rule_blocks[rb].and_op = e.target.value || null;
    changed("rules");
  });
  $("#rb-accu").addEventListener("change", (e) => {
    fb().rule_blocks[rb].accu = e.target.value || null;
    changed("rules");
  });
  $("#rule-append").addEventListener("click", () => {
    const block = fb().rule_blocks[rb];
    block.rules.push(blankRule(block));
    selectedRule = block.rules.length - 1;
    render();
    select(selectedRule);
  });
  $("#rule-insert").addEventListener("click", () => {
    const block = fb().rule_blocks[rb];
    const at = selectedRule === null ? Math.max(0, block.rules.length - 1) : selectedRule;
    block.rules.splice(at, 0, blankRule(block));
    selectedRule = at;
    render();
    select(at);
  });
  $("#rule-delete").addEventListener("click", () => {
    const block = fb().rule_blocks[rb];
    if (selectedRule === null || !block.rules[selectedRule]) return status("select a rule first (click its number)", "error");
    const [gone] = block.rules.splice(selectedRule, 1);
    selectedRule = Math.min(selectedRule, block.rules.length - 1);
    if (selectedRule < 0) selectedRule = null;
    changed("structure");
    render();
    status(`deleted rule ${gone.label}`);
  });
  $("#rule-compress").addEventListener("click", () => {
    const block = fb().rule_blocks[rb];
    const before = block.rules.length;
    block.rules = block.rules.filter((r) => r.condition || r.conclusions.length);
    block.rules.forEach((r, i) => (r.label = String(i + 1)));
    selectedRule = null;
    changed("structure");
    render();
    status(`compressed: ${before - block.rules.length} empty rule(s) removed, rules renumbered`);
  });
  document.addEventListener("keydown", (e) => {
    if (!$("#view-rules").hidden && e.altKey && e.key.toLowerCase() === "a") {
      e.preventDefault();
      $("#rule-append").click();
    }
  });
}

export function shown() {
  render();
}

export function focus(target) {
  rb = target.block || 0;
  selectedRule = target.rule;
  render();
  if (selectedRule !== null) select(selectedRule);
}
