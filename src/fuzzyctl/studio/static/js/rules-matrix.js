// The rule matrix: the terms of one input down, of another across, each cell the output
// term the rule "IF row AND column THEN output" concludes - the way a two-input rule base
// is usually drawn.  With more inputs the others are held at a term (or left out of the
// rule), so every slice of the rule base is a matrix.  A click on a cell (or Enter) picks
// the output term: the rule is changed, added, or removed when the cell is blanked.
import { fb, inputs, outputs, changed, status } from "./state.js";
import { $, el } from "./ui.js";
import { cells, fromCells, termOptions, nextLabel, ruleText } from "./rules-model.js";
import { gapCells, gapsBetweenTerms } from "./findings.js";

let host = null; // {block(), select(j)}
const axes = { row: null, col: null, output: null, fixed: {} };

export function setHost(h) {
  host = h;
}

function pickAxes() {
  const ins = inputs().map((v) => v.name);
  const outs = outputs().map((v) => v.name);
  if (!ins.includes(axes.row)) axes.row = ins[0] || null;
  if (!ins.includes(axes.col) || axes.col === axes.row) axes.col = ins.find((n) => n !== axes.row) || null;
  if (!outs.includes(axes.output)) axes.output = outs[0] || null;
  for (const name of Object.keys(axes.fixed)) if (!ins.includes(name) || name === axes.row || name === axes.col) delete axes.fixed[name];
  // an input held for the first time: at its first term when the rules use it
  const rules = host.block().rules;
  for (const name of ins.filter((n) => n !== axes.row && n !== axes.col && !(n in axes.fixed))) {
    const used = rules.some((r) => { const v = cells(r); return v && v.ins[name]; });
    axes.fixed[name] = used ? termOptions(name)[0] || "" : "";
  }
}

/** The condition a cell stands for: {input: term} for the row, the column and the held
 * inputs. */
function conditionOf(a, b) {
  const want = { ...axes.fixed };
  for (const k of Object.keys(want)) if (!want[k]) delete want[k];
  if (axes.row) want[axes.row] = a;
  if (axes.col) want[axes.col] = b;
  return want;
}

function sameCondition(view, want) {
  if (!view || Object.keys(view.neg || {}).length) return false;
  const keys = Object.keys(view.ins);
  return keys.length === Object.keys(want).length && keys.every((k) => want[k] === view.ins[k]);
}

/** Index the rules by cell: "a\u0000b" -> [rule indices], and count those outside. */
function index(block) {
  const map = new Map();
  let outside = 0;
  const rowTerms = axes.row ? termOptions(axes.row) : [""];
  const colTerms = axes.col ? termOptions(axes.col) : [""];
  block.rules.forEach((r, j) => {
    const view = cells(r);
    const a = view && axes.row ? view.ins[axes.row] : "";
    const b = view && axes.col ? view.ins[axes.col] : "";
    if (view && rowTerms.includes(a) && colTerms.includes(b) && sameCondition(view, conditionOf(a, b))) {
      const key = `${a}\u0000${b}`;
      map.set(key, [...(map.get(key) || []), j]);
    } else outside++;
  });
  return { map, outside };
}

const PALETTE = ["#2166ac", "#4393c3", "#92c5de", "#d1e5f0", "#f7f7f7", "#fddbc7", "#f4a582", "#d6604d", "#b2182b"];
function colour(term) {
  const terms = termOptions(axes.output);
  const i = terms.indexOf(term);
  if (i < 0) return null;
  const k = terms.length === 1 ? 4 : Math.round((i * (PALETTE.length - 1)) / (terms.length - 1));
  return PALETTE[k];
}

function controls(container) {
  const ins = inputs().map((v) => v.name);
  const select = (id, names, value, blankLabel) => el("select", { id }, ...(blankLabel ? [el("option", { value: "" }, blankLabel)] : []), ...names.map((n) => el("option", { value: n, selected: n === value }, n)));
  const row = select("mx-row", ins, axes.row);
  const col = select("mx-col", ins.filter((n) => n !== axes.row), axes.col);
  const out = select("mx-output", outputs().map((v) => v.name), axes.output);
  row.addEventListener("change", () => ((axes.row = row.value), host.render()));
  col.addEventListener("change", () => ((axes.col = col.value), host.render()));
  out.addEventListener("change", () => ((axes.output = out.value), host.render()));
  const bar = el("div", { class: "row matrix-controls" }, el("label", {}, "Rows ", row), el("label", {}, "Columns ", col), el("label", {}, "Cells: output ", out));
  for (const name of ins.filter((n) => n !== axes.row && n !== axes.col)) {
    const held = select(`mx-fixed-${name}`, termOptions(name), axes.fixed[name] || "", "(not in the rule)");
    held.addEventListener("change", () => ((axes.fixed[name] = held.value), host.render()));
    bar.append(el("label", { title: "the slice of the rule base shown: rules with this term of the input, or without the input" }, `${name} `, held));
  }
  container.append(bar);
}

export function render(container) {
  pickAxes();
  container.replaceChildren();
  const block = host.block();
  if (!axes.row || !axes.output) {
    container.append(el("p", { class: "hint" }, "The matrix needs an input and an output."));
    return;
  }
  controls(container);
  const { map, outside } = index(block);
  const rowTerms = termOptions(axes.row);
  const colTerms = axes.col ? termOptions(axes.col) : [""];
  const table = el("table", { class: "matrix", id: "rule-matrix", role: "grid" });
  table.append(el("thead", {}, el("tr", {}, el("th", { class: "corner" }, `${axes.row} ↓ / ${axes.col || ""} →`), ...colTerms.map((b) => el("th", { scope: "col" }, b || axes.output)))));
  const tbody = el("tbody");
  const gaps = gapCells(axes.output, axes.row, axes.col, axes.fixed);
  for (const a of rowTerms) {
    const tr = el("tr", {}, el("th", { scope: "row" }, a));
    for (const b of colTerms) {
      const found = map.get(`${a}\u0000${b}`) || [];
      const terms = found.map((j) => cells(block.rules[j]).outs[axes.output]).filter(Boolean);
      const text = terms.length ? [...new Set(terms)].join(" | ") : "";
      const td = el("td", { tabindex: "0", "data-row": a, "data-col": b, "data-rules": found.join(" "), class: `${text ? "" : "empty"}${new Set(terms).size > 1 ? " conflict" : ""}`, "aria-label": `${axes.row} ${a}, ${axes.col || ""} ${b}: ${text || "no rule"}`, title: found.length ? found.map((j) => `rule ${block.rules[j].label}: ${ruleText(block.rules[j])}`).join("\n") : "no rule: click to add one" }, text || "·");
      const c = terms.length === 1 ? colour(terms[0]) : null;
      if (c) td.style.background = c;
      if (c && ["#2166ac", "#b2182b", "#4393c3", "#d6604d"].includes(c)) td.style.color = "#fff";
      const gap = gaps.get(`${a}\u0000${b}`);
      if (gap) {
        // a gap of the output reaches into this cell: a rule here would cover (part of) it
        td.classList.add("gap");
        td.title += `\ngap of ${axes.output} (no rule fires): ${gap.join("; ")}`;
      }
      tr.append(td);
    }
    tbody.append(tr);
  }
  table.append(tbody);
  container.append(table);
  const legend = el("div", { class: "matrix-legend", "aria-label": "output terms" }, el("span", {}, `${axes.output}:`));
  for (const t of termOptions(axes.output)) {
    const c = colour(t);
    legend.append(el("span", { style: `background:${c};${["#2166ac", "#b2182b", "#4393c3", "#d6604d"].includes(c) ? "color:#fff" : ""}` }, t));
  }
  container.append(legend);
  const between = gapsBetweenTerms(axes.output, axes.row, axes.col);
  if (gaps.size || between.length) {
    const text = [gaps.size ? `dashed cells: a gap of ${axes.output} (no rule fires) lies where their terms reach` : "", ...between.map((b) => `gap of ${axes.output} between terms (no term above 0): ${b}`)].filter(Boolean);
    container.append(el("p", { class: "hint matrix-gaps", id: "matrix-gaps" }, text.join(". ")));
  }
  container.append(el("p", { class: "hint", id: "matrix-note" }, `${block.rules.length - outside} of ${block.rules.length} rule(s) in this matrix${outside ? `; ${outside} other(s) (other inputs, NOT, OR, several terms of one input...) are in the Table and Text views` : ""}. Click a cell (or Enter) to choose the output term; -blank- removes it.`));
}

function setCell(a, b, term) {
  const block = host.block();
  const want = conditionOf(a, b);
  const found = block.rules.map((r, j) => [r, j]).filter(([r]) => sameCondition(cells(r), want));
  const holder = found.find(([r]) => cells(r).outs[axes.output]) || found[0];
  if (holder) {
    const [rule, j] = holder;
    const view = cells(rule);
    if (term) view.outs[axes.output] = term;
    else delete view.outs[axes.output];
    if (!Object.keys(view.outs).length) {
      block.rules.splice(j, 1);
      status(`removed rule ${rule.label}`);
    } else {
      fromCells(rule, view);
      status(`rule ${rule.label}: ${ruleText(rule)}`);
    }
  } else if (term) {
    const rule = { label: nextLabel(block), condition: null, conclusions: [], weight: null };
    fromCells(rule, { ins: want, neg: {}, outs: { [axes.output]: term } });
    block.rules.push(rule);
    status(`added rule ${rule.label}: ${ruleText(rule)}`);
  }
  changed("rules");
}

function openPicker(td) {
  if (td.querySelector("select")) return;
  const current = td.textContent.includes("|") || td.classList.contains("empty") ? "" : td.textContent;
  const picker = el("select", { "aria-label": `output term for ${td.dataset.row} ${td.dataset.col}` }, el("option", { value: "" }, "-blank-"), ...termOptions(axes.output).map((t) => el("option", { value: t, selected: t === current }, t)));
  picker.value = current;
  let done = false;
  const close = (apply) => {
    if (done) return;
    done = true;
    if (apply && picker.value !== current) setCell(td.dataset.row, td.dataset.col, picker.value);
    const row = td.dataset.row;
    const col = td.dataset.col;
    host.render();
    const again = document.querySelector(`#rule-matrix td[data-row="${CSS.escape(row)}"][data-col="${CSS.escape(col)}"]`);
    if (again && apply !== null) again.focus();
  };
  picker.addEventListener("change", () => close(true));
  picker.addEventListener("blur", () => close(null));
  picker.addEventListener("keydown", (e) => {
    if (e.key === "Escape") close(false);
  });
  td.replaceChildren(picker);
  picker.focus();
}

export function bind(container) {
  container.addEventListener("click", (e) => {
    const td = e.target.closest("#rule-matrix td");
    if (td && !e.target.closest("select")) openPicker(td);
  });
  container.addEventListener("keydown", (e) => {
    const td = e.target.closest("#rule-matrix td");
    if (!td || e.target.tagName === "SELECT") return;
    if (e.key === "Enter" || e.key === "F2" || e.key === " ") {
      e.preventDefault();
      openPicker(td);
      return;
    }
    const moves = { ArrowUp: [0, -1], ArrowDown: [0, 1], ArrowLeft: [-1, 0], ArrowRight: [1, 0] };
    if (!moves[e.key]) return;
    e.preventDefault();
    const [dx, dy] = moves[e.key];
    const row = td.parentElement;
    const i = [...row.children].indexOf(td);
    const target = dx ? row.children[i + dx] : (dy < 0 ? row.previousElementSibling : row.nextElementSibling)?.children[i];
    if (target && target.tagName === "TD") target.focus();
  });
}

/** Whether the matrix suits the model (two or more inputs). */
export function suits() {
  return inputs().length >= 2 && outputs().length >= 1 && !!fb();
}

/** Whether every rule of the block has a cell in the matrix (no OR, NOT, other inputs...):
 * only then is the matrix the view a file opens on. */
export function holdsAll() {
  if (!suits() || !host) return false;
  pickAxes();
  return index(host.block()).outside === 0;
}

export { axes as matrixAxes };
