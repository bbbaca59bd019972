// Input and output editors (manual 6.4 and MATLAB's membership function editor): name,
// value range with the manual's two questions, terms (insert, delete, rename, "insert N"
// evenly spread), and every term kind the engine reads - points, singletons, triangle,
// trapezoid, Gaussian, bell, sigmoid ... and expressions - with a field per parameter,
// the term as FCL text, handles to drag on the chart (singletons and spikes as lines),
// every curve labelled, zoom in five steps.
import { state, on, fb, inputs, outputs, termBlock, range, changed, diagnosticsFor, evenTerms, termNames, isIdentifier, isInput, num, status, bodyWithoutRules } from "./state.js";
import { post } from "./api.js";
import { nameWarning } from "./names.js";
import { $, el, confirmDialog, fillDiagnostics, plot, COLORS } from "./ui.js";
import { footprintTraces, renderLower } from "./footprint.js";
import { SHAPES, kindOf, kindLabel, kinds, handles, placeOf, convert, paramName, readParam, paramText, positions, rescale, localCurve } from "./terms.js";

let current = null; // variable name
let term = 0; // index of the selected term
let point = 0; // index of the selected handle
let zoom = 0; // 0..5: the view is 2^zoom times narrower, centred on the selected point
let dragging = null;

const chart = () => $("#mf-chart");

function variableNames() {
  return [...inputs(), ...outputs()].map((v) => v.name);
}

function selected() {
  const blk = current ? termBlock(current) : null;
  return { blk, t: blk && blk.terms[term] ? blk.terms[term] : null };
}

function serverCurve(name) {
  const curves = (state.report && state.report.curves && state.report.curves[current]) || {};
  return curves[name] || {};
}

function curveOf(t, lo, hi) {
  const local = localCurve(t, lo, hi);
  if (local) return local;
  if (t.mf.type === "shape" && t.mf.kind === "constant" && typeof t.mf.params[0] === "number") return { singleton: t.mf.params[0] };
  return serverCurve(t.name);
}

function viewRange() {
  const [lo, hi] = range(current);
  if (!zoom) return [lo, hi];
  const { t } = selected();
  const h = t ? handles(t) : [];
  const centre = h[point] ? h[point].x : (lo + hi) / 2;
  const half = (hi - lo) / 2 / 2 ** zoom;
  return [centre - half, centre + half];
}

// --- the chart -------------------------------------------------------------------------

function labels(blk, lo, hi, view) {
  const placed = [];
  const span = view[1] - view[0];
  return blk.terms
    .map((t, i) => {
      const curve = curveOf(t, lo, hi);
      if (curve.text !== undefined && curve.points === undefined) return null;
      const { c } = placeOf(curve, lo, hi);
      const x = Math.max(view[0] + span * 0.03, Math.min(view[1] - span * 0.03, c));
      // labels closer than 7 % of the view step up, so neighbours never cover each other
      let level = 0;
      while (placed.some((p) => p.level === level && Math.abs(p.x - x) < span * 0.07)) level++;
      placed.push({ x, level });
      return { x, y: 1.04 + 0.065 * Math.min(level, 4), text: t.name, showarrow: false, font: { color: COLORS[i % COLORS.length], size: i === term ? 14 : 12 }, xanchor: "center" };
    })
    .filter(Boolean);
}

function renderChart() {
  const node = chart();
  const blk = current ? termBlock(current) : null;
  if (!blk) {
    if (window.Plotly) Plotly.purge(node);
    return;
  }
  const [lo, hi] = range(current);
  const view = viewRange();
  const traces = [];
  blk.terms.forEach((t, i) => {
    const active = i === term;
    const color = COLORS[i % COLORS.length];
    const curve = curveOf(t, lo, hi);
    const line = { color, width: active ? 3.5 : 1.6 };
    if (curve.singleton !== undefined) {
      traces.push({ x: [curve.singleton, curve.singleton], y: [0, 1], mode: "lines", line, name: t.name });
    } else if (curve.points) {
      traces.push({ x: curve.points.map((p) => p[0]), y: curve.points.map((p) => p[1]), mode: "lines", line, name: t.name });
      if (t.lower) traces.push(...footprintTraces(t.name, curve.points, serverCurve(t.name).lower, color, active));
    } else if (curve.spikes) {
      for (const [x, y] of curve.spikes) traces.push({ x: [x, x], y: [0, y], mode: "lines", line, name: t.name });
    }
    if (active) {
      const h = handles(t);
      traces.push({
        x: h.map((p) => p.x),
        y: h.map((p) => p.y),
        mode: "markers",
        marker: { size: h.map((_, k) => (k === point ? 15 : 10)), color: "#fff", line: { color, width: 2.5 } },
        name: `${t.name} handles`,
      });
    }
  });
  plot(node, traces, {
    xaxis: { range: view, fixedrange: true, zeroline: false, title: { text: current }, nticks: 10 },
    yaxis: { range: [-0.04, 1.33], fixedrange: true, title: { text: "degree of membership" }, tickvals: [0, 0.25, 0.5, 0.75, 1] },
    dragmode: false,
    hovermode: false,
    annotations: labels(blk, lo, hi, view),
    margin: { l: 55, r: 20, t: 10, b: 45 },
  }, { displayModeBar: false });
}

// --- the term panel ----------------------------------------------------------------------

function field(labelText, value, onChange, attrs = {}) {
  const input = el("input", { value, spellcheck: "false", "aria-label": labelText, ...attrs });
  input.addEventListener("change", () => onChange(input.value, input));
  input.addEventListener("keydown", (e) => e.key === "Enter" && (e.preventDefault(), input.dispatchEvent(new Event("change"))));
  return [el("label", { for: attrs.id || null }, labelText), input];
}

function renderParams(t) {
  const box = $("#term-params");
  box.replaceChildren();
  const mf = t.mf;
  const isOut = !isInput(current);
  if (mf.type === "singleton") {
    box.append(...field("value", paramText(mf.value), (v, input) => setParam(() => (mf.value = readParam(v)), input), { id: "param-0" }));
  } else if (mf.type === "shape") {
    const spec = SHAPES[mf.kind] || { params: [] };
    mf.params.forEach((p, i) => {
      box.append(...field(paramName(mf.kind, i), paramText(p), (v, input) => setParam(() => (mf.params[i] = readParam(v)), input), { id: `param-${i}`, title: spec.summary || "" }));
    });
    if (!["constant", "linear"].includes(mf.kind)) box.append(...field("height", paramText(mf.height), (v, input) => setParam(() => (mf.height = readParam(v)), input), { id: "param-height", title: "scales the shape (fuzzylite's height)" }));
  }
  $("#term-summary").textContent = mf.type === "shape" ? `${mf.kind}: ${(SHAPES[mf.kind] || {}).summary || ""}` : mf.type === "points" ? "IEC points: linear between the points, constant beyond the first and the last" : mf.type === "singleton" ? "a singleton (manual: a line on the output's axis)" : mf.type === "singletons" ? "singletons: degree y at each x, 0 elsewhere" : "an expression of the inputs: edit it in the FCL field";
  if (isOut && mf.type === "function") $("#term-summary").textContent += " (Takagi-Sugeno output)";
}

function setParam(apply, input) {
  const before = JSON.stringify(selected().t.mf);
  apply();
  const mf = selected().t.mf;
  const values = mf.type === "shape" ? [...mf.params, mf.height] : [mf.value];
  if (values.some((v) => v === undefined)) {
    selected().t.mf = JSON.parse(before);
    input.classList.add("bad");
    status("a parameter is a number or the name of a variable", "error");
    return;
  }
  changed("points");
}

function renderPoints(t) {
  const tbody = $("#points-table tbody");
  tbody.replaceChildren();
  const mf = t.mf;
  const list = mf.type === "points" || mf.type === "singletons" ? mf.points : null;
  $("#points-table").hidden = !list;
  $("#point-add").parentElement.hidden = !list;
  if (!list) return;
  list.forEach((p, k) => {
    const x = el("input", { type: "text", inputmode: "decimal", value: paramText(p.x), "aria-label": `point ${k + 1} x`, size: 8 });
    x.addEventListener("change", () => {
      const v = readParam(x.value);
      if (v === undefined) return;
      p.x = v;
      point = k;
      changed("points");
    });
    const y = el("input", { type: "text", inputmode: "decimal", value: paramText(p.y), "aria-label": `point ${k + 1} degree`, size: 5 });
    y.addEventListener("change", () => {
      const v = readParam(y.value);
      if (v === undefined || (typeof v === "number" && (v < 0 || v > 1))) return status("a degree is between 0 and 1 (or a variable)", "error");
      p.y = v;
      changed("points");
    });
    const row = el("tr", { class: k === point ? "selected" : null }, el("td", {}, String(k + 1)), el("td", {}, x), el("td", {}, y));
    row.addEventListener("focusin", () => (point = k));
    tbody.append(row);
  });
}

function renderTerm() {
  const { t } = selected();
  $("#term-editor").disabled = !t;
  if (!t) {
    $("#term-params").replaceChildren();
    $("#points-table tbody").replaceChildren();
    return;
  }
  if (document.activeElement !== $("#term-name")) $("#term-name").value = t.name;
  const kind = kindOf(t.mf);
  const list = kinds(!isInput(current));
  if (!list.includes(kind)) list.push(kind);
  $("#term-kind").replaceChildren(...list.map((k) => el("option", { value: k, selected: k === kind }, kindLabel(k))));
  renderParams(t);
  renderPoints(t);
  renderLower(t, current, { changed: () => changed("points"), status, body: bodyWithoutRules, diagnostics: diagnosticsFor(`term:${current}:${t.name}`) });
  const fcl = serverCurve(t.name).fcl;
  const field = $("#term-fcl");
  const key = `${current}\u0000${t.name}`;
  if (field.dataset.term !== key) {
    // another term: its own text, whatever was typed for the last one
    field.dataset.term = key;
    field.classList.remove("bad");
    $("#term-fcl-diags").replaceChildren();
    field.value = fcl ?? "";
  } else if (document.activeElement !== field && fcl !== undefined && !field.classList.contains("bad")) field.value = fcl;
}

function render() {
  const names = variableNames();
  if (!names.includes(current)) current = names[0] || null;
  const select = $("#var-select");
  select.replaceChildren(...names.map((n) => el("option", { value: n, selected: n === current }, `${isInput(n) ? "input" : "output"}: ${n}`)));
  const blk = current ? termBlock(current) : null;
  if (!blk) {
    renderChart();
    return;
  }
  if (term >= blk.terms.length) term = Math.max(0, blk.terms.length - 1);
  // A field being typed in keeps its text when a check's report redraws the view.
  if (document.activeElement !== $("#var-name")) $("#var-name").value = current;
  const [lo, hi] = range(current);
  if (document.activeElement !== $("#var-min")) $("#var-min").value = lo;
  if (document.activeElement !== $("#var-max")) $("#var-max").value = hi;
  const termSelect = $("#term-select");
  termSelect.size = Math.max(2, Math.min(8, blk.terms.length));
  termSelect.replaceChildren(...blk.terms.map((t, i) => el("option", { value: i, selected: i === term, title: kindLabel(kindOf(t.mf)) }, t.name)));
  const isOut = !isInput(current);
  $("#out-options").hidden = !isOut;
  if (isOut) {
    $("#out-method").value = blk.method || "COG";
    const d = blk.default;
    if (document.activeElement !== $("#out-default")) $("#out-default").value = !d ? "" : d.no_change && d.value === null ? "NC" : d.value === null ? "" : String(d.value);
  }
  renderChart();
  renderTerm();
  fillDiagnostics($("#var-diags"), [...diagnosticsFor(`var:${current}`), ...diagnosticsFor(`term:${current}`)]);
}

// --- renaming and rules ------------------------------------------------------------

function eachCondition(cond, fn) {
  if (!cond) return;
  if (cond.type === "is" || cond.type === "degree") fn(cond);
  else if (cond.type === "not") eachCondition(cond.operand, fn);
  else cond.operands.forEach((c) => eachCondition(c, fn));
}

function renameVariable(oldName, newName) {
  const b = fb();
  for (const v of b.variables) if (v.name === oldName) v.name = newName;
  for (const blk of [...b.fuzzify, ...b.defuzzify]) if (blk.variable === oldName) blk.variable = newName;
  for (const rb of b.rule_blocks) {
    for (const r of rb.rules) {
      eachCondition(r.condition, (c) => c.variable === oldName && (c.variable = newName));
      for (const c of r.conclusions) if (c.variable === oldName) c.variable = newName;
    }
  }
  const s = state.settings;
  if (s.ranges && s.ranges[oldName]) {
    s.ranges[newName] = s.ranges[oldName];
    delete s.ranges[oldName];
  }
  if (s.recorder) {
    s.recorder.curves = (s.recorder.curves || []).map((c) => (c === oldName ? newName : c));
    if (s.recorder.signals && s.recorder.signals[oldName]) {
      s.recorder.signals[newName] = s.recorder.signals[oldName];
      delete s.recorder.signals[oldName];
    }
  }
}

function renameTerm(variable, oldName, newName) {
  const b = fb();
  for (const rb of b.rule_blocks) {
    for (const r of rb.rules) {
      eachCondition(r.condition, (c) => c.variable === variable && c.term === oldName && (c.term = newName));
      for (const c of r.conclusions) if (c.variable === variable && c.term === oldName) c.term = newName;
    }
  }
}

/** Remove references to terms of ``variable`` that no longer exist (the table cells
 * become blank, as in the manual); returns how many rules changed. */
function blankMissingTerms(variable) {
  const b = fb();
  const names = new Set(termBlock(variable).terms.map((t) => t.name));
  let count = 0;
  const keep = (c) => !(c.type === "is" && c.variable === variable && !names.has(c.term));
  const prune = (cond) => {
    if (!cond) return cond;
    if (cond.type === "is" || cond.type === "degree") return keep(cond) ? cond : null;
    if (cond.type === "not") {
      const inner = prune(cond.operand);
      return inner ? { ...cond, operand: inner } : null;
    }
    const ops = cond.operands.map(prune).filter(Boolean);
    if (!ops.length) return null;
    return ops.length === 1 ? ops[0] : { ...cond, operands: ops };
  };
  for (const rb of b.rule_blocks) {
    rb.rules = rb.rules.map((r) => {
      const condition = prune(r.condition);
      const conclusions = r.conclusions.filter((c) => !(c.variable === variable && c.term !== null && !names.has(c.term)));
      if (JSON.stringify(condition) !== JSON.stringify(r.condition) || conclusions.length !== r.conclusions.length) count++;
      return { ...r, condition, conclusions };
    });
    rb.rules = rb.rules.filter((r) => r.condition && r.conclusions.length);
  }
  return count;
}

// --- actions -------------------------------------------------------------------------

async function setRange() {
  const lo = parseFloat($("#var-min").value);
  const hi = parseFloat($("#var-max").value);
  if (!(Number.isFinite(lo) && Number.isFinite(hi) && lo < hi)) return status("the minimum must be below the maximum", "error");
  const [oldLo, oldHi] = range(current);
  const blk = termBlock(current);
  const xs = blk.terms.flatMap((t) => positions(t.mf));
  let adjust = false;
  if (xs.some((x) => x < lo || x > hi)) {
    const answer = await confirmDialog("Change the value range", "There are some points outside the selected range. Adjust all membership functions?", [["cancel", "Cancel"], ["ok", "OK"]]);
    if (answer !== "ok") return render();
    adjust = true;
  } else if (lo < oldLo || hi > oldHi) {
    const answer = await confirmDialog("Change the value range", "Should the membership functions be adjusted to the new range of values?", [["no", "No"], ["yes", "Yes"]]);
    adjust = answer === "yes";
  }
  if (adjust) {
    const k = (hi - lo) / (oldHi - oldLo);
    for (const t of blk.terms) {
      rescale(t.mf, (x) => lo + (x - oldLo) * k, k);
      if (t.lower && t.lower.mf) rescale(t.lower.mf, (x) => lo + (x - oldLo) * k, k); // an explicit lower function moves with it
    }
  }
  if (blk.range) blk.range = { low: lo, high: hi };
  else state.settings.ranges = { ...(state.settings.ranges || {}), [current]: [lo, hi] };
  // the new range shows at once; the check confirms it
  if (state.report) state.report.ranges = { ...state.report.ranges, [current]: [lo, hi] };
  changed("range");
  status(`${current}: range ${num(lo)} … ${num(hi)}${adjust ? ", membership functions adjusted" : ""}`);
}

function insertTerm() {
  const blk = termBlock(current);
  const [lo, hi] = range(current);
  const names = blk.terms.map((t) => t.name);
  let k = blk.terms.length + 1;
  while (names.includes(`MBF_${k}`)) k++;
  const mid = (lo + hi) / 2;
  const w = (hi - lo) / 8;
  const r6 = (v) => Math.round(v * 1e6) / 1e6;
  const mf = isInput(current)
    ? { type: "points", points: [{ x: r6(mid - w), y: 0 }, { x: r6(mid), y: 1 }, { x: r6(mid + w), y: 0 }] }
    : { type: "singleton", value: r6(mid) };
  blk.terms.push({ name: `MBF_${k}`, mf });
  term = blk.terms.length - 1;
  point = 0;
  changed("terms");
}

async function deleteTerm() {
  const blk = termBlock(current);
  if (!blk.terms[term]) return;
  const name = blk.terms[term].name;
  blk.terms.splice(term, 1);
  term = Math.max(0, term - 1);
  const n = blankMissingTerms(current);
  changed("terms");
  status(`deleted term ${name}${n ? `; ${n} rule(s) lost it` : ""}`);
}

async function insertN() {
  const input = el("input", { type: "number", min: 1, max: 7, value: 5, id: "insert-n" });
  const answer = await confirmDialog("Insert membership functions", el("label", {}, "Number of membership functions (at most 7) ", input), [["cancel", "Cancel"], ["ok", "OK"]]);
  if (answer !== "ok") return;
  const n = Math.max(1, Math.min(7, parseInt(input.value, 10) || 5));
  const blk = termBlock(current);
  const [lo, hi] = range(current);
  const out = !isInput(current);
  blk.terms = evenTerms(n, lo, hi, out, termNames(n, out));
  term = 0;
  point = 0;
  const lost = blankMissingTerms(current);
  changed("terms");
  status(`${n} terms spread over ${num(lo)} … ${num(hi)}${lost ? `; ${lost} rule(s) referred to the old terms` : ""}`);
}

function changeKind(kind) {
  const { t } = selected();
  if (!t || kindOf(t.mf) === kind) return;
  const [lo, hi] = range(current);
  const mf = convert(kind, placeOf(curveOf(t, lo, hi), lo, hi), inputs().length);
  if (!mf) {
    $("#term-fcl").focus();
    status("write the expression in the FCL field (FUNCTION ...), then Enter", "info");
    renderTerm();
    return;
  }
  t.mf = mf;
  point = 0;
  changed("points");
  status(`${t.name} is a ${kindLabel(kind)} now: set its parameters or drag its handles`);
}

async function applyFcl() {
  const { t } = selected();
  const input = $("#term-fcl");
  if (!t || !input.value.trim()) return;
  let result;
  try {
    result = await post("/api/term/parse", bodyWithoutRules({ variable: current, text: input.value }));
  } catch (err) {
    fillDiagnostics($("#term-fcl-diags"), [{ severity: "error", message: err.message }]);
    input.classList.add("bad");
    return;
  }
  fillDiagnostics($("#term-fcl-diags"), result.diagnostics.map((d) => ({ ...d, line: null, message: `${d.column ? `column ${d.column}: ` : ""}${d.message}` })), { onClick: () => input.focus() });
  input.classList.toggle("bad", !result.ok);
  if (!result.ok) return;
  t.mf = result.mf;
  point = 0;
  changed("points");
  status(`${t.name} := ${input.value.trim()}`);
}

function addPoint(remove) {
  const { t } = selected();
  if (!t || (t.mf.type !== "points" && t.mf.type !== "singletons")) return;
  const pts = t.mf.points;
  if (remove) {
    if (pts.length <= 1) return status("a term keeps at least one point", "error");
    pts.splice(Math.min(point, pts.length - 1), 1);
    point = Math.max(0, point - 1);
  } else {
    const at = Math.min(point, pts.length - 1);
    const next = pts[at + 1];
    const here = pts[at];
    const [lo, hi] = range(current);
    const x = next && typeof next.x === "number" ? (here.x + next.x) / 2 : Math.min(hi, here.x + (hi - lo) / 20);
    pts.splice(at + 1, 0, { x: Math.round(x * 1e6) / 1e6, y: typeof here.y === "number" ? here.y : 0 });
    point = at + 1;
  }
  changed("points");
}

// --- dragging ------------------------------------------------------------------------

function axes() {
  const layout = chart()._fullLayout;
  return layout ? { xa: layout.xaxis, ya: layout.yaxis } : null;
}

function nearestHandle(event) {
  const ax = axes();
  if (!ax) return null;
  const rect = chart().getBoundingClientRect();
  const px = event.clientX - rect.left;
  const py = event.clientY - rect.top;
  const blk = termBlock(current);
  let best = null;
  blk.terms.forEach((t, i) => {
    handles(t).forEach((p, k) => {
      const hx = ax.xa.l2p(p.x) + ax.xa._offset;
      const dx = Math.abs(hx - px);
      // a singleton is a line: grab it anywhere along its height
      const top = p.line ? Math.max(p.y, 0.05) : p.y;
      const yAt = p.line ? Math.min(top, Math.max(0, ax.ya.p2l(py - ax.ya._offset))) : p.y;
      const hy = ax.ya.l2p(yAt) + ax.ya._offset;
      const d = Math.hypot(dx, hy - py) + (i === term ? 0 : 3); // prefer the selected term
      if (d < 14 && (!best || d < best.d)) best = { i, k, d };
    });
  });
  return best;
}

function onDown(event) {
  if (event.button !== 0 || !current) return;
  const hit = nearestHandle(event);
  if (!hit) return;
  event.preventDefault();
  term = hit.i;
  point = hit.k;
  dragging = { pointerId: event.pointerId };
  chart().setPointerCapture?.(event.pointerId);
  render();
}

function onMove(event) {
  if (!dragging) return;
  const ax = axes();
  const rect = chart().getBoundingClientRect();
  let x = ax.xa.p2l(event.clientX - rect.left - ax.xa._offset);
  const [lo, hi] = viewRange();
  x = Math.min(hi, Math.max(lo, x));
  const digits = Math.max(0, 3 - Math.floor(Math.log10(Math.max(1e-9, hi - lo))));
  x = Number(x.toFixed(Math.min(8, digits)));
  const { t } = selected();
  const h = handles(t);
  if (!h[point]) return;
  h[point].set(x);
  renderChart();
  renderParams(t);
  renderPoints(t);
  changed("points", { quiet: true });
}

function onUp() {
  if (!dragging) return;
  dragging = null;
  changed("points");
}

function onKey(event) {
  const { t } = selected();
  const h = t ? handles(t) : [];
  if (!h.length) return;
  const [lo, hi] = viewRange();
  const step = (hi - lo) / (event.shiftKey ? 1000 : 100);
  if (event.key === "ArrowLeft" || event.key === "ArrowRight") {
    event.preventDefault();
    const p = h[Math.min(point, h.length - 1)];
    p.set(Number((p.x + (event.key === "ArrowRight" ? step : -step)).toPrecision(10)));
    changed("points");
  } else if (event.key === "ArrowUp" || event.key === "ArrowDown") {
    event.preventDefault();
    point = (point + (event.key === "ArrowUp" ? 1 : h.length - 1)) % h.length;
    render();
  } else if (event.key === "+" || event.key === "-") {
    zoom = Math.max(0, Math.min(5, zoom + (event.key === "+" ? 1 : -1)));
    render();
  }
}

export function init() {
  on("model", () => !$("#view-variable").hidden && !dragging && render());
  on("report", () => {
    if ($("#view-variable").hidden) return;
    if (dragging) renderChart(); // the engine's curve of a smooth shape follows the drag
    else render();
  });
  on("loaded", () => {
    current = null;
    term = 0;
    point = 0;
    zoom = 0;
  });
  $("#var-select").addEventListener("change", (e) => {
    current = e.target.value;
    term = 0;
    point = 0;
    zoom = 0;
    render();
  });
  $("#var-name").addEventListener("change", (e) => {
    const name = e.target.value.trim();
    if (name === current) return;
    const refuse = (message) => ((e.target.value = current), status(message, "error"), render());
    if (!isIdentifier(name)) return refuse(`${name}: a name is a letter or _ followed by letters, digits or _`);
    if (variableNames().includes(name)) return refuse(`${name} exists already`);
    renameVariable(current, name);
    current = name;
    changed("rename");
    const warn = nameWarning("variable", name);
    if (warn) status(warn, "warning");
  });
  $("#term-select").addEventListener("change", (e) => {
    term = +e.target.value;
    point = 0;
    $("#term-fcl").classList.remove("bad");
    $("#term-fcl-diags").replaceChildren();
    render();
  });
  $("#term-name").addEventListener("change", (e) => {
    const blk = termBlock(current);
    const name = e.target.value.trim();
    const old = blk.terms[term].name;
    if (name === old) return;
    const refuse = (message) => ((e.target.value = old), status(message, "error"), render());
    if (!isIdentifier(name)) return refuse(`${name}: not a valid term name`);
    if (blk.terms.some((t) => t.name === name)) return refuse(`${current} has a term ${name} already`);
    blk.terms[term].name = name;
    renameTerm(current, old, name);
    changed("rename");
    const warn = nameWarning("term", name);
    if (warn) status(warn, "warning");
  });
  $("#term-kind").addEventListener("change", (e) => changeKind(e.target.value));
  $("#term-fcl").addEventListener("keydown", (e) => e.key === "Enter" && (e.preventDefault(), applyFcl()));
  $("#term-fcl").addEventListener("change", applyFcl);
  $("#point-add").addEventListener("click", () => addPoint(false));
  $("#point-del").addEventListener("click", () => addPoint(true));
  $("#var-range-apply").addEventListener("click", setRange);
  $("#term-insert").addEventListener("click", insertTerm);
  $("#term-delete").addEventListener("click", deleteTerm);
  $("#term-insert-n").addEventListener("click", insertN);
  $("#zoom-in").addEventListener("click", () => ((zoom = Math.min(5, zoom + 1)), render()));
  $("#zoom-out").addEventListener("click", () => ((zoom = Math.max(0, zoom - 1)), render()));
  $("#zoom-reset").addEventListener("click", () => ((zoom = 0), render()));
  $("#out-method").addEventListener("change", (e) => {
    termBlock(current).method = e.target.value;
    changed("method");
  });
  $("#out-default").addEventListener("change", (e) => {
    const raw = e.target.value.trim();
    const blk = termBlock(current);
    if (!raw) blk.default = null;
    else if (raw.toUpperCase() === "NC") blk.default = { value: null, no_change: true };
    else if (Number.isFinite(parseFloat(raw))) blk.default = { value: parseFloat(raw), no_change: false };
    else return status("DEFAULT is a number or NC", "error");
    changed("default");
  });
  const node = chart();
  node.addEventListener("pointerdown", onDown, true);
  node.addEventListener("pointermove", onMove);
  node.addEventListener("pointerup", onUp);
  node.addEventListener("pointercancel", onUp);
  node.addEventListener("keydown", onKey);
}

export function shown() {
  render();
}

export function focus(target) {
  if (target.name) current = target.name;
  const blk = termBlock(current);
  if (target.term && blk) term = Math.max(0, blk.terms.findIndex((t) => t.name === target.term));
  point = 0;
  render();
}
