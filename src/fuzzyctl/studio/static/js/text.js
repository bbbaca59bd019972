// The FCL text editor: syntax highlighting, line numbers and a mark in the gutter at
// every diagnostic, live diagnostics from `fuzzyctl check`, and the model updated whenever
// the text checks without errors.
import { state, on, emit, recheck, remember } from "./state.js";
import { post } from "./api.js";
import { $, fillDiagnostics } from "./ui.js";
import { CodeEditor, highlight } from "./code.js";

export { highlight };

let editor = null;
let own = false; // the model change came from this editor
let seq = 0;

async function parse(text) {
  const mine = ++seq;
  try {
    const result = await post("/api/parse", { text });
    if (mine !== seq) return;
    fillDiagnostics($("#text-diags"), result.diagnostics);
    editor.paint(result.diagnostics);
    if (result.document) {
      state.textError = null;
      own = true;
      state.doc = result.document;
      if (result.settings && Object.keys(result.settings).length) state.settings = result.settings;
      remember("text");
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
  if (typeof text === "string" && editor.value !== text) {
    editor.diagnostics = state.report.diagnostics;
    editor.value = text;
  } else if (state.report) {
    editor.paint(state.report.diagnostics);
  }
  fillDiagnostics($("#text-diags"), state.report ? state.report.diagnostics : []);
}

export function init() {
  editor = new CodeEditor($(".fcl-code"), { onInput: parse });
  on("report", () => !$("#view-text").hidden && !own && fill());
  on("rawtext", (text) => {
    state.textError = text;
    editor.diagnostics = state.report ? state.report.diagnostics : [];
    editor.value = text;
    fillDiagnostics($("#text-diags"), state.report ? state.report.diagnostics : []);
  });
  on("loaded", () => {
    state.textError = null;
  });
  // an undo or redo: the editor shows the model's text once the check has written it
  on("model", (what) => {
    if (what === "undo") state.textError = null;
  });
}

export function shown() {
  fill();
}

export function focus(target) {
  if (target.line) editor.goToLine(target.line);
}
