// Project view (manual 6.2, 6.3): the function block as a block diagram filling the view -
// inputs with their terms drawn small, their ranges and term counts, the rule blocks with
// their operators and rule counts, outputs with method and default - and beside it a
// summary of the whole model, including what the graphical editors do not edit (local
// variables, other function blocks, OPTIONS, expressions, hedges, weights ...): shown
// and kept, never silently dropped.  A click (or Enter) opens the editor of a part.
import { state, on, emit, fb, inputs, outputs, diagnosticsFor, changed, termNames, evenTerms, range, status, num } from "./state.js";
import { $, el, COLORS } from "./ui.js";
import { kindOf } from "./terms.js";
import { cells, termOptions } from "./rules-model.js";
import { relayout } from "./panes.js";

const NS = "http://www.w3.org/2000/svg";
function svg(tag, attrs = {}, text = null) {
  const node = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (text !== null) node.textContent = text;
  return node;
}

const GAP = 18;
let observer = null;

/** The terms of a variable drawn small (the report's curves) inside its box. */
function sparkline(parent, name, x, y, w, h) {
  const curves = (state.report && state.report.curves && state.report.curves[name]) || {};
  const [lo, hi] = range(name);
  const sx = (v) => x + ((v - lo) / (hi - lo || 1)) * w;
  const sy = (v) => y + h - Math.max(0, Math.min(1.05, v)) * h;
  parent.append(svg("line", { x1: x, y1: y + h, x2: x + w, y2: y + h, class: "spark-axis" }));
  Object.entries(curves).forEach(([, c], i) => {
    const color = COLORS[i % COLORS.length];
    if (c.points) {
      const pts = c.points.filter((p) => p[0] >= lo - 1e-9 && p[0] <= hi + 1e-9).map((p) => `${sx(p[0]).toFixed(1)},${sy(p[1]).toFixed(1)}`);
      if (pts.length) parent.append(svg("polyline", { points: pts.join(" "), class: "spark", stroke: color }));
    } else if (c.singleton !== undefined) {
      parent.append(svg("line", { x1: sx(c.singleton), x2: sx(c.singleton), y1: y + h, y2: y, class: "spark", stroke: color }));
    } else if (c.spikes) {
      for (const [px, py] of c.spikes) parent.append(svg("line", { x1: sx(px), x2: sx(px), y1: y + h, y2: sy(py), class: "spark", stroke: color }));
    }
  });
}

/** A rule block of two inputs drawn small as its matrix: a cell per pair of terms,
 * coloured by the output term its rule concludes (the Rules view's colours). */
function miniMatrix(parent, rb, x, y, w, h) {
  const ins = inputs();
  const outs = outputs();
  if (ins.length !== 2 || !outs.length) return;
  const rowsT = termOptions(ins[0].name);
  const colsT = termOptions(ins[1].name);
  const outT = termOptions(outs[0].name);
  if (!rowsT.length || !colsT.length || !outT.length) return;
  const size = Math.min(w / colsT.length, h / rowsT.length);
  const palette = ["#2166ac", "#4393c3", "#92c5de", "#d1e5f0", "#f7f7f7", "#fddbc7", "#f4a582", "#d6604d", "#b2182b"];
  const colour = (t) => {
    const i = outT.indexOf(t);
    return i < 0 ? null : palette[outT.length === 1 ? 4 : Math.round((i * (palette.length - 1)) / (outT.length - 1))];
  };
  const filled = new Map();
  for (const r of rb.rules) {
    const c = cells(r);
    if (!c || Object.keys(c.ins).length !== 2 || !c.outs[outs[0].name]) continue;
    filled.set(`${c.ins[ins[0].name]}\u0000${c.ins[ins[1].name]}`, c.outs[outs[0].name]);
  }
  rowsT.forEach((a, i) =>
    colsT.forEach((b, j) => {
      const t = filled.get(`${a}\u0000${b}`);
      parent.append(svg("rect", { x: x + j * size, y: y + i * size, width: size - 1, height: size - 1, fill: (t && colour(t)) || "#eef2f6", class: "mini-cell" }));
    }),
  );
}

function marks(g, id, x, y, w) {
  // a variable's box also carries the diagnostics of its terms
  const diags = id.startsWith("var:") ? [...diagnosticsFor(id), ...diagnosticsFor(`term:${id.slice(4)}`)] : diagnosticsFor(id);
  if (!diags.length) return;
  const bad = diags.some((d) => d.severity === "error");
  g.append(svg("circle", { cx: x + w - 4, cy: y + 4, r: 10, class: bad ? "mark error" : "mark warning" }));
  g.append(svg("text", { x: x + w - 4, y: y + 8, "text-anchor": "middle", class: "mark-text" }, String(diags.length)));
  g.append(svg("title", {}, diags.map((d) => `${d.severity}: ${d.message}`).join("\n")));
}

function box(parent, { x, y, w, h, label, lines, kind, id, onOpen, spark, rb }) {
  const sparkH = Math.max(26, h - 50 - 17 * lines.length);
  const g = svg("g", { class: `node ${kind}`, tabindex: "0", role: "button", "aria-label": `${kind} ${label}`, "data-id": id });
  g.append(svg("rect", { x, y, width: w, height: h, rx: 7, class: "box" }));
  g.append(svg("text", { x: x + 12, y: y + 22, class: "label" }, label));
  lines.forEach((line, i) => g.append(svg("text", { x: x + 12, y: y + 42 + i * 17, class: "sub" }, line)));
  if (spark) sparkline(g, spark, x + 12, y + h - sparkH - 8, w - 24, sparkH);
  if (kind === "rules" && rb) miniMatrix(g, rb, x + 12, y + h - sparkH - 8, w - 24, sparkH);
  marks(g, id, x, y, w);
  g.addEventListener("click", onOpen);
  g.addEventListener("keydown", (e) => (e.key === "Enter" || e.key === " ") && (e.preventDefault(), onOpen()));
  parent.append(g);
}

function wire(parent, x1, y1, x2, y2) {
  const mid = (x1 + x2) / 2;
  parent.append(svg("path", { d: `M${x1},${y1} C${mid},${y1} ${mid},${y2} ${x2},${y2}`, class: "wire" }));
}

function rangeText(name) {
  const [lo, hi] = range(name);
  return `${num(lo)} … ${num(hi)}`;
}

function renderDiagram() {
  const host = $("#diagram");
  host.replaceChildren();
  const b = fb();
  if (!b) {
    host.textContent = "No project: New (Alt+N) or Open (Ctrl+O).";
    return;
  }
  const ins = inputs();
  const outs = outputs();
  const blocks = b.rule_blocks.length ? b.rule_blocks : [{ name: "(no rule block)", rules: [] }];
  const rows = Math.max(ins.length, outs.length, blocks.length, 1);
  // drawn at the size of the view, one unit a pixel: the text stays readable and the
  // boxes (and the terms drawn in them) grow with the space there is
  const W = Math.max(640, host.clientWidth || 1000);
  const avail = Math.max(300, host.clientHeight || 500);
  const BOX_W = Math.round(Math.max(200, Math.min(360, W * 0.29)));
  const BOX_H = Math.round(Math.max(96, Math.min(210, (avail - 70) / rows - GAP)));
  const H = Math.max(avail, rows * (BOX_H + GAP) + 70);
  const root = svg("svg", { viewBox: `0 0 ${W} ${H}`, width: W, height: H, role: "group", "aria-label": `function block ${b.name}` });
  const column = (n, k) => 50 + ((H - 60 - n * (BOX_H + GAP)) / 2) + k * (BOX_H + GAP);
  const top = column(rows, 0) - 44;
  const bottom = column(rows, rows - 1) + BOX_H + 16;
  root.append(svg("rect", { x: BOX_W + 40, y: top, width: W - 2 * BOX_W - 80, height: bottom - top, rx: 12, class: "fb" }));
  root.append(svg("text", { x: W / 2, y: top + 24, "text-anchor": "middle", class: "fb-name" }, `FUNCTION_BLOCK ${b.name || ""}`));
  const ruleW = Math.round(Math.max(170, Math.min(320, W - 2 * BOX_W - 110)));
  const ruleX = (W - ruleW) / 2;
  blocks.forEach((rb, i) => {
    const y = column(blocks.length, i);
    const mid = y + BOX_H / 2;
    ins.forEach((v, k) => wire(root, 10 + BOX_W, column(ins.length, k) + BOX_H / 2, ruleX, mid));
    outs.forEach((v, k) => wire(root, ruleX + ruleW, mid, W - 10 - BOX_W, column(outs.length, k) + BOX_H / 2));
    const ops = [rb.and_op && `AND ${rb.and_op}`, rb.or_op && `OR ${rb.or_op}`, rb.act && `ACT ${rb.act}`, rb.accu && `ACCU ${rb.accu}`].filter(Boolean);
    // the operators on one line, or two when they would not fit the box
    const opLines = !ops.length ? ["operators: IEC defaults"] : ops.join(" · ").length * 7.2 < ruleW - 24 ? [ops.join(" · ")] : [ops.slice(0, 2).join(" · "), ops.slice(2).join(" · ")];
    box(root, { x: ruleX, y, w: ruleW, h: BOX_H, rb, label: "If … Then", lines: [`${rb.name || "rules"}: ${rb.rules.length} rule(s)${rb.enabled === false ? " (disabled)" : ""}`, ...opLines], kind: "rules", id: `ruleblock:${i}`, onOpen: () => emit("show", { view: "rules", target: { block: i, rule: null } }) });
  });
  ins.forEach((v, k) => {
    const blk = b.fuzzify.find((f) => f.variable === v.name);
    const n = blk ? blk.terms.length : 0;
    box(root, { x: 10, y: column(ins.length, k), w: BOX_W, h: BOX_H, label: v.name, lines: [`${n} term(s) · ${rangeText(v.name)}`], kind: "input", id: `var:${v.name}`, spark: v.name, onOpen: () => emit("show", { view: "variable", target: { name: v.name } }) });
  });
  outs.forEach((v, k) => {
    const blk = b.defuzzify.find((d) => d.variable === v.name);
    const n = blk ? blk.terms.length : 0;
    const d = blk && blk.default;
    const dflt = !d ? "" : d.value === null ? ", DEFAULT NC" : `, DEFAULT ${num(d.value)}${d.no_change ? " | NC" : ""}`;
    box(root, { x: W - 10 - BOX_W, y: column(outs.length, k), w: BOX_W, h: BOX_H, label: v.name, lines: [`${n} term(s) · ${rangeText(v.name)}`, `${blk && blk.method ? blk.method : "COG"}${dflt}`], kind: "output", id: `var:${v.name}`, spark: v.name, onOpen: () => emit("show", { view: "variable", target: { name: v.name } }) });
  });
  host.append(root);
}

// --- the summary -------------------------------------------------------------------------

function walk(cond, fn) {
  if (!cond) return;
  fn(cond);
  if (cond.type === "not") walk(cond.operand, fn);
  else if (cond.operands) cond.operands.forEach((c) => walk(c, fn));
}

/** What the model holds beyond what the graphical editors show as cells and handles. */
export function beyondEditors(doc, b) {
  const out = [];
  const locals = b.variables.filter((v) => v.kind === "VAR");
  if (locals.length) out.push(`local variables (VAR): ${locals.map((v) => v.name).join(", ")}`);
  if (doc.blocks.length > 1) out.push(`${doc.blocks.length - 1} other function block(s): ${doc.blocks.filter((x) => x !== b).map((x) => x.name || "(unnamed)").join(", ")} (Function block picker above)`);
  if (b.options.length) out.push(`${b.options.length} OPTIONS block(s) (kept as written)`);
  const fnTerms = [];
  const refTerms = [];
  for (const blk of [...b.fuzzify, ...b.defuzzify]) {
    for (const t of blk.terms) {
      if (kindOf(t.mf) === "function") fnTerms.push(`${blk.variable}.${t.name}`);
      if (JSON.stringify(t.mf).includes('"type":"ref"')) refTerms.push(`${blk.variable}.${t.name}`);
    }
    if (blk.clamp) out.push(`${blk.variable}: clamped to its range (lock-range)`);
  }
  if (fnTerms.length) out.push(`expression terms: ${fnTerms.join(", ")}`);
  if (refTerms.length) out.push(`terms with parameters given by variables: ${refTerms.join(", ")}`);
  let hedges = 0;
  let weights = 0;
  let complex = 0;
  for (const rb of b.rule_blocks) {
    if (rb.enabled === false) out.push(`rule block ${rb.name || ""} is disabled`);
    if (rb.rule_activation) out.push(`rule block ${rb.name || ""}: rule activation ${rb.rule_activation}`);
    for (const r of rb.rules) {
      let isComplex = false;
      walk(r.condition, (c) => {
        if (c.type === "or" || c.type === "not" || c.type === "degree") isComplex = true;
        if (c.hedges && c.hedges.length) hedges++;
      });
      if (r.conclusions.some((c) => c.weight !== null && c.weight !== undefined) || (r.weight !== null && r.weight !== undefined)) weights++;
      if (r.conclusions.some((c) => c.hedges && c.hedges.length)) hedges++;
      if (isComplex) complex++;
    }
  }
  if (complex) out.push(`${complex} rule(s) with OR, NOT or a degree condition (as text in the rule table)`);
  if (hedges) out.push(`${hedges} hedge(s) in rules`);
  if (weights) out.push(`${weights} weighted rule(s)`);
  return out;
}

function renderSummary() {
  const host = $("#model-summary");
  const b = fb();
  host.replaceChildren();
  if (!b) return;
  host.className = "pane side-pane summary";
  const table = (head, rows) => el("table", {}, el("thead", {}, el("tr", {}, ...head.map((h) => el("th", {}, h)))), el("tbody", {}, ...rows.map((r) => el("tr", {}, ...r.map((c, i) => el("td", { class: i && /^[-\d.…\s]+$/.test(String(c)) ? "num" : null }, c))))));
  host.append(el("h3", {}, `Function block ${b.name || ""}`));
  host.append(el("h3", {}, "Inputs"), table(["name", "range", "terms"], inputs().map((v) => {
    const blk = b.fuzzify.find((f) => f.variable === v.name);
    return [v.name, rangeText(v.name), blk ? blk.terms.map((t) => t.name).join(", ") : "—"];
  })));
  host.append(el("h3", {}, "Outputs"), table(["name", "range", "method", "default"], outputs().map((v) => {
    const blk = b.defuzzify.find((d) => d.variable === v.name) || {};
    const d = blk.default;
    return [v.name, rangeText(v.name), blk.method || "COG", !d ? "—" : d.value === null ? "NC" : `${num(d.value)}${d.no_change ? " | NC" : ""}`];
  })));
  host.append(el("h3", {}, "Rule blocks"), table(["name", "rules", "operators"], b.rule_blocks.map((rb) => [rb.name || "—", String(rb.rules.length), [rb.and_op && `AND ${rb.and_op}`, rb.or_op && `OR ${rb.or_op}`, rb.act && `ACT ${rb.act}`, rb.accu && `ACCU ${rb.accu}`].filter(Boolean).join(", ") || "defaults"])));
  const beyond = beyondEditors(state.doc, b);
  host.append(el("h3", {}, "Also in the model (kept)"));
  host.append(beyond.length ? el("ul", { id: "beyond-list" }, ...beyond.map((x) => el("li", {}, x))) : el("p", { class: "hint", id: "beyond-list" }, "Nothing beyond what the editors show."));
  if (state.report && state.report.level) host.append(el("p", { class: "hint" }, `Conformance level ${state.report.level}: the Check panel lists the features that need it.`));
  const losses = (state.report && state.report.fcl_losses) || [];
  if (losses.length) host.append(el("h3", { class: "losses" }, "Saving as FCL drops"), el("ul", { class: "losses", id: "fcl-losses" }, ...losses.map((l) => el("li", {}, l))));
}

function render() {
  if ($("#view-project").hidden) return;
  renderDiagram();
  renderSummary();
}

function uniqueName(prefix) {
  const names = new Set(fb().variables.map((v) => v.name));
  let i = 1;
  while (names.has(`${prefix}${i}`)) i++;
  return `${prefix}${i}`;
}

function addVariable(isOutput) {
  const b = fb();
  if (!b) return;
  const name = uniqueName(isOutput ? "output" : "input");
  const kind = isOutput ? "VAR_OUTPUT" : "VAR_INPUT";
  // inserted at the end of its kind, as the manual's Edit menu does
  let at = b.variables.length;
  for (let i = b.variables.length - 1; i >= 0; i--) if (b.variables[i].kind === kind) { at = i + 1; break; }
  b.variables.splice(at, 0, { name, kind, data_type: "REAL", initial: null, range: null });
  const terms = evenTerms(5, -100, 100, isOutput, termNames(5, isOutput));
  if (isOutput) b.defuzzify.push({ variable: name, terms, range: null, method: "COGS", default: { value: null, no_change: true }, accu: null, clamp: false });
  else b.fuzzify.push({ variable: name, terms, range: null, clamp: false });
  state.settings.ranges = { ...(state.settings.ranges || {}), [name]: [-100, 100] };
  changed("structure");
  status(`added ${name}`);
}

function deleteLast(isOutput) {
  const b = fb();
  const list = isOutput ? outputs() : inputs();
  if (!b || list.length <= 1) return status("a function block keeps at least one input and one output", "error");
  const name = list[list.length - 1].name;
  b.variables = b.variables.filter((v) => v.name !== name);
  b.fuzzify = b.fuzzify.filter((f) => f.variable !== name);
  b.defuzzify = b.defuzzify.filter((d) => d.variable !== name);
  // the variable's parts leave every rule; a rule left without a conclusion goes
  for (const rb of b.rule_blocks) {
    rb.rules = rb.rules
      .map((r) => ({ ...r, condition: dropVariable(r.condition, name), conclusions: r.conclusions.filter((c) => c.variable !== name) }))
      .filter((r) => r.conclusions.length && r.condition);
  }
  if (state.settings.ranges) delete state.settings.ranges[name];
  changed("structure");
  status(`deleted ${name} (and its parts of the rules)`);
}

function dropVariable(cond, name) {
  if (!cond) return cond;
  if (cond.type === "is" || cond.type === "degree") return cond.variable === name ? null : cond;
  if (cond.type === "not") {
    const inner = dropVariable(cond.operand, name);
    return inner ? { ...cond, operand: inner } : null;
  }
  const ops = cond.operands.map((c) => dropVariable(c, name)).filter(Boolean);
  if (!ops.length) return null;
  return ops.length === 1 ? ops[0] : { ...cond, operands: ops };
}

export function init() {
  on("model", render);
  on("report", render);
  observer = new ResizeObserver(() => !$("#view-project").hidden && renderDiagram());
  observer.observe($("#diagram"));
  $("#btn-add-input").addEventListener("click", () => addVariable(false));
  $("#btn-add-output").addEventListener("click", () => addVariable(true));
  $("#btn-del-input").addEventListener("click", () => deleteLast(false));
  $("#btn-del-output").addEventListener("click", () => deleteLast(true));
}
export function shown() {
  render();
  relayout();
}
