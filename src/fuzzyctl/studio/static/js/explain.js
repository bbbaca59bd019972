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
  terms.replaceChildren(...e.terms.map((t) => el("tr", { class: t.degree > 0 ? "fired" : null }, el("td", {}, t.variable), el("td", {}, t.term), el("td", { class: "num" }, deg(t.degree)), el("td", {}, bar(t.degree)))));
  const rules = $("#ex-rules tbody");
  rules.replaceChildren(
    ...e.rules.map((r) => {
      const rule = modelRule(r.block, r.label);
      const text = rule ? ruleText(rule) : r.conclusions.map((c) => `${c.variable} IS ${c.term}`).join(", ");
      return el("tr", { class: r.degree > 0 ? "fired" : null }, el("td", { class: "num", title: r.block ? `rule block ${r.block}` : null }, r.label), el("td", { class: "num" }, deg(r.degree)), el("td", {}, bar(r.degree)), el("td", { class: "mono rule-text" }, text));
    }),
  );
  const o = e.outputs.find((x) => x.name === output) || e.outputs[0];
  if (!o) return;
  const traces = [];
  if (o.breakpoints && o.breakpoints.length) traces.push({ x: o.breakpoints.map((p) => p[0]), y: o.breakpoints.map((p) => p[1]), mode: "lines", fill: "tozeroy", line: { color: COLORS[0] }, name: "accumulated set" });
  for (const [x, mu] of o.singletons || []) traces.push({ x: [x, x], y: [0, mu], mode: "lines+markers", line: { color: COLORS[0], width: 4 }, name: `singleton ${fmt(x)}` });
  const [lo, hi] = range(o.name);
  traces.push({ x: [o.value, o.value], y: [0, 1.05], mode: "lines", line: { color: COLORS[1], dash: "dash" }, name: `${o.name} = ${fmtVar(o.name, o.value)}` });
  plot($("#ex-chart"), traces, { xaxis: { range: [Math.min(lo, o.value ?? lo), Math.max(hi, o.value ?? hi)], title: { text: `${o.name} = ${fmtVar(o.name, o.value)} (${o.method})` }, nticks: 10 }, yaxis: { range: [0, 1.1], title: { text: "degree" } }, showlegend: false, margin: { l: 55, r: 20, t: 10, b: 45 } });
  $("#ex-chart").dataset.value = String(o.value);
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
