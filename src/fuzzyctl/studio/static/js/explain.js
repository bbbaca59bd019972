// Explain any point: the selected output's accumulated set (or its singletons) with the
// defuzzified value on top, then every term degree and every rule - labelled with its
// text - with its degree and conclusions, as the engine computes them (fuzzyctl explain).
import { state, on, inputs, outputs, range, body, fmt, deg, fmtVar, status, fb } from "./state.js";
import { post } from "./api.js";
import { $, el, plot, COLORS } from "./ui.js";
import { ruleText } from "./rules-model.js";

const values = {};
let output = null;
let timer = null;

function bar(v) {
  const pct = Math.max(0, Math.min(1, v || 0)) * 100;
  return el("span", { class: "bar", style: `--w:${pct}%` });
}

/** The model's rule for an explained rule (block name and label). */
export function modelRule(blockName, label) {
  const b = fb();
  if (!b) return null;
  for (const rb of b.rule_blocks) {
    if ((rb.name || null) !== (blockName || null)) continue;
    const r = rb.rules.find((x) => x.label === label);
    if (r) return r;
  }
  return null;
}

/** [value, term name] of the singleton terms of ``output``. */
function singletonNames(output) {
  const b = fb();
  const d = b && b.defuzzify.find((x) => x.variable === output);
  return d ? d.terms.filter((t) => t.mf.type === "singleton" && typeof t.mf.value === "number").map((t) => [t.mf.value, t.name]) : [];
}

function renderInputs() {
  const row = $("#ex-inputs");
  row.replaceChildren();
  for (const v of inputs()) {
    const [lo, hi] = range(v.name);
    if (!(v.name in values)) values[v.name] = (lo + hi) / 2;
    const input = el("input", { type: "number", step: "any", value: values[v.name], size: 8, id: `ex-in-${v.name}`, "aria-label": v.name });
    input.addEventListener("input", () => {
      const x = parseFloat(input.value);
      if (Number.isFinite(x)) {
        values[v.name] = x;
        schedule();
      }
    });
    row.append(el("label", { title: `range ${fmt(lo)} … ${fmt(hi)}` }, `${v.name} `, input));
  }
  const select = el("select", { id: "ex-output", "aria-label": "output" }, ...outputs().map((o) => el("option", { value: o.name, selected: o.name === output }, o.name)));
  select.addEventListener("change", () => {
    output = select.value;
    schedule();
  });
  row.append(el("label", {}, "Output ", select));
  if (!outputs().some((o) => o.name === output)) output = outputs()[0] && outputs()[0].name;
}

function schedule() {
  clearTimeout(timer);
  timer = setTimeout(run, 100);
}

export async function run() {
  if (!state.doc || $("#view-explain").hidden) return;
  const point = {};
  for (const v of inputs()) point[v.name] = values[v.name];
  let e;
  try {
    e = await post("/api/explain", body({ inputs: point }));
  } catch (err) {
    status(err.message, "error");
    return;
  }
  const terms = $("#ex-terms tbody");
  // an interval type-2 system: each degree is an interval, lower … upper
  const shown = (x) => (x.lower === undefined ? deg(x.degree) : `${deg(x.lower)} … ${deg(x.degree)}`);
  terms.replaceChildren(...e.terms.map((t) => el("tr", { class: t.degree > 0 ? "fired" : null }, el("td", {}, t.variable), el("td", {}, t.term), el("td", { class: "num" }, shown(t)), el("td", {}, bar(t.degree)))));
  const rules = $("#ex-rules tbody");
  rules.replaceChildren(
    ...e.rules.map((r) => {
      const rule = modelRule(r.block, r.label);
      const text = rule ? ruleText(rule) : r.conclusions.map((c) => `${c.variable} IS ${c.term}`).join(", ");
      return el("tr", { class: r.degree > 0 ? "fired" : null }, el("td", { class: "num", title: r.block ? `rule block ${r.block}` : null }, r.label), el("td", { class: "num" }, shown(r)), el("td", {}, bar(r.degree)), el("td", { class: "mono rule-text" }, text));
    }),
  );
  const o = e.outputs.find((x) => x.name === output) || e.outputs[0];
  if (!o) return;
  const [lo, hi] = range(o.name);
  const value = o.value;
  const label = `${o.name} = ${fmtVar(o.name, value)}`;
  // the result first, so that a singleton at the same place is drawn over it; its marker
  // below the axis and its label above the chart read apart from the singletons
  const traces = [];
  if (typeof value === "number") traces.push({ x: [value, value], y: [0, 1.08], mode: "lines", line: { color: COLORS[1], dash: "dot", width: 1.5 }, hoverinfo: "skip", name: label });
  if (o.interval) {
    const [yl, yr] = o.interval;
    traces.push({ x: [yl, yl, yr, yr], y: [0, 1, 1, 0], mode: "lines", fill: "toself", fillcolor: "rgba(31,119,180,0.2)", line: { color: COLORS[0] }, name: "type-reduced interval" });
  }
  if (o.breakpoints && o.breakpoints.length) traces.push({ x: o.breakpoints.map((p) => p[0]), y: o.breakpoints.map((p) => p[1]), mode: "lines", fill: "tozeroy", line: { color: COLORS[0] }, name: "accumulated set" });
  const names = singletonNames(o.name);
  const marks = [];
  for (const [x, mu] of o.singletons || []) {
    if (!(mu > 0)) continue; // an unfired singleton has no bar (no line at 0 that reads as one)
    const term = names.filter(([v]) => Math.abs(v - x) <= 1e-9 * Math.max(1, Math.abs(x))).map(([, n]) => n).join("/") || fmt(x);
    traces.push({ x: [x, x], y: [0, mu], mode: "lines+markers", line: { color: COLORS[0], width: 5 }, marker: { size: 7 }, hoverinfo: "skip", name: term });
    marks.push({ x, y: mu, text: `${term} ${deg(mu)}` });
  }
  if (marks.length) traces.push({ x: marks.map((m) => m.x), y: marks.map((m) => m.y), text: marks.map((m) => m.text), mode: "text", textposition: "top center", textfont: { size: 13, color: "#111" }, hoverinfo: "skip", name: "terms" });
  if (typeof value === "number") traces.push({ x: [value], y: [-0.045], mode: "markers", marker: { symbol: "triangle-up", size: 15, color: COLORS[1] }, hoverinfo: "skip", name: "result" });
  const pad = 0.03 * (hi - lo);
  const annotations = typeof value === "number" ? [{ x: value, y: 1.17, text: `<b>${label}</b>`, showarrow: false, font: { color: COLORS[1], size: 14 }, bgcolor: "#fff", bordercolor: COLORS[1], borderpad: 3 }] : [];
  plot($("#ex-chart"), traces, { xaxis: { range: [Math.min(lo, value ?? lo) - pad, Math.max(hi, value ?? hi) + pad], zeroline: false, title: { text: `${o.name} (${o.method}); ▲ the result` }, nticks: 11, showgrid: true }, yaxis: { range: [-0.09, 1.25], tickvals: [0, 0.25, 0.5, 0.75, 1], zeroline: true, zerolinecolor: "#888", title: { text: "degree" } }, annotations, showlegend: false, margin: { l: 55, r: 20, t: 10, b: 45 } });
  $("#ex-chart").dataset.labels = JSON.stringify(marks);
  $("#ex-chart").dataset.value = String(o.value);
  $("#ex-chart").dataset.interval = o.interval ? JSON.stringify(o.interval) : "";
}

export function init() {
  on("model", () => !$("#view-explain").hidden && (renderInputs(), schedule()));
  on("loaded", () => {
    for (const k of Object.keys(values)) delete values[k];
  });
}

export function shown() {
  if (!state.doc) return;
  renderInputs();
  run();
}

export function focus(target) {
  if (target.inputs) Object.assign(values, target.inputs);
  renderInputs();
  run();
}
