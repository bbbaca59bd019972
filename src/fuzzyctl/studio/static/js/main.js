// The studio's shell: views, the file menu, the check panel, keyboard shortcuts.
import { get, post } from "./api.js";
import { state, on, emit, load, changed, recheck, body, newDocument, status, undo, redo, history } from "./state.js";
import { matlabSummary } from "./matlab.js";
import { $, el, confirmDialog, openDialog, fillDiagnostics } from "./ui.js";
import * as diagram from "./diagram.js";
import * as variable from "./variable.js";
import * as rules from "./rules.js";
import * as text from "./text.js";
import * as surface from "./surface.js";
import * as recorder from "./recorder.js";
import * as explain from "./explain.js";
import * as onlineView from "./online.js";
import * as ruleviewer from "./ruleviewer.js";
import * as panes from "./panes.js";
import { setShapes } from "./terms.js";
import * as findings from "./findings.js";

const views = { project: diagram, variable, rules, ruleviewer, text, surface, recorder, explain, online: onlineView };
let current = "project";

// views that need a model: disabled, saying why, while the file opened does not read
const NEEDS_MODEL = ["project", "variable", "rules", "ruleviewer", "surface", "recorder", "explain"];
let origin = null; // the format the model was read from (fis: a MATLAB file)

function gateViews() {
  const why = state.doc ? null : "the file has errors: fix them in the FCL text (the first is selected there), then this view works";
  for (const tab of document.querySelectorAll('[role="tab"]')) {
    const off = why !== null && NEEDS_MODEL.includes(tab.dataset.view);
    tab.disabled = off;
    tab.setAttribute("aria-disabled", String(off));
    tab.title = off ? why : tab.dataset.keys || tab.title;
  }
}

export function show(view) {
  if (!views[view]) return;
  if (!state.doc && NEEDS_MODEL.includes(view) && document.body.dataset.broken === "true") return;
  current = view;
  for (const tab of document.querySelectorAll('[role="tab"]')) {
    const selected = tab.dataset.view === view;
    tab.setAttribute("aria-selected", String(selected));
    tab.tabIndex = selected ? 0 : -1;
  }
  for (const name of Object.keys(views)) $(`#view-${name}`).hidden = name !== view;
  views[view].shown?.();
}
on("show", ({ view, target }) => {
  show(view);
  if (target) views[view].focus?.(target);
});

// --- check panel ---------------------------------------------------------------------

function renderReport(report) {
  const badge = $("#level-badge");
  badge.textContent = report.level ? `level: ${report.level}` : "level: —";
  const errors = report.diagnostics.filter((d) => d.severity === "error").length;
  const warnings = report.diagnostics.filter((d) => d.severity === "warning").length;
  const check = $("#check-badge");
  check.textContent = errors ? `${errors} error(s)` : `OK, ${warnings} warning(s)`;
  check.className = "badge " + (errors ? "bad" : warnings ? "warn" : "good");
  const detail = $("#level-detail");
  detail.replaceChildren();
  if (report.level) {
    const features = report.features || [];
    const list = el("ul", { class: "features" }, ...features.map((f) => el("li", {}, `${f.level} (${f.table}): ${f.element} — ${f.detail}`)));
    if (origin === "fis" && state.doc) {
      // a MATLAB user reads the file's [System] settings, not the IEC standard's tables
      detail.append(matlabSummary(state.doc.blocks[state.block]));
      if (features.length) detail.append(el("details", { class: "conformance" }, el("summary", {}, `As IEC 61131-7 FCL: level ${report.level} (${features.length} item(s))`), list));
    } else {
      detail.append(el("p", {}, `Conformance level: ${report.level}`));
      if (features.length) detail.append(list);
    }
  }
  const losses = (report.fcl_losses || []).map((l) => ({ severity: "warning", message: `saving as FCL drops: ${l}`, element: null }));
  fillDiagnostics($("#all-diags"), [...report.diagnostics, ...losses]);
}

function renderBlocks() {
  const blocks = state.doc ? state.doc.blocks : [];
  $("#fb-picker").hidden = blocks.length < 2;
  $("#fb-select").replaceChildren(...blocks.map((b, i) => el("option", { value: i, selected: i === state.block }, b.name || `block ${i + 1}`)));
}

function renderTitle() {
  const name = state.path || (state.doc ? "(not saved)" : "no project");
  $("#project-name").textContent = (state.dirty ? "● " : "") + name;
  document.title = `${state.dirty ? "● " : ""}${state.path || "fuzzyctl studio"} — fuzzyctl studio`;
}

// --- files ---------------------------------------------------------------------------

async function guardDirty() {
  if (!state.dirty) return true;
  const answer = await confirmDialog("Unsaved changes", "The project has changes that are not saved. Discard them?", [["cancel", "Cancel"], ["discard", "Discard"]]);
  return answer === "discard";
}

async function newProject() {
  if (!(await guardDirty())) return;
  const value = await openDialog("#dlg-new");
  if (value !== "ok") return;
  const name = $("#new-name").value.trim() || "project";
  const nIn = Math.max(1, Math.min(8, +$("#new-inputs").value || 1));
  const nOut = Math.max(1, Math.min(4, +$("#new-outputs").value || 1));
  const doc = newDocument(name, nIn, nOut);
  const ranges = {};
  for (const v of doc.blocks[0].variables) ranges[v.name] = [-100, 100];
  load({ document: doc, settings: { ranges }, path: null, sha256: null, ok: true, diagnostics: [], level: null, ranges });
  state.dirty = true;
  emit("dirty", true);
  status(`new project ${name}: ${nIn} input(s), ${nOut} output(s)`);
  show("project");
}

async function openFile() {
  if (!(await guardDirty())) return;
  const { files, root } = await get("/api/files");
  $("#open-root").textContent = root;
  const list = $("#open-list");
  list.replaceChildren(...files.filter((f) => !f.path.endsWith(".toml")).map((f) => el("option", { value: f.path }, f.path)));
  if (list.options.length) list.selectedIndex = 0;
  const value = await openDialog("#dlg-open", list);
  if (value !== "ok" || !list.value) return;
  await openPath(list.value);
}

export async function openPath(path) {
  try {
    const result = await post("/api/open", { path });
    if (!result.document) {
      // the file does not read: open it at its first error, the views that need a model off
      document.body.dataset.broken = "true";
      load({ ...result, document: null });
      emit("report", state.report);
      emit("rawtext", result.text);
      const first = (result.diagnostics || []).find((d) => d.severity === "error" && d.line);
      show("text");
      if (first) emit("show", { view: "text", target: { line: first.line } });
      status(`${path} has errors${first ? ` (the first at line ${first.line}, selected)` : ""}: fix them in the FCL text; the other views open once it reads`, "error");
      return;
    }
    load(result, { path: result.path, sha: result.sha256 });
    status(result.imported_from ? `imported ${result.imported_from}; save it as an FCL project` : `opened ${path}`);
  } catch (err) {
    status(err.message, "error");
  }
}

async function save(asNew = false) {
  if (!state.doc) return;
  if (state.textError) {
    status("the FCL text has errors: fix them before saving", "error");
    return;
  }
  let path = state.path;
  let overwrite = false;
  if (asNew || !path) {
    $("#saveas-path").value = path || `${state.doc.blocks[state.block].name || "project"}.fcl`;
    const value = await openDialog("#dlg-saveas", $("#saveas-path"));
    if (value !== "ok") return;
    path = $("#saveas-path").value.trim();
    if (!path.toLowerCase().endsWith(".fcl")) path += ".fcl";
  }
  const request = body({ path, expected_sha256: path === state.path ? state.sha : null, overwrite });
  try {
    let result;
    try {
      result = await post("/api/save", request);
    } catch (err) {
      if (err.status !== 409 || !(err.payload.exists || err.payload.changed)) throw err;
      const answer = await confirmDialog("Replace file?", err.message + ". Replace it?", [["cancel", "Cancel"], ["replace", "Replace"]]);
      if (answer !== "replace") return;
      result = await post("/api/save", { ...request, overwrite: true });
    }
    state.path = result.path;
    state.sha = result.sha256;
    state.dirty = false;
    emit("dirty", false);
    status(`saved ${result.path}`);
  } catch (err) {
    status(err.message, "error");
  }
}

async function importFile(file) {
  if (!(await guardDirty())) return;
  const buffer = new Uint8Array(await file.arrayBuffer());
  let binary = "";
  for (let i = 0; i < buffer.length; i += 0x8000) binary += String.fromCharCode(...buffer.subarray(i, i + 0x8000));
  try {
    const result = await post("/api/import", { filename: file.name, data_base64: btoa(binary) });
    load({ ...result, path: null, sha256: null });
    state.dirty = true;
    emit("dirty", true);
    const warn = result.warnings.length ? ` (${result.warnings.length} warning(s))` : "";
    status(`imported ${file.name} (${result.format})${warn}; save it as an FCL project`);
  } catch (err) {
    status(err.message, "error");
  }
}

async function exportFile() {
  if (!state.doc) return;
  const select = $("#export-format");
  if (!select.options.length) {
    for (const f of state.info.formats.filter((f) => f.write)) select.append(el("option", { value: f.name }, `${f.name} (${f.extensions.join(", ")})`));
  }
  const value = await openDialog("#dlg-export", select);
  if (value !== "ok") return;
  try {
    let result = await post("/api/export", body({ format: select.value }));
    if (result.text === null) {
      const list = el("ul", { class: "losses" }, ...result.losses.map((l) => el("li", {}, l)));
      const answer = await confirmDialog(`${result.format} cannot express everything`, el("div", {}, el("p", {}, "These elements would be dropped:"), list), [["cancel", "Cancel"], ["lossy", "Export without them"]]);
      if (answer !== "lossy") return;
      result = await post("/api/export", body({ format: select.value, lossy: true }));
    }
    const blob = new Blob([result.text], { type: "text/plain" });
    const link = el("a", { href: URL.createObjectURL(blob), download: result.filename });
    document.body.append(link);
    link.click();
    link.remove();
    setTimeout(() => URL.revokeObjectURL(link.href), 1000);
    status(`exported ${result.filename}${result.losses.length ? ` (${result.losses.length} element(s) dropped)` : ""}`);
  } catch (err) {
    status(err.message, "error");
  }
}

// --- start ---------------------------------------------------------------------------

function textField(target) {
  return target instanceof HTMLTextAreaElement || (target instanceof HTMLInputElement && ["text", "search"].includes(target.type));
}

function bindShell() {
  $("#btn-new").addEventListener("click", newProject);
  $("#btn-open").addEventListener("click", openFile);
  $("#btn-save").addEventListener("click", () => save(false));
  $("#btn-saveas").addEventListener("click", () => save(true));
  $("#btn-import").addEventListener("click", () => $("#import-file").click());
  $("#import-file").addEventListener("change", (e) => {
    const file = e.target.files[0];
    e.target.value = "";
    if (file) importFile(file);
  });
  $("#btn-export").addEventListener("click", exportFile);
  const tabs = [...document.querySelectorAll('[role="tab"]')];
  tabs.forEach((tab, i) => {
    tab.addEventListener("click", () => show(tab.dataset.view));
    tab.addEventListener("keydown", (e) => {
      if (e.key === "ArrowRight" || e.key === "ArrowLeft") {
        const next = tabs[(i + (e.key === "ArrowRight" ? 1 : tabs.length - 1)) % tabs.length];
        next.focus();
        show(next.dataset.view);
      }
    });
  });
  document.addEventListener("keydown", (e) => {
    const key = e.key.toLowerCase();
    if ((e.ctrlKey || e.metaKey) && key === "s") {
      e.preventDefault();
      save(e.shiftKey);
    } else if ((e.ctrlKey || e.metaKey) && key === "o") {
      e.preventDefault();
      openFile();
    } else if ((e.ctrlKey || e.metaKey) && (key === "z" || key === "y") && !textField(e.target)) {
      // the model's undo; a text field keeps its own (the browser's) while it is edited
      e.preventDefault();
      if (key === "y" || e.shiftKey) redo() || status("nothing to redo");
      else undo() || status("nothing to undo");
    } else if (e.altKey && key === "n") {
      e.preventDefault();
      newProject();
    } else if (e.altKey && /^[1-9]$/.test(e.key)) {
      e.preventDefault();
      const tab = tabs[+e.key - 1];
      show(tab.dataset.view);
      tab.focus();
    }
  });
  window.addEventListener("beforeunload", (e) => {
    if (state.dirty) e.preventDefault();
  });
  on("report", renderReport);
  on("dirty", renderTitle);
  on("loaded", renderTitle);
  on("loaded", (result) => {
    origin = result.format || ((result.imported_from || "").match(/\.([a-z0-9]+)$/i) || [])[1]?.toLowerCase() || null;
    if (result.document) document.body.dataset.broken = "false";
    gateViews();
  });
  on("model", () => {
    if (state.doc && document.body.dataset.broken === "true") document.body.dataset.broken = "false";
    gateViews();
  });
  for (const tab of tabs) tab.dataset.keys = tab.title;
  $("#btn-undo").addEventListener("click", () => undo() || status("nothing to undo"));
  $("#btn-redo").addEventListener("click", () => redo() || status("nothing to redo"));
  on("history", (h) => {
    $("#btn-undo").disabled = !h.undo.length;
    $("#btn-redo").disabled = !h.redo.length;
    document.body.dataset.undo = String(h.undo.length);
    document.body.dataset.redo = String(h.redo.length);
  });
  on("loaded", renderBlocks);
  $("#fb-select").addEventListener("change", (e) => {
    state.block = +e.target.value;
    emit("model", "all");
    recheck();
  });
  $("#online-badge").addEventListener("click", () => show("online"));
  on("status", ({ message, kind }) => {
    const s = $("#status");
    s.textContent = message;
    s.className = `status ${kind}`;
  });
}

async function start() {
  bindShell();
  panes.init();
  findings.init();
  for (const view of Object.values(views)) view.init?.();
  $("#loading-text").textContent = "Reading the project…";
  const [info, shapes] = await Promise.all([get("/api/info"), get("/api/shapes")]);
  state.info = info;
  // The import dialog offers what the server's format registry reads (no list of our own).
  const readable = info.formats.filter((f) => f.read);
  $("#import-file").accept = readable.flatMap((f) => f.extensions).join(",");
  $("#btn-import").title = `Import ${readable.map((f) => f.name.toUpperCase()).join(", ")}`;
  setShapes(shapes);
  if (state.info.file) await openPath(state.info.file);
  else status("New (Alt+N) creates a project, Open (Ctrl+O) opens one from the project directory.");
  const params = new URLSearchParams(location.search);
  if (params.get("view")) show(params.get("view"));
  emit("ready", state.info);
  document.body.dataset.ready = "true";
}

start().catch((err) => {
  status(String(err.message || err), "error");
  $("#loading-text").textContent = `The studio could not start: ${err.message || err}`;
});
export { changed };
