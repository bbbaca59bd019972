// The project being edited: the model in fuzzyctl's JSON form, the studio settings, the
// last check report, and a small event bus the views listen to.
import { post } from "./api.js";

export const state = {
  doc: null, // {format, version, blocks: [...]}
  block: 0,
  settings: {},
  path: null, // relative to the project directory; null: not saved yet
  sha: null, // of the file as opened/saved (conflict check)
  dirty: false,
  report: null, // {ok, diagnostics, level, features, text, ranges, curves}
  textError: null, // the text editor holds text that does not parse
  info: null,
};

const listeners = {};
export function on(event, fn) {
  (listeners[event] ||= []).push(fn);
}
export function emit(event, data) {
  for (const fn of listeners[event] || []) {
    try {
      fn(data);
    } catch (err) {
      console.warn(err);
    }
  }
}

export function fb() {
  return state.doc ? state.doc.blocks[state.block] : null;
}
export function variables(kind) {
  const b = fb();
  return b ? b.variables.filter((v) => v.kind === kind) : [];
}
export const inputs = () => variables("VAR_INPUT");
export const outputs = () => variables("VAR_OUTPUT");
export function isInput(name) {
  return inputs().some((v) => v.name === name);
}
export function termBlock(name) {
  const b = fb();
  if (!b) return null;
  return b.fuzzify.find((f) => f.variable === name) || b.defuzzify.find((d) => d.variable === name) || null;
}
export function range(name) {
  const r = state.report && state.report.ranges && state.report.ranges[name];
  return r || [-100, 100];
}
export function diagnosticsFor(prefix) {
  const r = state.report;
  if (!r) return [];
  return r.diagnostics.filter((d) => d.element && (d.element === prefix || d.element.startsWith(prefix + ":")));
}

// --- model changes -------------------------------------------------------------------

let timer = null;
let seq = 0;
/** Something in the model changed: views redraw now, the check runs shortly after. */
export function changed(what = "model", { quiet = false } = {}) {
  state.dirty = true;
  if (!quiet) emit("model", what);
  emit("dirty", true);
  clearTimeout(timer);
  timer = setTimeout(recheck, 150);
}

export async function recheck() {
  if (!state.doc) return;
  const mine = ++seq;
  try {
    const request = body();
    const map = ruleMap;
    const report = await post("/api/check", request);
    if (mine !== seq) return; // a newer check is on its way
    for (const d of report.diagnostics) {
      const m = /^rule:(\d+):(\d+)$/.exec(d.element || "");
      if (m && map[+m[1]]) d.element = `rule:${m[1]}:${map[+m[1]][+m[2]]}`;
    }
    state.report = report;
    state.textError = null;
    emit("report", report);
  } catch (err) {
    if (mine !== seq) return;
    state.report = { ok: false, diagnostics: [{ severity: "error", message: err.message, element: null }], level: null, ranges: (state.report || {}).ranges || {}, curves: (state.report || {}).curves || {} };
    emit("report", state.report);
  }
}

let ruleMap = [];
/** The model part of every analysis request.  Rules the table holds without a THEN part
 * yet are left out (they do nothing, manual 1.5); ``ruleMap`` turns the indices of the
 * rules sent back into the table's. */
export function body(extra = {}) {
  const doc = JSON.parse(JSON.stringify(state.doc));
  const b = doc.blocks[state.block];
  ruleMap = [];
  if (b) {
    b.rule_blocks.forEach((rb, i) => {
      const kept = [];
      const map = [];
      rb.rules.forEach((r, j) => {
        if (r.conclusions.length) { // no IF part: degree 1 (manual 1.5); no THEN part: no effect
          kept.push(r);
          map.push(j);
        }
      });
      rb.rules = kept;
      ruleMap[i] = map;
    });
  }
  return { document: doc, block: state.block, settings: cleanSettings(), ...extra };
}

export function cleanSettings() {
  const s = JSON.parse(JSON.stringify(state.settings || {}));
  for (const key of Object.keys(s)) if (s[key] === null || s[key] === undefined) delete s[key];
  return s;
}

export function load(result, { path = result.path, sha = result.sha256 } = {}) {
  state.doc = result.document;
  state.block = 0;
  state.settings = result.settings || {};
  state.path = path;
  state.sha = sha;
  state.dirty = false;
  state.report = { ok: result.ok, diagnostics: result.diagnostics || [], level: result.level, features: result.features || [], text: result.text, ranges: result.ranges || {}, curves: {} };
  emit("loaded", result);
  emit("model", "all");
  emit("dirty", false);
  recheck();
}

// --- term helpers ------------------------------------------------------------------

/** The draggable handles of a term: [{x, y, set(x)}] or null when the term is not a
 * constant point list, singleton, triangle or trapezoid (edited as text then). */
export function handles(term) {
  const mf = term.mf;
  const num = (v) => typeof v === "number";
  if (mf.type === "points" && mf.points.every((p) => num(p.x) && num(p.y))) {
    return mf.points.map((p) => ({ x: p.x, y: p.y, set: (x) => (p.x = x) }));
  }
  if (mf.type === "singleton" && num(mf.value)) {
    return [{ x: mf.value, y: 1, set: (x) => (mf.value = x), singleton: true }];
  }
  if (mf.type === "shape" && (mf.kind === "triangle" || mf.kind === "trapezoid") && mf.params.every(num)) {
    const ys = mf.kind === "triangle" ? [0, 1, 0] : [0, 1, 1, 0];
    return mf.params.map((x, i) => ({ x, y: ys[i], set: (v) => (mf.params[i] = v) }));
  }
  return null;
}

/** Points to draw for a term from the local model (live while dragging), extended flat
 * to the range ends as IEC defines; null: use the server's curve. */
export function localCurve(term, lo, hi) {
  const h = handles(term);
  if (!h) return null;
  if (h[0].singleton) return { singleton: h[0].x };
  const pts = h.map((p) => [p.x, p.y]).sort((a, b) => a[0] - b[0]);
  if (term.mf.type === "shape") {
    // a shape is 0 outside its support
    return { points: [[Math.min(lo, pts[0][0]), 0], ...pts, [Math.max(hi, pts[pts.length - 1][0]), 0]] };
  }
  return { points: [[Math.min(lo, pts[0][0]), pts[0][1]], ...pts, [Math.max(hi, pts[pts.length - 1][0]), pts[pts.length - 1][1]]] };
}

export const SIEMENS_INPUT_NAMES = { 1: ["zero"], 2: ["low", "high"], 3: ["neg", "zero", "pos"], 4: ["n_big", "n_small", "p_small", "p_big"], 5: ["n_big", "n_small", "zero", "p_small", "p_big"], 6: ["n_big", "n_medium", "n_small", "p_small", "p_medium", "p_big"], 7: ["n_big", "n_medium", "n_small", "zero", "p_small", "p_medium", "p_big"] };
export const SIEMENS_OUTPUT_NAMES = { 1: ["zero"], 2: ["low", "high"], 3: ["neg", "zero", "pos"], 4: ["n_large", "n_small", "p_small", "p_large"], 5: ["n_large", "n_small", "zero", "p_small", "p_large"], 6: ["n_large", "n_medium", "n_small", "p_small", "p_medium", "p_large"], 7: ["n_large", "n_medium", "n_small", "zero", "p_small", "p_medium", "p_large"] };

const r6 = (v) => Math.round(v * 1e6) / 1e6;

/** N terms evenly spread over [lo, hi] (manual 6.4): triangles with shoulders at the ends
 * for an input, singletons for an output. */
export function evenTerms(n, lo, hi, isOutput, names) {
  const terms = [];
  if (isOutput) {
    for (let i = 0; i < n; i++) {
      const x = n === 1 ? (lo + hi) / 2 : lo + ((hi - lo) * i) / (n - 1);
      terms.push({ name: names[i], mf: { type: "singleton", value: r6(x) } });
    }
    return terms;
  }
  if (n === 1) return [{ name: names[0], mf: { type: "points", points: [{ x: lo, y: 1 }, { x: hi, y: 1 }] } }];
  const step = (hi - lo) / (n - 1);
  for (let i = 0; i < n; i++) {
    const c = lo + step * i;
    let pts;
    if (i === 0) pts = [{ x: r6(c), y: 1 }, { x: r6(c + step), y: 0 }];
    else if (i === n - 1) pts = [{ x: r6(c - step), y: 0 }, { x: r6(c), y: 1 }];
    else pts = [{ x: r6(c - step), y: 0 }, { x: r6(c), y: 1 }, { x: r6(c + step), y: 0 }];
    terms.push({ name: names[i], mf: { type: "points", points: pts } });
  }
  return terms;
}

export function termNames(n, isOutput, existing = []) {
  const base = (isOutput ? SIEMENS_OUTPUT_NAMES : SIEMENS_INPUT_NAMES)[Math.min(n, 7)] || [];
  const names = [];
  for (let i = 0; i < n; i++) {
    let name = base[i] || `MBF_${i + 1}`;
    let k = 2;
    while (existing.includes(name) || names.includes(name)) name = `${base[i] || "MBF"}_${k++}`;
    names.push(name);
  }
  return names;
}

/** A new project as the manual's "Define Project" dialog makes it (6.2). */
export function newDocument(name, nIn, nOut) {
  const variables = [];
  const fuzzify = [];
  const defuzzify = [];
  for (let i = 1; i <= nIn; i++) {
    variables.push({ name: `input${i}`, kind: "VAR_INPUT", data_type: "REAL", initial: null, range: null });
    fuzzify.push({ variable: `input${i}`, terms: evenTerms(5, -100, 100, false, termNames(5, false)), range: null, clamp: false });
  }
  for (let i = 1; i <= nOut; i++) {
    variables.push({ name: `output${i}`, kind: "VAR_OUTPUT", data_type: "REAL", initial: null, range: null });
    defuzzify.push({ variable: `output${i}`, terms: evenTerms(5, -100, 100, true, termNames(5, true)), range: null, method: "COGS", default: { value: null, no_change: true }, accu: null, clamp: false });
  }
  return {
    format: "fuzzyctl-model",
    version: 1,
    blocks: [{ name, variables, fuzzify, defuzzify, rule_blocks: [{ name: "rules", rules: [], and_op: "MIN", or_op: null, act: null, accu: "MAX", enabled: true, rule_activation: null }], options: [] }],
  };
}

export function isIdentifier(name) {
  return /^[A-Za-z_][A-Za-z0-9_]*$/.test(name);
}

export function fmt(v, digits = 5) {
  if (v === null || v === undefined || Number.isNaN(v)) return "—";
  if (typeof v !== "number") return String(v);
  const a = Math.abs(v);
  if (a !== 0 && (a >= 1e6 || a < 1e-3)) return v.toExponential(3);
  return String(Number(v.toPrecision(digits)));
}

export function status(message, kind = "info") {
  emit("status", { message, kind });
}
