// On line (manual 6.7, 6.8): connect to a running `fuzzyctl serve`, pick an instance,
// watch its values, START_STOP / MAN_AUTO / forcing, and download the edited knowledge
// base after a confirmation that shows the difference of the two FCL texts.
import { state, on, body, fmt, status } from "./state.js";
import { post } from "./api.js";
import { $, el, confirmDialog } from "./ui.js";
import { diffLines } from "./diff.js";

export const online = { url: null, token: null, instance: null, detail: null, instances: [] };
let poller = null;

function creds() {
  return { url: online.url, token: online.token || null, instance: online.instance };
}

async function connect() {
  online.url = $("#on-url").value.trim();
  online.token = $("#on-token").value.trim() || null;
  try {
    const res = await post("/api/online/instances", { url: online.url, token: online.token || null });
    online.instances = res.instances;
    const select = $("#on-instance");
    select.replaceChildren(...res.instances.map((i) => el("option", { value: i.name }, `${i.name} (${i.style}, ${i.state})`)));
    online.instance = res.instances.length ? res.instances[0].name : null;
    status(`connected to ${res.api}: fuzzyctl ${res.health.version}, ${res.instances.length} instance(s)`);
    await read();
    startPolling();
  } catch (err) {
    status(err.message, "error");
  }
}

async function read() {
  if (!online.url || !online.instance) return;
  try {
    online.detail = await post("/api/online/read", creds());
    render();
  } catch (err) {
    status(err.message, "error");
    stopPolling();
  }
}

function startPolling() {
  stopPolling();
  poller = setInterval(() => !$("#view-online").hidden && read(), 500);
}
function stopPolling() {
  if (poller) clearInterval(poller);
  poller = null;
}

function render() {
  const d = online.detail;
  if (!d) return;
  const status_ = Object.entries(d.status).map(([k, v]) => `${k} ${v}`).join(", ");
  $("#on-detail").replaceChildren(el("span", { class: `badge state-${d.state}`, id: "on-state" }, d.state), el("span", {}, ` ${d.style}, period ${fmt(d.period)} s, ${d.cycles} cycles, ${status_}; parameters: ${Object.entries(d.parameters).map(([k, v]) => `${k}=${v}`).join(", ")}; knowledge base ${d.knowledge_base.origin} (${d.knowledge_base.sha256.slice(0, 10)}…), ${d.downloads} download(s)`));
  const rows = [];
  for (const [name, v] of Object.entries(d.inputs)) rows.push(el("tr", {}, el("th", {}, `input ${name}`), el("td", { class: "num", id: `on-in-${name}` }, fmt(v)), el("td", {}, name in d.forced ? `forced ${fmt(d.forced[name])}` : "")));
  for (const [name, v] of Object.entries(d.outputs)) rows.push(el("tr", {}, el("th", {}, `output ${name}`), el("td", { class: "num", id: `on-out-${name}` }, fmt(v)), el("td", {}, "")));
  $("#on-values tbody").replaceChildren(...rows);
  const force = $("#on-force-input");
  if (force.options.length !== Object.keys(d.inputs).length) force.replaceChildren(...Object.keys(d.inputs).map((n) => el("option", { value: n }, n)));
}

async function command(action, extra = {}) {
  try {
    await post("/api/online/command", { ...creds(), action, ...extra });
    status(`${action}: done`);
    await read();
  } catch (err) {
    status(err.message, "error");
  }
}

async function download() {
  if (!online.url || !online.instance) return status("connect and pick an instance first", "error");
  if (!state.doc) return;
  let diff;
  try {
    diff = await post("/api/online/diff", body(creds()));
  } catch (err) {
    return status(err.message, "error");
  }
  const lines = diffLines(diff.running.fcl, diff.edited);
  const changes = lines.filter((l) => l.op !== " ").length;
  const pre = el("pre", { class: "diff", id: "download-diff" });
  for (const l of lines) pre.append(el("span", { class: l.op === "+" ? "add" : l.op === "-" ? "del" : "same" }, `${l.op} ${l.line}\n`));
  const content = el("div", {}, el("p", {}, `Instance ${online.instance} runs ${diff.running.origin} (${diff.running.format}). ${changes ? `${changes} line(s) differ` : "The knowledge bases are the same"}; − running, + edited:`), pre);
  const answer = await confirmDialog(`Download to ${online.instance}?`, content, [["cancel", "Cancel"], ["download", "Download"]]);
  if (answer !== "download") return;
  try {
    const res = await post("/api/online/download", body(creds()));
    status(`downloaded to ${online.instance}: ${res.procedure}`);
    await read();
  } catch (err) {
    const diags = err.payload && err.payload.runtime && err.payload.runtime.diagnostics;
    status(diags ? `${err.message}` : err.message, "error");
  }
}

export function init() {
  $("#on-connect").addEventListener("click", connect);
  $("#on-instance").addEventListener("change", (e) => {
    online.instance = e.target.value;
    read();
  });
  $("#on-token").addEventListener("change", (e) => (online.token = e.target.value.trim() || null));
  $("#on-start").addEventListener("click", () => command("start"));
  $("#on-stop").addEventListener("click", () => command("stop"));
  $("#on-auto").addEventListener("click", () => command("auto"));
  $("#on-manual").addEventListener("click", () => command("manual"));
  $("#on-force").addEventListener("click", () => {
    const value = parseFloat($("#on-force-value").value);
    if (!Number.isFinite(value)) return status("give the forced value", "error");
    command("force", { target: $("#on-force-input").value, value });
  });
  $("#on-release").addEventListener("click", () => command("release", { target: $("#on-force-input").value }));
  $("#on-download").addEventListener("click", download);
  on("loaded", () => {});
}

export function shown() {
  if (online.url && online.instance) read();
}
