// The rule viewer, in the manner of MATLAB's: one row per rule - for every input the term
// its condition reads, filled up to that term's degree, with the input value as a red line;
// for every output the set the rule's conclusion activates - and at the bottom the
// accumulated sets with the defuzzified values.  Inputs are set with the sliders, or by
// clicking / dragging in an input's column.  Everything is computed by the engine
// (/api/ruleview); the drawing clips nothing itself but the input terms' fill.
import { state, on, inputs, outputs, range, body, fmt, fmtVar, deg, status } from "./state.js";
import { post } from "./api.js";
import { $, el } from "./ui.js";

const NS = "http://www.w3.org/2000/svg";
let W = 132; // a cell's size: as wide as the view allows (MATLAB's columns fill the window)
let H = 40;
const values = {};
let inFlight = false;
let again = false;
let last = null;

function svg(tag, attrs = {}, text = null) {
  const node = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (text !== null) node.textContent = text;
  return node;
}

function scaleFor(name) {
  const [lo, hi] = range(name);
  const sx = (v) => 2 + ((v - lo) / (hi - lo || 1)) * (W - 4);
  const sy = (v) => H - 2 - Math.max(0, Math.min(1.1, v)) * (H - 6);
  return { sx, sy, lo, hi };
}

/** ``min(mu(x), level)`` of a polyline, with the crossings added (geometry only). */
function clip(points, level) {
  const out = [];
  for (let i = 0; i < points.length; i++) {
    const [x, y] = points[i];
    if (i > 0) {
      const [x0, y0] = points[i - 1];
      if ((y0 - level) * (y - level) < 0) out.push([x0 + ((level - y0) * (x - x0)) / (y - y0), level]);
    }
    out.push([x, Math.min(y, level)]);
  }
  return out;
}

function polygon(points, s, cls) {
  if (!points.length) return null;
  const pts = [[points[0][0], 0], ...points, [points[points.length - 1][0], 0]].map(([x, y]) => `${s.sx(x).toFixed(1)},${s.sy(y).toFixed(1)}`);
  return svg("polygon", { points: pts.join(" "), class: cls });
}

function polyline(points, s, cls = "mf") {
  return svg("polyline", { points: points.map(([x, y]) => `${s.sx(x).toFixed(1)},${s.sy(y).toFixed(1)}`).join(" "), class: cls });
}

function curveOf(variable, term) {
  const c = state.report && state.report.curves && state.report.curves[variable];
  return c ? c[term] : null;
}

function cellSvg(name, cls) {
  const root = svg("svg", { width: W, height: H, viewBox: `0 0 ${W} ${H}`, class: cls, "data-var": name });
  root.append(svg("line", { x1: 0, x2: W, y1: H - 2, y2: H - 2, class: "axis" }));
  return root;
}

function inputCell(name, lits) {
  const s = scaleFor(name);
  const root = cellSvg(name, "drag in-cell");
  let text = "";
  for (const lit of lits) {
    const curve = curveOf(name, lit.term);
    const d = lit.degree === null || lit.degree === undefined ? 0 : lit.negated ? 1 - lit.degree : lit.degree;
    if (curve && curve.points) {
      const pts = lit.negated ? curve.points.map(([x, y]) => [x, 1 - y]) : curve.points;
      const fill = polygon(clip(pts, d), s, "fill-in");
      if (fill) root.append(fill);
      root.append(polyline(pts, s));
      if (curve.lower) root.append(polyline(lit.negated ? curve.lower.map(([x, y]) => [x, 1 - y]) : curve.lower, s, "mf lower"));
    } else if (curve && curve.singleton !== undefined) {
      root.append(svg("line", { x1: s.sx(curve.singleton), x2: s.sx(curve.singleton), y1: s.sy(0), y2: s.sy(1), class: "mf" }));
    }
    // an interval type-2 term: its degree is an interval (NOT turns [l, u] into [1 - u, 1 - l])
    const shown = lit.lower === undefined ? deg(d) : lit.negated ? `${deg(1 - lit.degree)} … ${deg(1 - lit.lower)}` : `${deg(lit.lower)} … ${deg(d)}`;
    text += `${text ? ", " : ""}${lit.negated ? "NOT " : ""}${lit.term} ${shown}`;
  }
  if (values[name] !== undefined) root.append(svg("line", { x1: s.sx(values[name]), x2: s.sx(values[name]), y1: 0, y2: H, class: "value-line" }));
  root.append(svg("title", {}, lits.length ? `${name} IS ${text}` : `${name} is not in this rule`));
  return el("td", { class: "rv-in", "data-var": name }, root);
}

function outputCell(name, concls) {
  const s = scaleFor(name);
  const root = cellSvg(name, "out-cell");
  let text = "";
  for (const c of concls) {
    const curve = curveOf(name, c.term);
    const set = c.set;
    if (set && set.x) {
      const fill = polygon(set.x.map((x, i) => [x, set.y[i]]), s, "fill-out");
      if (fill) root.append(fill);
    }
    const lower = c.lower_set;
    if (lower && lower.x) {
      const fill = polygon(lower.x.map((x, i) => [x, lower.y[i]]), s, "fill-out-lower");
      if (fill) root.append(fill);
    }
    if (curve && curve.lower) root.append(polyline(curve.lower, s, "mf lower"));
    if (set && set.spikes) for (const [x, y] of set.spikes) root.append(svg("line", { x1: s.sx(x), x2: s.sx(x), y1: s.sy(0), y2: s.sy(y), class: "spike-out" }));
    if (curve && curve.points) root.append(polyline(curve.points, s));
    else if (curve && curve.singleton !== undefined) root.append(svg("line", { x1: s.sx(curve.singleton), x2: s.sx(curve.singleton), y1: s.sy(0), y2: s.sy(1), class: "mf" }));
    text += `${text ? ", " : ""}${c.term} ${deg(c.degree * c.weight)}`;
  }
  root.append(svg("title", {}, concls.length ? `${name} IS ${text}` : `${name} is not concluded by this rule`));
  return el("td", { class: "rv-out", "data-var": name }, root);
}

function totalCell(o) {
  const s = scaleFor(o.name);
  const root = cellSvg(o.name, "out-cell total");
  if (o.breakpoints && o.breakpoints.length) {
    const fill = polygon(o.breakpoints, s, "fill-out");
    if (fill) root.append(fill);
  }
  for (const [x, y] of o.singletons || []) root.append(svg("line", { x1: s.sx(x), x2: s.sx(x), y1: s.sy(0), y2: s.sy(y), class: "spike-out" }));
  if (o.interval) root.append(polygon([[o.interval[0], 1], [o.interval[1], 1]], s, "fill-interval")); // the type-reduced interval
  if (o.value !== null && o.value !== undefined) root.append(svg("line", { x1: s.sx(o.value), x2: s.sx(o.value), y1: 0, y2: H, class: "value-line" }));
  return el("td", { class: "rv-total", "data-var": o.name, "data-value": o.value ?? "" }, root, el("div", { class: "num", id: `rv-value-${o.name}` }, `${o.name} = ${fmtVar(o.name, o.value)}`));
}

function draw(view) {
  const ins = inputs();
  const outs = outputs();
  const room = ($("#rv-grid").clientWidth || 1000) - 330 - 70 - 20;
  W = Math.round(Math.max(120, Math.min(280, room / Math.max(1, ins.length + outs.length))));
  H = view.rules.length <= 12 ? 56 : 40;
  const onlyFired = $("#rv-filter").value === "fired";
  const table = el("table", { class: "rv-table", id: "rv-table" });
  table.append(el("thead", {}, el("tr", {}, el("th", {}, "Rule"), ...ins.map((v) => el("th", {}, `${v.name}`)), el("th", {}, "degree"), ...outs.map((v) => el("th", {}, v.name)))));
  const tbody = el("tbody");
  let shown = 0;
  for (const row of view.rules) {
    if (onlyFired && !(row.degree > 0)) continue;
    shown++;
    const tr = el("tr", { class: row.degree > 0 ? "fired" : null, "data-label": row.label }, el("th", { class: "rule", scope: "row", title: row.text }, `${row.label}. ${row.text}`));
    for (const v of ins) tr.append(inputCell(v.name, row.literals.filter((l) => l.variable === v.name)));
    tr.append(el("td", { class: "deg" }, !row.evaluated ? "—" : row.lower === undefined ? deg(row.degree) : `${deg(row.lower)} … ${deg(row.degree)}`));
    for (const v of outs) tr.append(outputCell(v.name, row.conclusions.filter((c) => c.variable === v.name)));
    tbody.append(tr);
  }
  const total = el("tr", { class: "total" }, el("th", { class: "rule", scope: "row" }, "accumulated, defuzzified"));
  for (const v of ins) total.append(el("td", { class: "num" }, `${v.name} = ${fmtVar(v.name, values[v.name])}`));
  total.append(el("td", {}, ""));
  for (const v of outs) {
    const o = view.outputs.find((x) => x.name === v.name);
    total.append(o ? totalCell(o) : el("td", {}, "—"));
  }
  tbody.append(total);
  table.append(tbody);
  $("#rv-grid").replaceChildren(table);
  $("#rv-note").textContent = `${shown} of ${view.rules.length} rule(s) shown; yellow: the term up to its degree, blue: the activated output set, red: the input values and the outputs. Click or drag in an input's column to move it.`;
}

async function refresh() {
  if (!state.doc || $("#view-ruleviewer").hidden) return;
  if (inFlight) {
    again = true;
    return;
  }
  inFlight = true;
  again = false;
  try {
    const point = {};
    for (const v of inputs()) point[v.name] = values[v.name];
    last = await post("/api/ruleview", body({ inputs: point }), { quiet: true });
    draw(last);
    $("#view-ruleviewer").dataset.outputs = JSON.stringify(Object.fromEntries(last.outputs.map((o) => [o.name, o.value])));
    // the result stays in view beside the sliders too (the bottom row may be scrolled away)
    $("#rv-result").textContent = last.outputs.map((o) => `${o.name} = ${fmtVar(o.name, o.value)}`).join(",  ");
  } catch (err) {
    status(err.message, "error");
  } finally {
    inFlight = false;
    if (again) refresh();
  }
}

/** Set input ``name``; ``snap``: a value from the slider or the mouse, rounded to a
 * thousandth of the range (what the number field then shows, not 14.1132). */
function setValue(name, v, snap = false) {
  const [lo, hi] = range(name);
  const clamped = Math.max(lo, Math.min(hi, v));
  values[name] = snap ? parseFloat(fmt(clamped, 4, hi - lo)) : clamped;
  const slider = $(`#rv-slider-${CSS.escape(name)}`);
  const number = $(`#rv-in-${CSS.escape(name)}`);
  if (slider) slider.value = values[name];
  if (number && document.activeElement !== number) number.value = Number(values[name].toPrecision(6));
  refresh();
}

function renderInputs() {
  const row = $("#rv-inputs");
  row.replaceChildren();
  for (const v of inputs()) {
    const [lo, hi] = range(v.name);
    if (!(v.name in values) || values[v.name] < lo || values[v.name] > hi) values[v.name] = (lo + hi) / 2;
    const slider = el("input", { type: "range", min: lo, max: hi, step: (hi - lo) / 500, value: values[v.name], id: `rv-slider-${v.name}`, "aria-label": `${v.name} slider` });
    const number = el("input", { type: "number", step: "any", value: Number(values[v.name].toPrecision(6)), size: 8, id: `rv-in-${v.name}`, "aria-label": v.name });
    slider.addEventListener("input", () => setValue(v.name, parseFloat(slider.value), true));
    number.addEventListener("change", () => Number.isFinite(parseFloat(number.value)) && setValue(v.name, parseFloat(number.value)));
    row.append(el("label", {}, `${v.name} `, slider, number));
  }
  row.append(el("span", { class: "sep" }), el("strong", { id: "rv-result", class: "num" }, ""));
}

function valueAt(event, svgNode) {
  const name = svgNode.dataset.var;
  const rect = svgNode.getBoundingClientRect();
  const s = scaleFor(name);
  const x = ((event.clientX - rect.left) / rect.width) * W;
  return [name, s.lo + ((x - 2) / (W - 4)) * (s.hi - s.lo)];
}

export function init() {
  let dragging = null;
  const grid = $("#rv-grid");
  grid.addEventListener("pointerdown", (e) => {
    const node = e.target.closest("svg.in-cell");
    if (!node || e.button !== 0) return;
    e.preventDefault();
    dragging = node;
    const [name, v] = valueAt(e, node);
    setValue(name, v, true);
  });
  window.addEventListener("pointermove", (e) => {
    if (!dragging) return;
    const [name, v] = valueAt(e, dragging);
    setValue(name, v, true);
  });
  window.addEventListener("pointerup", () => (dragging = null));
  $("#rv-filter").addEventListener("change", () => last && draw(last));
  on("model", () => !$("#view-ruleviewer").hidden && (renderInputs(), refresh()));
  on("loaded", () => {
    for (const k of Object.keys(values)) delete values[k];
    $("#rv-filter").value = "all";
  });
}

export function shown() {
  if (!state.doc) return;
  const count = state.doc.blocks[state.block].rule_blocks.reduce((n, rb) => n + rb.rules.length, 0);
  if (count > 60 && !$("#rv-filter").dataset.touched) $("#rv-filter").value = "fired";
  $("#rv-filter").addEventListener("change", () => ($("#rv-filter").dataset.touched = "true"), { once: true });
  renderInputs();
  refresh();
}
