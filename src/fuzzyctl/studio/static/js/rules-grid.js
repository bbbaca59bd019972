// The rule table, in two orientations: one row per rule (the default: hundreds of rules
// scroll down, names are never cut) or one column per rule (the Siemens rule table, manual
// 6.5).  Cells show the term as text and become a term picker when clicked (or Enter / F2 /
// Space): a table of 500 rules is 500 rows of text, not thousands of <select>s.  Input
// cells offer NOT term as well.  A rule a table cannot show as cells (OR, parentheses,
// hedges, WITH weights) shows its IF and THEN parts as text fields read by the FCL parser.
import { state, fb, inputs, outputs, changed, status } from "./state.js";
import { $, el } from "./ui.js";
import { cells, fromCells, complete, conditionText, conclusionsText, ruleText, termOptions, ruleOf } from "./rules-model.js";

let host = null; // {block(), selected(), select(j), parseRule(text) -> rule|null, orientation}

export function setHost(h) {
  host = h;
}

function cellLabel(view, v, side) {
  if (side === "if") {
    const term = view.ins[v.name];
    if (!term) return ["—", true];
    return [view.neg && view.neg[v.name] ? `NOT ${term}` : term, false];
  }
  const term = view.outs[v.name];
  return term ? [term, false] : ["—", true];
}

function termCell(rule, j, v, side, view) {
  const [text, blank] = cellLabel(view, v, side);
  const td = el("td", { class: `cell${blank ? " blank" : ""}${side === "then" && v === outputs()[0] ? " then-first" : ""}`, tabindex: "0", role: "gridcell", "aria-label": `rule ${rule.label} ${v.name}: ${blank ? "blank" : text}`, "data-rule": j, "data-var": v.name, "data-side": side }, text);
  if (text.startsWith("NOT ")) td.replaceChildren(el("span", { class: "neg" }, "NOT "), text.slice(4));
  return td;
}

/** Open the term picker of a cell. */
export function openPicker(td) {
  if (!td || td.querySelector("select")) return;
  const j = +td.dataset.rule;
  const name = td.dataset.var;
  const side = td.dataset.side;
  const block = host.block();
  const rule = block.rules[j];
  const view = cells(rule);
  if (!view) return;
  host.select(j, false);
  const current = side === "if" ? (view.ins[name] ? (view.neg && view.neg[name] ? `NOT ${view.ins[name]}` : view.ins[name]) : "") : view.outs[name] || "";
  const terms = termOptions(name);
  const options = [el("option", { value: "" }, "-blank-"), ...terms.map((t) => el("option", { value: t, selected: t === current }, t))];
  if (side === "if") options.push(...terms.map((t) => el("option", { value: `NOT ${t}`, selected: `NOT ${t}` === current }, `NOT ${t}`)));
  const picker = el("select", { "aria-label": `rule ${rule.label} ${name}`, "data-rule": j, "data-var": name }, ...options);
  picker.value = current;
  let done = false;
  const close = (apply) => {
    if (done) return;
    done = true;
    if (apply && picker.value !== current) {
      const now = cells(block.rules[j]);
      const target = side === "if" ? now.ins : now.outs;
      let value = picker.value;
      if (side === "if") {
        now.neg ||= {};
        delete now.neg[name];
        if (value.startsWith("NOT ")) {
          value = value.slice(4);
          now.neg[name] = true;
        }
      }
      if (value) target[name] = value;
      else delete target[name];
      fromCells(block.rules[j], now);
      changed("rules");
    }
    const fresh = termCell(block.rules[j], j, inputs().concat(outputs()).find((v) => v.name === name), side, cells(block.rules[j]) || view);
    td.replaceWith(fresh);
    if (apply !== null) fresh.focus();
    host.refreshRule?.(j);
  };
  picker.addEventListener("change", () => close(true));
  picker.addEventListener("blur", () => close(null));
  picker.addEventListener("keydown", (e) => {
    if (e.key === "Escape") {
      e.preventDefault();
      close(false);
    } else if (e.key === "Enter") {
      e.preventDefault();
      close(true);
    }
  });
  td.replaceChildren(picker);
  picker.focus();
}

function textCell(rule, j, side, span) {
  const value = side === "if" ? conditionText(rule.condition) : conclusionsText(rule);
  const input = el("input", { value, spellcheck: "false", "aria-label": `rule ${rule.label} ${side === "if" ? "condition" : "conclusions"} (FCL)`, "data-rule": j, "data-part": side, title: side === "if" ? "the IF part as FCL: AND, OR, NOT, parentheses, hedges; Enter applies" : "the THEN part as FCL: several conclusions separated by commas, WITH weights; Enter applies" });
  input.addEventListener("focus", () => host.select(j, false));
  input.addEventListener("keydown", (e) => {
    if (e.key === "Enter") {
      e.preventDefault();
      input.dispatchEvent(new Event("change"));
    } else if (e.key === "Escape") {
      input.value = value;
      input.classList.remove("bad");
    }
  });
  input.addEventListener("change", async () => {
    const r = host.block().rules[j];
    const condition = side === "if" ? input.value : conditionText(r.condition);
    const conclusions = side === "then" ? input.value : conclusionsText(r);
    const parsed = await host.parseRule(`RULE ${r.label} : IF ${condition} THEN ${conclusions}`, input);
    if (!parsed) return;
    r.condition = parsed.condition;
    r.conclusions = parsed.conclusions;
    changed("rules");
    host.render();
    status(`rule ${r.label}: ${ruleText(r)}`);
  });
  const attrs = { class: side === "if" ? "cond-text" : "concl-text then-first" };
  if (host.orientation === "rows") attrs.colspan = span;
  else attrs.rowspan = span;
  return el("td", attrs, input);
}

function header(rule, j, selected) {
  const cls = `rule-head${j === selected ? " selected" : ""}${complete(rule) ? "" : " incomplete"}`;
  const th = el("th", { scope: host.orientation === "rows" ? "row" : "col", class: cls, tabindex: "0", "data-rule": j, title: complete(rule) ? ruleText(rule) : "incomplete: needs an IF and a THEN part" }, rule.label);
  return th;
}

function editAsText(j) {
  const b = host.block();
  b.rules[j]._text = true; // shown as text fields until the next render from the model
  host.render();
  const field = document.querySelector(`#rule-table input[data-rule="${j}"][data-part="if"]`);
  if (field) field.focus();
}

/** The rules of the selected block as a table (rows or columns). */
export function render(table) {
  const block = host.block();
  const ins = inputs();
  const outs = outputs();
  const selected = host.selected();
  table.className = `rules ${host.orientation}`;
  table.setAttribute("role", "grid");
  const views = block.rules.map((r) => (r._text ? null : cells(r)));
  const thead = el("thead");
  const tbody = el("tbody");
  if (host.orientation === "rows") {
    thead.append(el("tr", {}, el("th", { scope: "col" }, "Rule"), ...ins.map((v, i) => el("th", { scope: "col" }, `${i === 0 ? "IF " : ""}${v.name}`)), ...outs.map((v, i) => el("th", { scope: "col", class: i === 0 ? "then-first" : null }, `${i === 0 ? "THEN " : ""}${v.name}`)), el("th", { scope: "col" }, "")));
    const rows = block.rules.map((r, j) => {
      const tr = el("tr", { "data-rule": j, class: j === selected ? "selected" : null }, header(r, j, selected));
      const view = views[j];
      if (view) {
        for (const v of ins) tr.append(termCell(r, j, v, "if", view));
        for (const v of outs) tr.append(termCell(r, j, v, "then", view));
      } else {
        tr.append(textCell(r, j, "if", ins.length), textCell(r, j, "then", outs.length));
      }
      tr.append(el("td", {}, el("button", { class: "as-text", title: "edit this rule's IF and THEN parts as text (OR, NOT, parentheses, several conclusions, WITH)", "data-rule": j, "aria-label": `rule ${r.label} as text` }, "✎")));
      return tr;
    });
    tbody.append(...rows);
  } else {
    thead.append(el("tr", {}, el("th", { scope: "col" }, "Rule"), ...block.rules.map((r, j) => header(r, j, selected))));
    const rowsFor = (vars, side) =>
      vars.forEach((v, vi) => {
        const tr = el("tr", { class: vi === 0 ? `first ${side}` : side }, el("th", { scope: "row" }, `${vi === 0 ? (side === "if" ? "IF " : "THEN ") : ""}${v.name}`));
        block.rules.forEach((r, j) => {
          const view = views[j];
          if (view) tr.append(termCell(r, j, v, side, view));
          else if (vi === 0) tr.append(textCell(r, j, side, vars.length));
        });
        tbody.append(tr);
      });
    rowsFor(ins, "if");
    rowsFor(outs, "then");
    const tr = el("tr", {}, el("th", { scope: "row" }, ""));
    block.rules.forEach((r, j) => tr.append(el("td", {}, el("button", { class: "as-text", "data-rule": j, "aria-label": `rule ${r.label} as text`, title: "edit as text" }, "✎"))));
    tbody.append(tr);
  }
  table.replaceChildren(thead, tbody);
  for (const r of block.rules) delete r._text;
  marks(table);
}

/** Mark the rules the last check has diagnostics about. */
export function marks(table) {
  const bad = new Map();
  for (const d of (state.report && state.report.diagnostics) || []) {
    const at = ruleOf(d.element);
    if (at && at.block === host.blockIndex()) bad.set(at.rule, d.severity === "error" || bad.get(at.rule) === "error" ? "error" : d.severity);
  }
  for (const th of table.querySelectorAll("th.rule-head")) {
    const m = bad.get(+th.dataset.rule);
    th.style.boxShadow = m === "error" ? "inset 3px 0 0 #b3261e" : m === "warning" ? "inset 3px 0 0 #d4a017" : "";
  }
}

/** Events of the table, bound once. */
export function bind(table) {
  table.addEventListener("click", (e) => {
    const button = e.target.closest("button.as-text");
    if (button) return editAsText(+button.dataset.rule);
    const head = e.target.closest("th.rule-head");
    if (head) return host.select(+head.dataset.rule, true);
    const td = e.target.closest("td.cell");
    if (td && !e.target.closest("select")) openPicker(td);
  });
  table.addEventListener("keydown", (e) => {
    const td = e.target.closest("td.cell, th.rule-head");
    if (!td || e.target.tagName === "SELECT" || e.target.tagName === "INPUT") return;
    if (td.matches("th.rule-head") && e.key === "Enter") return host.select(+td.dataset.rule, true);
    if (td.matches("td.cell") && (e.key === "Enter" || e.key === "F2" || e.key === " ")) {
      e.preventDefault();
      return openPicker(td);
    }
    const moves = { ArrowUp: [0, -1], ArrowDown: [0, 1], ArrowLeft: [-1, 0], ArrowRight: [1, 0] };
    if (!moves[e.key] || !td.matches("td.cell")) return;
    e.preventDefault();
    const [dx, dy] = moves[e.key];
    const row = td.parentElement;
    let target = null;
    if (dx) target = dx < 0 ? td.previousElementSibling : td.nextElementSibling;
    else {
      const index = [...row.children].indexOf(td);
      const other = dy < 0 ? row.previousElementSibling : row.nextElementSibling;
      target = other ? other.children[index] : null;
    }
    if (target && target.matches("td.cell")) target.focus();
  });
  table.addEventListener("focusin", (e) => {
    const td = e.target.closest("td.cell");
    if (td) host.select(+td.dataset.rule, false);
  });
}
