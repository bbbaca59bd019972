// The FCL text editor: syntax highlighting under a plain <textarea> (so every browser
// editing key works), live diagnostics from `fuzzyctl check`, and the model updated
// whenever the text checks without errors.
import { state, on, emit, recheck } from "./state.js";
import { post } from "./api.js";
import { $, fillDiagnostics } from "./ui.js";

const KEYWORDS = new Set("FUNCTION_BLOCK END_FUNCTION_BLOCK VAR_INPUT VAR_OUTPUT VAR END_VAR FUZZIFY END_FUZZIFY DEFUZZIFY END_DEFUZZIFY RULEBLOCK END_RULEBLOCK OPTIONS END_OPTIONS OPTION END_OPTION TERM RANGE METHOD DEFAULT ACCU ACT AND OR NOT IF THEN IS WITH RULE NC".split(" "));
const TYPES = new Set("REAL LREAL INT DINT SINT UINT WORD BOOL".split(" "));
const TOKEN = /(\(\*[\s\S]*?(?:\*\)|$)|\/\*[\s\S]*?(?:\*\/|$)|\/\/[^\n]*)|([A-Za-z_][A-Za-z0-9_]*)|(-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)|(:=|\.\.|[;:(),])/g;

let timer = null;
let own = false; // the model change came from this editor
let seq = 0;

function escape(s) {
  return s.replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
}

export function highlight(text, diagnostics = []) {
  let html = "";
  let last = 0;
  for (const m of text.matchAll(TOKEN)) {
    html += escape(text.slice(last, m.index));
    const [tok, comment, word, number, punct] = m;
    if (comment) html += `<span class="tk-comment">${escape(tok)}</span>`;
    else if (word && KEYWORDS.has(word.toUpperCase())) html += `<span class="tk-keyword">${tok}</span>`;
    else if (word && TYPES.has(word.toUpperCase())) html += `<span class="tk-type">${tok}</span>`;
    else if (word) html += `<span class="tk-name">${tok}</span>`;
    else if (number) html += `<span class="tk-number">${tok}</span>`;
    else if (punct) html += `<span class="tk-punct">${escape(tok)}</span>`;
    last = m.index + tok.length;
  }
  html += escape(text.slice(last));
  // mark the lines diagnostics point at (comments may span lines, so mark after tokens)
  const marks = new Map();
  for (const d of diagnostics) if (d.line) marks.set(d.line, d.severity === "error" || marks.get(d.line) === "error" ? "error" : d.severity);
  const lines = html.split("\n");
  return lines.map((line, i) => (marks.has(i + 1) ? `<span class="line-${marks.get(i + 1)}">${line || " "}</span>` : line)).join("\n") + "\n";
}

function paint(diagnostics) {
  const input = $("#code-input");
  $("#code-highlight").innerHTML = highlight(input.value, diagnostics);
  syncScroll();
}

function syncScroll() {
  const input = $("#code-input");
  const pre = $("#code-highlight");
  pre.scrollTop = input.scrollTop;
  pre.scrollLeft = input.scrollLeft;
}

async function parse() {
  const text = $("#code-input").value;
  const mine = ++seq;
  try {
    const result = await post("/api/parse", { text });
    if (mine !== seq) return;
    fillDiagnostics($("#text-diags"), result.diagnostics);
    paint(result.diagnostics);
    if (result.document) {
      state.textError = null;
      own = true;
      state.doc = result.document;
      if (result.settings && Object.keys(result.settings).length) state.settings = result.settings;
      state.dirty = true;
      emit("model", "text");
      emit("dirty", true);
      own = false;
      recheck();
    } else {
      state.textError = text;
      state.report = { ...(state.report || {}), ok: false, diagnostics: result.diagnostics, level: null };
      emit("report", state.report);
      state.dirty = true;
      emit("dirty", true);
    }
  } catch (err) {
    fillDiagnostics($("#text-diags"), [{ severity: "error", message: err.message }]);
  }
}

function fill() {
  if (state.textError !== null) return; // keep the user's text with its errors
  const text = state.report && state.report.text;
  if (typeof text === "string" && $("#code-input").value !== text) {
    $("#code-input").value = text;
    paint(state.report.diagnostics);
  }
  fillDiagnostics($("#text-diags"), state.report ? state.report.diagnostics : []);
}

export function init() {
  const input = $("#code-input");
  input.addEventListener("input", () => {
    paint([]);
    clearTimeout(timer);
    timer = setTimeout(parse, 300);
  });
  input.addEventListener("scroll", syncScroll);
  input.addEventListener("keydown", (e) => {
    if (e.key === "Tab" && !e.shiftKey && !e.ctrlKey && !e.altKey) {
      // indent; Escape then Tab leaves the editor (keyboard users keep a way out)
      if (input.dataset.escaped === "true") return;
      e.preventDefault();
      input.setRangeText("    ", input.selectionStart, input.selectionEnd, "end");
      input.dispatchEvent(new Event("input"));
    }
    input.dataset.escaped = String(e.key === "Escape");
  });
  on("report", () => !$("#view-text").hidden && !own && fill());
  on("rawtext", (text) => {
    state.textError = text;
    input.value = text;
    paint(state.report ? state.report.diagnostics : []);
    fillDiagnostics($("#text-diags"), state.report ? state.report.diagnostics : []);
  });
  on("loaded", () => {
    state.textError = null;
  });
}

export function shown() {
  fill();
}

export function focus(target) {
  const input = $("#code-input");
  if (target.line) {
    const lines = input.value.split("\n");
    const offset = lines.slice(0, target.line - 1).reduce((n, l) => n + l.length + 1, 0);
    input.focus();
    input.setSelectionRange(offset, offset + (lines[target.line - 1] || "").length);
    const lineHeight = parseFloat(getComputedStyle(input).lineHeight) || 18;
    input.scrollTop = Math.max(0, (target.line - 5) * lineHeight);
    syncScroll();
  }
}
