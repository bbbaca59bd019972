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
let inFlight = false; // a check is on its way
let again = false; // the model changed while it was
/** Something in the model changed: views redraw now, the check runs shortly after.  One
 * check is in flight at a time; changes meanwhile are checked together when it returns
 * (a 500-rule model takes a while to check, edits must not queue up behind each other). */
let changes = 0; // model changes so far; a check reports which of them it saw
export function changed(what = "model", { quiet = false, delay = 150 } = {}) {
  remember(what);
  state.dirty = true;
  changes++;
  document.body.dataset.changes = String(changes);
  if (inFlight) again = true; // the check under way is of the model before this change
  if (!quiet) emit("model", what);
  emit("dirty", true);
  clearTimeout(timer);
  timer = setTimeout(recheck, delay);
}

export async function recheck() {
  if (!state.doc) return;
  if (inFlight) {
    again = true;
    return;
  }
  inFlight = true;
  again = false;
  const mine = ++seq;
  const seen = changes;
  emit("checking", true);
  try {
    const request = body();
    const map = ruleMap;
    const report = await post("/api/check", request);
    if (mine !== seq || again) return; // a newer check follows: its answer is the one to show
    for (const d of report.diagnostics) {
      const m = /^rule:(\d+):(\d+)$/.exec(d.element || "");
      if (m && map[+m[1]]) d.element = `rule:${m[1]}:${map[+m[1]][+m[2]]}`;
    }
    state.report = report;
    state.textError = null;
    emit("report", report);
    // for tests and timing: how many checks came back, and up to which change they saw
    document.body.dataset.checks = String(+(document.body.dataset.checks || 0) + 1);
    document.body.dataset.checkedChanges = String(seen);
  } catch (err) {
    if (mine !== seq || again) return;
    // a refusal that lists its diagnostics (422 of an invalid model) shows them, else its message
    const listed = err.payload && Array.isArray(err.payload.diagnostics) && err.payload.diagnostics.length ? err.payload.diagnostics : null;
    const diagnostics = listed || [{ severity: "error", message: err.message, element: null }];
    state.report = { ok: false, diagnostics, level: null, ranges: (state.report || {}).ranges || {}, curves: (state.report || {}).curves || {} };
    emit("report", state.report);
  } finally {
    inFlight = false;
    emit("checking", false);
    if (again) recheck();
  }
}

/** The request body of the editors that read text in the edited function block (rule
 * lines, a term): the model without rules or source positions, small however many rules. */
export function bodyWithoutRules(extra = {}) {
  const doc = { ...state.doc, blocks: state.doc.blocks.map((b) => ({ ...b, rule_blocks: b.rule_blocks.map((rb) => ({ ...rb, rules: [] })) })) };
  return { document: withoutSpans(doc), block: state.block, ...extra };
}

/** A copy of the model without source positions: they point into the file as it was
 * opened, the server reads the model from its FCL text again, and they are most of the
 * size of a large rule base's JSON. */
export function withoutSpans(value) {
  return JSON.parse(JSON.stringify(value, (key, v) => (key === "span" || key === "item_spans" ? undefined : v)));
}

let ruleMap = [];
/** The model part of every analysis request.  Rules the table holds without a THEN part
 * yet are left out (they do nothing, manual 1.5); ``ruleMap`` turns the indices of the
 * rules sent back into the table's. */
export function body(extra = {}) {
  const doc = withoutSpans(state.doc);
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
  state.report = { ok: result.ok, diagnostics: result.diagnostics || [], level: result.level, features: result.features || [], text: result.text, ranges: result.ranges || {}, curves: result.curves || {}, fcl_losses: result.fcl_losses || [] };
  history.undo = [];
  history.redo = [];
  history.current = snapshot();
  emit("loaded", result);
  emit("history", history);
  emit("model", "all");
  emit("dirty", false);
  // an opened or imported file comes checked, with its curves; a new project is checked now
  if (result.curves) emit("report", state.report);
  else recheck();
}

// --- undo / redo -------------------------------------------------------------------
// Every edit goes through changed(): the model (and the view settings) before it is kept,
// so Ctrl+Z / Ctrl+Y step through every edit whichever view made it.  Edits of one kind
// within HISTORY_MERGE_MS (a point dragged, a number typed) are one step.

const HISTORY_MAX = 200;
const HISTORY_MERGE_MS = 600;
export const history = { undo: [], redo: [], current: null, last: { what: null, at: 0 } };

function snapshot() {
  return state.doc ? JSON.stringify({ doc: state.doc, settings: state.settings || {} }) : null;
}

/** Keep the model before an edit made outside changed() (the FCL text). */
export function remember(what) {
  const now = snapshot();
  if (now === null || now === history.current) return;
  const merge = what === history.last.what && Date.now() - history.last.at < HISTORY_MERGE_MS && history.undo.length;
  if (!merge && history.current !== null) {
    history.undo.push(history.current);
    if (history.undo.length > HISTORY_MAX) history.undo.shift();
  }
  history.redo = [];
  history.current = now;
  history.last = { what, at: Date.now() };
  emit("history", history);
}

function restore(from, to) {
  if (state.textError !== null) return false; // the FCL text holds its own edits
  const target = from.pop();
  if (target === undefined) return false;
  to.push(history.current);
  history.current = target;
  history.last = { what: null, at: 0 };
  const { doc, settings } = JSON.parse(target);
  state.doc = doc;
  state.settings = settings;
  if (state.block >= doc.blocks.length) state.block = 0;
  state.dirty = true;
  changes++;
  document.body.dataset.changes = String(changes);
  if (inFlight) again = true;
  emit("model", "undo");
  emit("dirty", true);
  emit("history", history);
  clearTimeout(timer);
  timer = setTimeout(recheck, 50);
  return true;
}

/** Take back the last edit (Ctrl+Z); false when there is none. */
export const undo = () => restore(history.undo, history.redo);
/** Do again the edit taken back last (Ctrl+Y, Ctrl+Shift+Z). */
export const redo = () => restore(history.redo, history.undo);

// --- new terms ----------------------------------------------------------------------

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

/** A number as an engineer reads it: fixed decimals, four significant digits, no
 * exponent between 0.001 and 100000, and 0 for what is 0 at that resolution
 * (``4.476e-13`` is ``0.000``).  With ``span`` (the variable's range width) the decimals
 * resolve 1/1000 of the range, so every value of one variable has the same decimals. */
export function fmt(v, digits = 4, span = null) {
  if (v === null || v === undefined || Number.isNaN(v)) return "—";
  if (typeof v !== "number") return String(v);
  if (!Number.isFinite(v)) return v > 0 ? "∞" : "−∞";
  const a = Math.abs(v);
  let decimals;
  if (span && span > 0) decimals = Math.ceil(-Math.log10(span / 1000));
  else if (a < 1e-9) decimals = 3;
  else if (a >= 1e5 || a < 1e-3) return v.toExponential(digits - 1);
  else decimals = digits - 1 - Math.floor(Math.log10(a));
  decimals = Math.max(0, Math.min(6, decimals));
  const text = v.toFixed(decimals);
  return /^-0(\.0*)?$/.test(text) ? text.slice(1) : text;
}

/** A number of the model as written (a range limit, a parameter): no trailing zeros,
 * at most six significant digits. */
export function num(v) {
  if (v === null || v === undefined || Number.isNaN(v)) return "—";
  if (typeof v !== "number") return String(v);
  return String(Number(v.toPrecision(6)));
}

/** A value of variable ``name`` formatted over its range, with its unit when known. */
export function fmtVar(name, v, unit = null) {
  const [lo, hi] = range(name);
  const text = fmt(v, 4, hi - lo);
  return unit ? `${text} ${unit}` : text;
}

/** Round tick values for an axis over [lo, hi]: steps of 1, 2, 2.5 or 5 times a power of
 * ten, about ``n`` of them. */
export function niceTicks(lo, hi, n = 5) {
  const span = hi - lo;
  if (!(span > 0)) return [lo];
  const raw = span / n;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * power).find((s) => s >= raw) || raw;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(Number(v.toPrecision(12)));
  return out;
}

/** A degree of membership: three decimals. */
export function deg(v) {
  return v === null || v === undefined || Number.isNaN(v) ? "—" : v.toFixed(3);
}

export function status(message, kind = "info") {
  emit("status", { message, kind });
}
