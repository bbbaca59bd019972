// The rule editor (manual 6.5 and beyond): the rule block's operators, and four views of
// the same rules - the matrix of two inputs, the table with one row per rule, the Siemens
// table with one column per rule, and the rules as text - with append, insert blank,
// delete and compress.  Every view edits the model; the check follows.
import { state, on, fb, changed, status, bodyWithoutRules } from "./state.js";
import { post } from "./api.js";
import { $, el, fillDiagnostics } from "./ui.js";
import { complete, blankRule, ruleText } from "./rules-model.js";
import * as grid from "./rules-grid.js";
import * as matrix from "./rules-matrix.js";
import * as text from "./rules-text.js";

export { cells, complete, conditionText, ruleText } from "./rules-model.js";

const MODE_KEY = "fuzzyctl-studio.rule-mode";
let rb = 0; // rule block index
let selectedRule = null;
let mode = null; // "matrix" | "rows" | "columns" | "text"

function block() {
  const b = fb();
  if (!b.rule_blocks.length) b.rule_blocks.push({ name: "rules", rules: [], and_op: "MIN", or_op: null, act: null, accu: "MAX", enabled: true, rule_activation: null });
  if (rb >= b.rule_blocks.length) rb = 0;
  return b.rule_blocks[rb];
}

/** The request body for reading rule lines: the model without any rules (the server reads
 * the lines in the function block with this rule block alone). */
function parseBody(extra) {
  return bodyWithoutRules(extra);
}

async function parseLines(textValue) {
  return post("/api/rules/parse", parseBody({ rule_block: rb, text: textValue }));
}

/** One rule written as text (``RULE n : IF ... THEN ...``): the rule, or null with the
 * error shown on ``field``. */
async function parseRule(line, field) {
  let result;
  try {
    result = await parseLines(line);
  } catch (err) {
    status(err.message, "error");
    return null;
  }
  const errors = result.diagnostics.filter((d) => d.severity === "error");
  if (!result.ok || !result.rules || result.rules.length !== 1) {
    const message = errors.length ? errors.map((d) => `${d.column ? `column ${d.column - line.indexOf(" : ") - 3}: ` : ""}${d.message}`).join("; ") : "write one rule";
    if (field) {
      field.classList.add("bad");
      field.title = message;
    }
    fillDiagnostics($("#rule-diags"), errors.map((d) => ({ ...d, line: null })));
    status(message, "error");
    return null;
  }
  if (field) field.classList.remove("bad");
  return result.rules[0];
}

function defaultMode() {
  const saved = localStorage.getItem(MODE_KEY);
  // the matrix only when it shows every rule (a MATLAB file's OR rules are not cells)
  const matrixFits = matrix.holdsAll();
  if (saved && ["matrix", "rows", "columns", "text"].includes(saved) && (saved !== "matrix" || matrixFits)) return saved;
  return matrixFits && state.doc && fb().rule_blocks.every((r) => r.rules.length <= 400) && fb().variables.filter((v) => v.kind === "VAR_INPUT").length === 2 ? "matrix" : "rows";
}

function setMode(next) {
  mode = next;
  try {
    localStorage.setItem(MODE_KEY, next);
  } catch (_) {
    /* not remembered */
  }
  render();
}

const host = {
  block,
  blockIndex: () => rb,
  selected: () => selectedRule,
  select,
  render: () => render(),
  parseRule,
  parse: parseLines,
  orientation: "rows",
};
grid.setHost(host);
matrix.setHost(host);
text.setHost(host);

export function render() {
  const b = fb();
  if (!b) return;
  if (!mode) mode = defaultMode();
  if (mode === "matrix" && !matrix.suits()) mode = "rows";
  const blk = block();
  $("#rb-select").replaceChildren(...b.rule_blocks.map((r, i) => el("option", { value: i, selected: i === rb }, r.name || `block ${i + 1}`)));
  $("#rb-and").value = blk.and_op || "";
  $("#rb-or").value = blk.or_op || "";
  $("#rb-act").value = blk.act || "";
  $("#rb-accu").value = blk.accu || "";
  for (const button of document.querySelectorAll("#view-rules .segmented button")) {
    button.setAttribute("aria-checked", String(button.dataset.mode === mode));
    button.disabled = button.dataset.mode === "matrix" && !matrix.suits();
    if (button.disabled) button.title = "the matrix needs two inputs";
  }
  $("#rules-matrix").hidden = mode !== "matrix";
  $("#rules-grid").hidden = mode !== "rows" && mode !== "columns";
  $("#rules-text").hidden = mode !== "text";
  $("#rule-actions").hidden = mode === "matrix" || mode === "text";
  const incomplete = blk.rules.filter((r) => !complete(r)).length;
  $("#rule-count").textContent = `${blk.rules.length} rule(s)${incomplete ? `, ${incomplete} incomplete` : ""}`;
  const t0 = performance.now();
  if (mode === "matrix") matrix.render($("#rules-matrix"));
  else if (mode === "text") text.render();
  else {
    host.orientation = mode;
    grid.render($("#rule-table"));
  }
  $("#view-rules").dataset.renderMs = String(Math.round(performance.now() - t0));
  $("#view-rules").dataset.mode = mode;
  if (mode !== "text") renderDiagnostics(blk);
}

function renderDiagnostics(blk) {
  const diags = state.report ? state.report.diagnostics.filter((d) => d.element && (d.element === `ruleblock:${rb}` || d.element.startsWith(`rule:${rb}:`))) : [];
  fillDiagnostics($("#rule-diags"), diags);
  const incomplete = blk.rules.filter((r) => !complete(r)).length;
  if (incomplete) $("#rule-diags").prepend(el("li", { class: "note" }, `${incomplete} incomplete rule(s) (no THEN part): not part of the knowledge base until complete, not saved.`));
  noIfNote(blk);
}

/** Rules with a THEN part only (manual 1.5): say what they do and how FCL holds them. */
function noIfNote(blk) {
  const labels = blk.rules.filter((r) => !r.condition && r.conclusions.length).map((r) => r.label);
  if (!labels.length) return;
  $("#rule-diags").prepend(el("li", { class: "note", "data-no-if": labels.join(",") }, `rule(s) ${labels.join(", ")}: no IF part, acting with degree 1 (manual 1.5); saved in FCL as "IF ALWAYS THEN", ALWAYS an unconnected input := 1.0.`));
}

function markSelected() {
  for (const node of document.querySelectorAll("#rule-table .selected")) node.classList.remove("selected");
  if (selectedRule === null) return;
  for (const node of document.querySelectorAll(`#rule-table th.rule-head[data-rule="${selectedRule}"], #rule-table tr[data-rule="${selectedRule}"]`)) node.classList.add("selected");
}

/** Select rule ``j`` (for Insert blank and Delete); ``focus``: move the focus to it. */
export function select(j, focus = true) {
  selectedRule = j;
  markSelected();
  if (focus) {
    const first = document.querySelector(`#rule-table td.cell[data-rule="${j}"], #rule-table input[data-rule="${j}"]`);
    if (first) first.focus();
  }
}

function afterStructure(message) {
  changed("structure");
  render();
  if (message) status(message);
}

export function init() {
  text.init();
  grid.bind($("#rule-table"));
  matrix.bind($("#rules-matrix"));
  on("model", (what) => !$("#view-rules").hidden && what !== "rules" && what !== "rules-text" && render());
  // new findings redraw the matrix's gap cells; not another mode, nor a cell being picked
  on("findings", () => !$("#view-rules").hidden && $("#view-rules").dataset.mode === "matrix" && !document.querySelector("#rule-matrix select") && render());
  on("report", () => {
    if ($("#view-rules").hidden) return;
    if (mode === "text") text.report();
    else if (mode === "matrix") renderDiagnostics(block());
    else {
      grid.marks($("#rule-table"));
      renderDiagnostics(block());
      $("#rule-count").textContent = `${block().rules.length} rule(s)`;
    }
  });
  on("loaded", () => {
    rb = 0;
    selectedRule = null;
    mode = null;
    text.reset();
  });
  for (const button of document.querySelectorAll("#view-rules .segmented button")) button.addEventListener("click", () => setMode(button.dataset.mode));
  $("#rb-select").addEventListener("change", (e) => {
    rb = +e.target.value;
    selectedRule = null;
    text.reset();
    render();
  });
  for (const [id, key] of [["#rb-and", "and_op"], ["#rb-or", "or_op"], ["#rb-act", "act"], ["#rb-accu", "accu"]]) {
    $(id).addEventListener("change", (e) => {
      block()[key] = e.target.value || null;
      changed("rules");
    });
  }
  $("#rule-append").addEventListener("click", () => {
    const blk = block();
    blk.rules.push(blankRule(blk));
    selectedRule = blk.rules.length - 1;
    render();
    select(selectedRule);
    const row = document.querySelector(`#rule-table [data-rule="${selectedRule}"]`);
    if (row) row.scrollIntoView({ block: "nearest", inline: "nearest" });
  });
  $("#rule-insert").addEventListener("click", () => {
    const blk = block();
    const at = selectedRule === null ? Math.max(0, blk.rules.length - 1) : selectedRule;
    blk.rules.splice(at, 0, blankRule(blk));
    selectedRule = at;
    render();
    select(at);
  });
  $("#rule-delete").addEventListener("click", () => {
    const blk = block();
    if (selectedRule === null || !blk.rules[selectedRule]) return status("select a rule first (click its number)", "error");
    const [gone] = blk.rules.splice(selectedRule, 1);
    selectedRule = Math.min(selectedRule, blk.rules.length - 1);
    if (selectedRule < 0) selectedRule = null;
    afterStructure(`deleted rule ${gone.label}: ${ruleText(gone)}`);
  });
  $("#rule-compress").addEventListener("click", () => {
    const blk = block();
    const before = blk.rules.length;
    blk.rules = blk.rules.filter((r) => r.condition || r.conclusions.length);
    blk.rules.forEach((r, i) => (r.label = String(i + 1)));
    selectedRule = null;
    afterStructure(`compressed: ${before - blk.rules.length} empty rule(s) removed, rules renumbered`);
  });
  document.addEventListener("keydown", (e) => {
    if (!$("#view-rules").hidden && e.altKey && e.key.toLowerCase() === "a" && !$("#rule-actions").hidden) {
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
  if (mode === "text" && selectedRule !== null) {
    render();
    text.focusRule(selectedRule);
    return;
  }
  if (mode === "matrix" || mode === null) mode = "rows";
  render();
  if (selectedRule !== null) {
    select(selectedRule);
    const row = document.querySelector(`#rule-table [data-rule="${selectedRule}"]`);
    if (row) row.scrollIntoView({ block: "nearest", inline: "nearest" });
  }
}

export function currentMode() {
  return mode;
}
