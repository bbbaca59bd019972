// The rule table, in two orientations: one row per rule (the default: hundreds of rules
// scroll down, names are never cut) or one column per rule (the Siemens rule table, manual
// 6.5).  Cells show the term as text and become a term picker when clicked (or Enter / F2 /
// Space): a table of 500 rules is text, built as one HTML string, not thousands of
// <select>s.  Input cells offer NOT term as well.  An IF or THEN part a table cannot show
// as cells (OR, parentheses, hedges, several conclusions for one output, WITH weights) is
// a text field read by the FCL parser; the ✎ button turns any rule into text fields.
import { state, inputs, outputs, changed, status } from "./state.js";
import { el } from "./ui.js";
import { escape } from "./code.js";
import { conditionCells, conclusionCells, setCondition, setConclusions, complete, conditionText, conclusionsText, ruleText, termOptions, ruleOf, alwaysName } from "./rules-model.js";

let host = null; // {block(), blockIndex(), selected(), select(j, focus), parseRule(text, field), render(), orientation}

export function setHost(h) {
  host = h;
}

const attr = (v) => escape(String(v)).replace(/"/g, "&quot;");

function cellText(part, name, side) {
  if (side === "if") {
    const term = part.ins[name];
    if (!term) return null;
    return part.neg && part.neg[name] ? `NOT ${term}` : term;
  }
  return part.outs[name] || null;
}

function cellHtml(rule, j, name, side, part, first) {
  const text = cellText(part, name, side);
  const shown = !text ? "—" : text.startsWith("NOT ") ? `<span class="neg">NOT</span> ${escape(text.slice(4))}` : escape(text);
  const cls = `cell${text ? "" : " blank"}${first ? " then-first" : ""}`;
  return `<td class="${cls}" tabindex="0" role="gridcell" data-rule="${j}" data-var="${attr(name)}" data-side="${side}" aria-label="rule ${attr(rule.label)} ${attr(name)}: ${attr(text || "blank")}">${shown}</td>`;
}

function textHtml(rule, j, side, span) {
  const value = side === "if" ? conditionText(rule.condition) : conclusionsText(rule);
  const title = side === "if" ? "the IF part as FCL: AND, OR, NOT, parentheses, hedges; Enter applies" : "the THEN part as FCL: conclusions separated by commas, WITH weights; Enter applies";
  const spanAttr = host.orientation === "rows" ? `colspan="${span}"` : `rowspan="${span}"`;
  return `<td class="${side === "if" ? "cond-text" : "concl-text then-first"}" ${spanAttr}><input value="${attr(value)}" spellcheck="false" data-rule="${j}" data-part="${side}" data-original="${attr(value)}" aria-label="rule ${attr(rule.label)} ${side === "if" ? "condition" : "conclusions"} (FCL)" title="${attr(title)}"></td>`;
}

function headHtml(rule, j, selected) {
  const cls = `rule-head${j === selected ? " selected" : ""}${complete(rule) ? "" : " incomplete"}`;
  const weight = rule.weight !== null && rule.weight !== undefined ? ` <span class="hint" title="rule weight (MATLAB / fuzzylite): multiplies the condition degree">×${attr(typeof rule.weight === "object" ? rule.weight.name : rule.weight)}</span>` : "";
  const title = complete(rule) ? ruleText(rule) : "incomplete: needs a THEN part";
  return `<th scope="${host.orientation === "rows" ? "row" : "col"}" class="${cls}" tabindex="0" data-rule="${j}" title="${attr(title)}">${escape(rule.label)}${weight}</th>`;
}

const editButton = (rule, j) => `<button class="as-text" data-rule="${j}" aria-label="rule ${attr(rule.label)} as text" title="edit this rule's IF and THEN parts as text (OR, NOT, parentheses, several conclusions, WITH)">✎</button>`;

/** The rules of the selected block as a table (rows or columns). */
export function render(table) {
  const block = host.block();
  const ins = inputs().map((v) => v.name);
  const outs = outputs().map((v) => v.name);
  const selected = host.selected();
  table.className = `rules ${host.orientation}`;
  table.setAttribute("role", "grid");
  const parts = block.rules.map((r) => (r._text ? [null, null] : [conditionCells(r), conclusionCells(r)]));
  const html = [];
  if (host.orientation === "rows") {
    html.push("<thead><tr><th scope=\"col\">Rule</th>");
    ins.forEach((n, i) => html.push(`<th scope="col">${i === 0 ? "IF " : ""}${escape(n)}</th>`));
    outs.forEach((n, i) => html.push(`<th scope="col"${i === 0 ? ' class="then-first"' : ""}>${i === 0 ? "THEN " : ""}${escape(n)}</th>`));
    html.push("<th scope=\"col\"></th></tr></thead><tbody>");
    block.rules.forEach((r, j) => {
      const [cond, concl] = parts[j];
      html.push(`<tr data-rule="${j}"${j === selected ? ' class="selected"' : ""}>${headHtml(r, j, selected)}`);
      if (cond) ins.forEach((n) => html.push(cellHtml(r, j, n, "if", cond, false)));
      else html.push(textHtml(r, j, "if", ins.length));
      if (concl) outs.forEach((n, i) => html.push(cellHtml(r, j, n, "then", concl, i === 0)));
      else html.push(textHtml(r, j, "then", outs.length));
      html.push(`<td>${editButton(r, j)}</td></tr>`);
    });
    html.push("</tbody>");
  } else {
    html.push("<thead><tr><th scope=\"col\">Rule</th>");
    block.rules.forEach((r, j) => html.push(headHtml(r, j, selected)));
    html.push("</tr></thead><tbody>");
    const rowsFor = (names, side) =>
      names.forEach((n, vi) => {
        html.push(`<tr class="${vi === 0 ? `first ${side}` : side}"><th scope="row">${vi === 0 ? (side === "if" ? "IF " : "THEN ") : ""}${escape(n)}</th>`);
        block.rules.forEach((r, j) => {
          const part = parts[j][side === "if" ? 0 : 1];
          if (part) html.push(cellHtml(r, j, n, side, part, false));
          else if (vi === 0) html.push(textHtml(r, j, side, names.length));
        });
        html.push("</tr>");
      });
    rowsFor(ins, "if");
    rowsFor(outs, "then");
    html.push("<tr><th scope=\"row\"></th>");
    block.rules.forEach((r, j) => html.push(`<td>${editButton(r, j)}</td>`));
    html.push("</tr></tbody>");
  }
  table.innerHTML = html.join("");
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
    th.classList.toggle("has-error", m === "error");
    th.classList.toggle("has-warning", m === "warning");
  }
}

/** Open the term picker of a cell. */
export function openPicker(td) {
  if (!td || td.querySelector("select")) return;
  const j = +td.dataset.rule;
  const name = td.dataset.var;
  const side = td.dataset.side;
  const block = host.block();
  const rule = block.rules[j];
  const part = side === "if" ? conditionCells(rule) : conclusionCells(rule);
  if (!part) return;
  host.select(j, false);
  const current = cellText(part, name, side) || "";
  const terms = termOptions(name);
  const options = [el("option", { value: "" }, "-blank-"), ...terms.map((t) => el("option", { value: t }, t))];
  if (side === "if") options.push(...terms.map((t) => el("option", { value: `NOT ${t}` }, `NOT ${t}`)));
  const picker = el("select", { "aria-label": `rule ${rule.label} ${name}`, "data-rule": j, "data-var": name }, ...options);
  picker.value = current;
  let done = false;
  const close = (apply) => {
    if (done) return;
    done = true;
    const t0 = performance.now();
    if (apply && picker.value !== current) {
      const now = side === "if" ? conditionCells(block.rules[j]) : conclusionCells(block.rules[j]);
      let value = picker.value;
      if (side === "if") {
        delete now.neg[name];
        if (value.startsWith("NOT ")) {
          value = value.slice(4);
          now.neg[name] = true;
        }
        if (value) now.ins[name] = value;
        else delete now.ins[name];
        setCondition(block.rules[j], now);
      } else {
        if (value) now.outs[name] = value;
        else delete now.outs[name];
        setConclusions(block.rules[j], now);
      }
      changed("rules");
    }
    const after = side === "if" ? conditionCells(block.rules[j]) : conclusionCells(block.rules[j]);
    td.outerHTML = cellHtml(block.rules[j], j, name, side, after, td.classList.contains("then-first"));
    const fresh = document.querySelector(`#rule-table td.cell[data-rule="${j}"][data-var="${CSS.escape(name)}"][data-side="${side}"]`);
    if (fresh && apply !== null) fresh.focus();
    const head = document.querySelector(`#rule-table th.rule-head[data-rule="${j}"]`);
    if (head) {
      head.classList.toggle("incomplete", !complete(block.rules[j]));
      head.title = complete(block.rules[j]) ? ruleText(block.rules[j]) : "incomplete: needs a THEN part";
    }
    // the browser's time for the edit: the model changed, the cell drawn again (for tests)
    document.querySelector("#rule-table").dataset.editMs = (performance.now() - t0).toFixed(1);
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

async function applyText(input) {
  const j = +input.dataset.rule;
  const r = host.block().rules[j];
  const side = input.dataset.part;
  const condition = side === "if" ? input.value.trim() || alwaysName() : r.condition ? conditionText(r.condition) : alwaysName();
  const conclusions = side === "then" ? input.value : conclusionsText(r);
  const parsed = await host.parseRule(`RULE ${r.label} : IF ${condition} THEN ${conclusions}`, input);
  if (!parsed) return;
  r.condition = parsed.condition;
  r.conclusions = parsed.conclusions;
  changed("rules");
  host.render();
  const table = document.querySelector("#rule-table");
  table.dataset.applied = String(+(table.dataset.applied || 0) + 1); // for tests
  status(`rule ${r.label}: ${ruleText(r)}`);
}

function editAsText(j) {
  host.block().rules[j]._text = true; // text fields until the next render from the model
  host.render();
  const field = document.querySelector(`#rule-table input[data-rule="${j}"][data-part="if"]`);
  if (field) field.focus();
}

/** Events of the table, bound once (the table's content is replaced on every render). */
export function bind(table) {
  table.addEventListener("click", (e) => {
    const button = e.target.closest("button.as-text");
    if (button) return editAsText(+button.dataset.rule);
    const head = e.target.closest("th.rule-head");
    if (head) return host.select(+head.dataset.rule, true);
    const td = e.target.closest("td.cell");
    if (td && !e.target.closest("select")) openPicker(td);
  });
  table.addEventListener("change", (e) => {
    if (e.target.matches("input[data-part]")) applyText(e.target);
  });
  table.addEventListener("keydown", (e) => {
    if (e.target.matches("input[data-part]")) {
      if (e.key === "Enter") {
        e.preventDefault();
        applyText(e.target);
      } else if (e.key === "Escape") {
        e.target.value = e.target.dataset.original;
        e.target.classList.remove("bad");
      }
      return;
    }
    const td = e.target.closest("td.cell, th.rule-head");
    if (!td || e.target.tagName === "SELECT") return;
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
    const node = e.target.closest("td.cell, input[data-rule]");
    if (node) host.select(+node.dataset.rule, false);
  });
}
